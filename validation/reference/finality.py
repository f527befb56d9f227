"""Energy bounds that tell the reference solver when a peak metric can no longer change (DESIGN.md, "Early stop").

Written from the model's connectors (:mod:`validation.reference.model`), independently of the engine's
early stop.  For a dissipative scene (no connector injects energy: only the paper's
``literal_lambda_sign`` reading does) the mechanical energy ``E = sum m v^2/2 + sum U`` (J) never
increases: its rate is minus the dissipated powers, each >= 0.  So with ``E`` now, at every later time
(SI units; every bound is used with ``E (1 + ENERGY_SLACK)`` against the integration error):

* **positions**: the linear springs' energy ``q^T K q / 2 <= E`` (``q`` the body positions, ``K`` positive
  semi-definite, assembled from every connector's ``linear_stiffness``), so a combination ``c.q`` is at
  most ``sqrt(2 E c^T K^+ c)`` -- infinite if ``c`` is not in the range of K (``K^+``: pseudo-inverse).  A
  connector's ``d = x_b - x_a`` is ``c.q`` with ``c = e_b - e_a``;
* **contacts**: the penetration ``p = d - offset`` is at most ``d_max - offset`` (<= 0: the contact cannot
  close) and at most what its own potential allows, ``((n+1) E / k)^(1/(n+1))``.  A contact from the ground
  to a body also bounds that body's position: ``x <= offset + p_max`` (the recoil stop bounds x_M);
* **velocities**: ``|v_i| <= sqrt(2 E / m_i)``, ``|v_b - v_a| <= sqrt(2 E (1/m_a + 1/m_b))``; and a body all
  of whose connectors go to the ground, once its contacts with other bodies cannot close, keeps its own
  energy ``m v^2/2 + sum U`` from increasing: ``|v| <= sqrt(2 E_own / m)``;
* **forces**: each connector bounds its force from those (``Connector.force_bound``); the support force
  ``|S|`` by the sum of the bounds of the connectors touching the ground.

External inputs (loads, shots) add energy: the bounds hold only once the last of them has acted
(:attr:`Model.last_input_time`; the solver checks from then on), and not at all under a load that never
ends (a constant load: :attr:`Finality.enabled` is False).  The maxima are observed over the whole run.

A metric is final once its observed maximum (a lower bound of the true one: values of the solution at the
solver's step points) reaches the bound of everything later: ``max_barrel_displacement`` (x of the barrel),
``max_absorber_velocity`` (every absorber's v), ``peak_contact_force`` (every contact's force: absorbers
and stops), ``peak_support_force`` (|S|), ``impacts`` (every contact: no episode going on and its force
bound below the impact threshold).
"""

from __future__ import annotations

import math

import numpy as np

from .model import GROUND, Model, Mode

#: The metrics that can be proven final (names of :class:`~validation.reference.result.ReferenceResult` properties).
METRICS = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "impacts", "peak_support_force")
#: Relative margin on the energy in every bound.
ENERGY_SLACK = 1e-4
#: A bound counts as reached within this relative margin.  The terminal event's root is located to
#: ~1e-16 s, but the margin there is zero only to the event function's slope times that: measured
#: -1.005e-12 (model (ii), m = 500 kg, gap 120 mm, the force bound against the impact threshold),
#: which with a 1e-12 tolerance restarted the solve at the same instant for ever.  1e-9 is far below
#: the bounds' own ENERGY_SLACK (a 5e-5 relative margin on every square-root bound).
ROOT_TOLERANCE = 1e-9
#: c is in the range of K when |K K^+ c - c| <= this times |c|.
_RANGE_TOLERANCE = 1e-9


def check_names(names) -> tuple[str, ...]:
    """The requested metric names as a tuple; ValueError naming ``stop_when_final`` and the allowed values."""
    if isinstance(names, str):
        raise ValueError(f"stop_when_final must be a sequence of metric names, not a string; allowed: "
                         f"{', '.join(METRICS)}")
    names = tuple(names)
    unknown = [n for n in names if n not in METRICS]
    if unknown:
        raise ValueError(f"stop_when_final: unknown metric {unknown[0]!r}; allowed: {', '.join(METRICS)}")
    return tuple(n for n in METRICS if n in names)


