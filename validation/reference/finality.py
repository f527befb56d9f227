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

**A nonlinear potential** (``nonlinear_potential``: the recuperator's gas spring, ``U(d) = integral_0^d F``
with ``F > 0``, negative for d < 0) breaks "every term of E is >= 0".  Such a connector between the
ground and a body, with that body's contacts with the ground (its stops), makes a **potential well**
``W(x) = sum_c U_c(+-x)`` of the body's position (``+x`` for ground -> body, ``-x`` for body -> ground): every
``U_c`` is convex (its force at rest never decreases with d), so W is, with its minimum ``W*`` where the
forces at rest balance.  All other terms of E and ``W - W*`` are >= 0, so everything above holds with
``E' = E - W*`` in place of E, and ``W(x) <= W* + E'`` confines x to an interval ``[lo, hi]`` (found by
Brent's method between doubling brackets; ``hi < V0/A`` since the gas spring's U diverges there), which
bounds the body's position, each member's |d| (``max(|lo|, |hi|)``, hence its force) and each member
contact's penetration (from the upper end of its d).  The slack then applies to E'.  A nonlinear potential
anywhere else, or a well without a minimum, gives no bound at all.

A metric is final once its observed maximum (a lower bound of the true one: values of the solution at the
solver's step points) reaches the bound of everything later: ``max_barrel_displacement`` (x of the barrel),
``max_absorber_velocity`` (every absorber's v), ``peak_contact_force`` (every contact's force: absorbers
and stops), ``peak_support_force`` (|S|), ``impacts`` (every contact: no episode going on and its force
bound below the impact threshold).  For ``impacts`` (an episode is one when its peak rises above the force
the contact held at rest when it began by more than the threshold -- 0 for an episode that begins inside
the window): every episode of an open contact is over, with the full run's record; every later one begins
inside the window from 0 N and peaks at most at the bound, so it is no impact.  A contact in an episode is
never final: the episode's end is still to come, and a preload's hold from t = 0 (no impact itself) may
still open and a new episode begin.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

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


class PotentialWell:
    """The well ``W(x)`` of a nonlinear potential and its body's stops (module docstring).

    Attributes: ``body`` (index, None if no well can be formed), ``members`` (connectors), ``floor`` (W*, J;
    -inf without a well), ``x_star`` (m).
    """

    #: |x| (m) beyond which no bracket is sought (no bound).
    FAR = 1e6

    def __init__(self, model: Model):
        gas = [c for c in model.connectors if c.nonlinear_potential]
        self.body, self.members, self.floor, self.x_star = None, [], -math.inf, math.nan
        bodies = {c.body_b if c.a == GROUND else c.body_a for c in gas}
        if not gas or any(GROUND not in (c.a, c.b) for c in gas) or len(bodies) != 1:
            return
        self.body = bodies.pop()
        self.members = gas + [c for c in model.contacts
                              if GROUND in (c.a, c.b) and self.body in (c.body_a, c.body_b)]
        self.sign = {c.index: 1.0 if c.a == GROUND else -1.0 for c in self.members}
        # x where every member's law is defined: d = s x < d_limit
        self.x_high = min([c.d_limit for c in self.members if self.sign[c.index] > 0], default=math.inf)
        self.x_low = max([-c.d_limit for c in self.members if self.sign[c.index] < 0], default=-math.inf)
        self._cache: dict = {}
        root = self._root(lambda x: sum(self.sign[c.index] * c.static_force(self.sign[c.index] * x)
                                        for c in self.members), 0.0)
        if root is not None:
            self.x_star = root
            self.floor = self.W(root)

    def W(self, x: float) -> float:
        """The well's potential (J) at the body's position x (m)."""
        return float(sum(c.stored_energy(self.sign[c.index] * x) for c in self.members))

    def _bracket(self, f, start: float, side: float):
        """A point beyond ``start`` on ``side`` where ``f >= 0`` (f < 0 at start): doubling steps, halving the
        way to a finite end of the domain; None if there is none."""
        end = self.x_high if side > 0 else self.x_low
        gap = 1e-9
        x_prev = start
        while True:
            if math.isfinite(end) and side * (end - start) <= gap:
                x = 0.5 * (x_prev + end)
                if x == x_prev or x == end:
                    return None
            else:
                x = start + side * gap
                if abs(x) > self.FAR:
                    return None
            if f(x) >= 0.0:
                return x_prev, x
            x_prev, gap = x, 2.0 * gap

    def _root(self, slope, start: float):
        """The root of the non-decreasing ``slope`` (the balance of the forces at rest), None without one."""
        value = slope(start)
        if value == 0.0:
            return start
        side = -1.0 if value > 0.0 else 1.0
        found = self._bracket(lambda x: side * slope(x), start, side)
        if found is None:
            return None
        return brentq(slope, min(found), max(found), xtol=1e-300, rtol=4.0 * np.finfo(float).eps, maxiter=500)

    def end(self, excess: float, side: float) -> float:
        """The end (m) on ``side`` (-1, +1) of ``W(x) <= W* + excess`` (J): the outermost float at or outside
        the root (a bound); +-inf if W never gets there."""
        if not excess > 0.0:
            return self.x_star
        if not math.isfinite(excess):
            return side * math.inf
        key = (excess, side)
        if key not in self._cache:
            level = self.floor + excess
            found = self._bracket(lambda x: self.W(x) - level, self.x_star, side)
            if found is None:
                value = side * math.inf if not math.isfinite(self.x_high if side > 0 else self.x_low) else \
                    (self.x_high if side > 0 else self.x_low)
            else:
                value = brentq(lambda x: self.W(x) - level, min(found), max(found), xtol=1e-300,
                               rtol=4.0 * np.finfo(float).eps, maxiter=500)
                while self.W(value) < level:
                    value = math.nextafter(value, side * math.inf)
            if len(self._cache) > 64:
                self._cache.clear()
            self._cache[key] = value
        return self._cache[key]


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
        #: the potential well of a nonlinear potential (None without one)
        self.well = PotentialWell(model) if any(c.nonlinear_potential for c in model.connectors) else None
        for i in range(nb):
            touching = [c for c in model.connectors if i in (c.body_a, c.body_b)]
            if all(c.support_sign != 0 or c.is_contact for c in touching) and \
                    (self.well is None or i != self.well.body):
                self._own_energy[i] = ([c for c in touching if c.support_sign != 0],
                                       [c for c in touching if c.support_sign == 0])

    @property
    def floor(self) -> float:
        """A lower bound (J) of the stored energy: 0, or the well's W*."""
        return 0.0 if self.well is None else self.well.floor

    def with_slack(self, energy: float) -> float:
        """``E (1 + ENERGY_SLACK)``; with a well ``W* + (E - W*) (1 + ENERGY_SLACK)`` (J)."""
        if self.well is None:
            return energy * (1.0 + ENERGY_SLACK)
        if math.isinf(self.well.floor):
            return energy
        return self.well.floor + (energy - self.well.floor) * (1.0 + ENERGY_SLACK)

    def _above_floor(self, energy: float) -> float:
        """``E' = E - W*`` (J): what bounds each non-negative term; E itself without a well."""
        if self.well is None:
            return energy
        return math.inf if math.isinf(self.well.floor) else max(energy - self.well.floor, 0.0)

    def _member(self, c) -> bool:
        return self.well is not None and any(c is m for m in self.well.members)

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
        energy = self._above_floor(energy)
        out = []
        for c, form in zip(self.model.connectors, self._connector_form):
            d = self._sqrt2(energy, form)
            rate = self._sqrt2(energy, c.inverse_reduced_mass)
            p = math.inf
            if self._member(c):  # from the well's interval: |d| <= max(|lo|, |hi|), d <= s-end
                lo, hi = self.well.end(energy, -1.0), self.well.end(energy, 1.0)
                d = max(abs(lo), abs(hi))
                if c.is_contact:
                    top = hi if self.well.sign[c.index] > 0 else -lo
                    p = top - c.offset if top > c.offset else 0.0
            elif c.is_contact:
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
        energy = self._above_floor(energy)
        x = [self._sqrt2(energy, form) for form in self._body_form]
        for i, c in self._ground_contacts:
            if not self._member(c):
                x[i] = min(x[i], c.offset + c.penetration_bound(energy))
        if self.well is not None and self.well.body is not None:
            x[self.well.body] = min(x[self.well.body], self.well.end(energy, 1.0))
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
        whose end, and for a hold from t = 0 what follows it, is not known yet).  ``continuous`` leaves out
        the own-energy refinement (see :meth:`EnergyBounds.bounds`)."""
        names = self.requested if names is None else names
        energy = self.energy_bounds.with_slack(float(self.model.mechanical_energy(y)))
        b = self.energy_bounds.bounds(energy, y, continuous)
        out = {}
        for name in names:
            margins = [self._margin(item, b, mode) for item in self.items[name] if item not in self.final_items]
            if margins:
                out[name] = min(margins)
        return out

    def item_gaps(self, y, mode: Mode) -> dict[tuple, float]:
        """Margin of every item not yet final (as :meth:`gaps`, item by item)."""
        energy = self.energy_bounds.with_slack(float(self.model.mechanical_energy(y)))
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