class EnergyBounds:
    """The bounds of the module docstring for one model; every method takes the energy E (J) now."""

    def __init__(self, model: Model):
        self.model = model
        nb = model.n_bodies
        K = np.zeros((nb, nb))
        for c in model.connectors:
            if c.linear_stiffness > 0:
                v = self.direction(c)
                K += c.linear_stiffness * np.outer(v, v)
        self._K, self._K_plus = K, np.linalg.pinv(K)
        #: c^T K^+ c of every connector's d (inf if not in the range of K), and of every body's position
        self._connector_form = [self.quadratic_form(self.direction(c)) for c in model.connectors]
        self._body_form = [self.quadratic_form(np.eye(nb)[i]) for i in range(nb)]
        #: contacts from the ground to a body: (body, connector) -- they bound that body's position
        self._ground_contacts = [(c.body_b, c) for c in model.contacts if c.a == GROUND]
        self._ground_connectors = [c for c in model.connectors if c.support_sign != 0]
        # bodies whose connectors all go to the ground but for contacts with other bodies
        self._own_energy = {}
        for i in range(nb):
            touching = [c for c in model.connectors if i in (c.body_a, c.body_b)]
            if all(c.support_sign != 0 or c.is_contact for c in touching):
                self._own_energy[i] = ([c for c in touching if c.support_sign != 0],
                                       [c for c in touching if c.support_sign == 0])

    def direction(self, connector) -> np.ndarray:
        """c with ``d = c.q``: ``e_b - e_a`` (the ground has no coordinate)."""
        v = np.zeros(self.model.n_bodies)
        if connector.body_b is not None:
            v[connector.body_b] += 1.0
        if connector.body_a is not None:
            v[connector.body_a] -= 1.0
        return v

    def quadratic_form(self, c: np.ndarray) -> float:
        """``c^T K^+ c`` (1/(N/m)), or inf if c is not in the range of K."""
        norm = float(np.linalg.norm(c))
        if norm == 0:
            return 0.0
        if np.linalg.norm(self._K @ (self._K_plus @ c) - c) > _RANGE_TOLERANCE * norm:
            return math.inf
        return max(float(c @ self._K_plus @ c), 0.0)

    @staticmethod
    def _sqrt2(energy: float, factor: float) -> float:
        return math.inf if math.isinf(factor) else math.sqrt(2.0 * max(energy, 0.0) * factor)

    def connector_bounds(self, energy: float) -> list[tuple[float, float, float]]:
        """Per connector: (``|d|`` m, ``|d'|`` m/s, penetration m -- 0 if a contact cannot close, else
        the smaller of the quadratic-form and own-potential bounds; inf for non-contacts)."""
        out = []
        for c, form in zip(self.model.connectors, self._connector_form):
            d = self._sqrt2(energy, form)
            rate = self._sqrt2(energy, c.inverse_reduced_mass)
            p = math.inf
            if c.is_contact:
                p = 0.0 if d <= c.offset else min(c.penetration_bound(energy), d - c.offset)
            out.append((d, rate, p))
        return out

    def bounds(self, energy: float, y=None, continuous: bool = False) -> dict:
        """Bounds at every later time from the energy ``energy`` (J) now.

        Keys: ``x`` (list per body, m), ``v`` (per body, m/s), ``force`` (per connector, N),
        ``penetration`` (per connector, m), ``reachable`` (per connector, bool: can a contact close),
        ``support`` (N).  With the state ``y`` and not ``continuous``, velocities also use the bodies' own
        energies (the refinement jumps where a contact becomes unreachable: an event function must not).
        """
        model = self.model
        per_connector = self.connector_bounds(energy)
        forces = [c.force_bound(d, rate, p) for c, (d, rate, p) in zip(model.connectors, per_connector)]
        x = [self._sqrt2(energy, form) for form in self._body_form]
        for i, c in self._ground_contacts:
            x[i] = min(x[i], c.offset + c.penetration_bound(energy))
        v = [self._sqrt2(energy, 1.0 / m) for m in model.masses]
        reachable = [p > 0 for (_, _, p) in per_connector]
        if y is not None and not continuous:
            for i, (grounded, others) in self._own_energy.items():
                if not any(reachable[c.index] for c in others):
                    own = 0.5 * model.masses[i] * y[2 * i + 1] ** 2 + sum(c.stored_energy(c.d_of(y)) for c in grounded)
                    v[i] = min(v[i], self._sqrt2(float(own) * (1.0 + ENERGY_SLACK), 1.0 / model.masses[i]))
        support = sum(forces[c.index] for c in self._ground_connectors)
        return {"x": x, "v": v, "force": forces, "penetration": [p for (_, _, p) in per_connector],
                "reachable": reachable, "support": support}


class Finality:
    """Running maxima of a reference solve and the finality decisions (see the module docstring).

    Every metric is made of *items* -- ``("x", body)``, ``("v", body)``, ``("force", connector)``,
    ``("impacts", connector)``, ``("support",)`` -- and is final when all of its items are (a metric
    without items, e.g. the absorber metrics of a scene without absorbers, is final from the start).
    ``observed`` holds lower bounds of the item maxima over the time integrated so far.
    """

    def __init__(self, model: Model, requested, impact_threshold: float):
        self.model = model
        self.requested = check_names(requested)
        self.impact_threshold = float(impact_threshold)
        self.enabled = (not any(c.injects_energy for c in model.connectors)
                        and math.isfinite(model.last_input_time))
        self.energy_bounds = EnergyBounds(model)
        contacts = [c.index for c in model.contacts]
        self.items = {
            "max_barrel_displacement": [("x", 0)],
            "peak_contact_force": [("force", j) for j in contacts],
            "max_absorber_velocity": [("v", model.body(a.body)) for a in model.absorbers],
            "impacts": [("impacts", j) for j in contacts],
            "peak_support_force": [("support",)],
        }
        self.observed = {item: -math.inf for items in self.items.values() for item in items
                         if item[0] in ("x", "v")}
        self.observed.update({item: 0.0 for items in self.items.values() for item in items
                              if item[0] in ("force", "support")})
        self.final_items: set = set()

    @property
    def final(self) -> set[str]:
        """The metrics proven final so far."""
        return {name for name, items in self.items.items() if set(items) <= self.final_items}

    @property
    def done(self) -> bool:
        return self.enabled and bool(self.requested) and set(self.requested) <= self.final

    def observe_segment(self, mode: Mode, sol, t0: float, t1: float) -> None:
        """Fold the values of one finished segment (dense output ``sol`` on [t0, t1]) into the maxima."""
        ts = np.asarray(sol.ts, dtype=float)
        ts = np.unique(np.concatenate(([t0], ts[(ts > t0) & (ts < t1)], [t1])))
        y = sol(ts)
        evaluation = self.model.evaluate(mode, y, t=ts)
        connectors = self.model.connectors
        for item in self.observed:
            kind = item[0]
            if kind == "x":
                value = np.max(y[2 * item[1]])
            elif kind == "v":
                value = np.max(y[2 * item[1] + 1])
            elif kind == "force":
                value = np.max(connectors[item[1]].reported(evaluation.forces[item[1]]))
            else:
                value = np.max(np.abs(self._support(evaluation)))
            self.observed[item] = max(self.observed[item], float(value))

    def _support(self, evaluation):
        """|S| from the reported (clipped) forces of the connectors touching the ground (N)."""
        return sum(c.support_sign * c.reported(evaluation.forces[c.index])
                   for c in self.model.connectors if c.support_sign != 0)

    def gaps(self, y, mode: Mode, names=None, continuous: bool = False) -> dict[str, float]:
        """Relative margin ``(observed - bound) / |observed|`` per metric in ``names`` (default: the
        requested ones) not yet final: the smallest over its items not yet final; final once >=
        -:data:`ROOT_TOLERANCE`.  ``mode``: the current segment's (a contact with a force is in an episode,
        whose impact is not decided yet).  ``continuous`` leaves out the own-energy refinement (see
        :meth:`EnergyBounds.bounds`)."""
        names = self.requested if names is None else names
        energy = float(self.model.mechanical_energy(y)) * (1.0 + ENERGY_SLACK)
        b = self.energy_bounds.bounds(energy, y, continuous)
        out = {}
        for name in names:
            margins = [self._margin(item, b, mode) for item in self.items[name] if item not in self.final_items]
            if margins:
                out[name] = min(margins)
        return out

    def item_gaps(self, y, mode: Mode) -> dict[tuple, float]:
        """Margin of every item not yet final (as :meth:`gaps`, item by item)."""
        energy = float(self.model.mechanical_energy(y)) * (1.0 + ENERGY_SLACK)
        b = self.energy_bounds.bounds(energy, y)
        return {item: self._margin(item, b, mode) for items in self.items.values() for item in items
                if item not in self.final_items}

    def _margin(self, item, b: dict, mode: Mode) -> float:
        kind = item[0]
        if kind == "impacts":
            j = item[1]
            in_episode = mode.states[j].phase != "off"
            observed, bound = self.impact_threshold, (math.inf if in_episode else b["force"][j])
        elif kind == "support":
            observed, bound = self.observed[item], b["support"]
        else:
            observed, bound = self.observed[item], b[kind][item[1]]
        if not math.isfinite(bound) or not math.isfinite(observed):
            return -math.inf
        return (observed - bound) / (abs(observed) if observed != 0 else 1.0)

    def check(self, y, mode: Mode, names=None) -> None:
        """Mark the items (of the metrics in ``names``, default the requested ones) that ``y`` proves final."""
        if not self.enabled:
            return
        wanted = {item for name in (self.requested if names is None else names) for item in self.items[name]}
        for item, gap in self.item_gaps(y, mode).items():
            if item in wanted and gap >= -ROOT_TOLERANCE:
                self.final_items.add(item)

    def stop_event(self, mode: Mode):
        """Terminal solve_ivp event: crosses 0 upwards when every requested metric becomes final.

        Uses the maxima observed *before* the segment: a bound below them is below the maximum
        up to the event too.
        """
        def event(t, y):
            gaps = self.gaps(y, mode, continuous=True)
            return min(1.0, max(-1.0, min(gaps.values()))) if gaps else 1.0
        event.terminal = True
        event.direction = 1.0
        return event
