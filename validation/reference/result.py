"""Result of the scipy reference solve: dense output per smooth segment, and refined metrics.

Every metric is located on the dense interpolant, not on samples: a maximum of ``f`` is found at a root of
``f'`` (``brentq`` on the interpolated derivative, bracketed on the solver's steps subdivided 4 times)
or at a segment end (segment ends are the exact events of :mod:`validation.reference.solver`).  Nothing
here names an effect: bodies, connectors, contacts and the roles (absorbers, stops) come from the model
(:mod:`validation.reference.model`); only the version-1 names of the API (``barrel_position``,
``peak_contact_force``, ...) say which body or connector they read.

Names (DESIGN.md): bodies ``barrel`` and the absorbers' names; connectors ``recoil_spring``,
``recoil_damper``, ``absorber_damper`` and ``contact`` (one absorber) or ``<name>_damper`` and
``<name>_contact`` (several), and each end stop's connector, named like its table.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from functools import cached_property
from typing import Any, Callable

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from .finality import METRICS
from .model import Mode, Model

#: Why a solve ended (:attr:`ReferenceResult.stop_reason`).
STOP_END_TIME = "end_time"
STOP_METRICS_FINAL = "metrics_final"
STOP_NO_BOUND = "end_time_no_energy_bound"
#: A barrel within this distance (m) of x = 0 is in battery (the per-shot outputs of a burst).
BATTERY_TOLERANCE = 1e-3
_SUBDIVISIONS = 4
#: Local maxima whose bracket stays this fraction of the value range below the best grid value are not
#: refined: between two grid points (a quarter of a solver step) no solution rises that much.
_PRUNE = 1e-2


@dataclass(frozen=True)
class ReferenceSegment:
    """One smooth piece ``[t0, t1]`` (s) integrated in one ``mode``; ``sol(t)`` is the state's dense output."""

    t0: float
    t1: float
    mode: Mode
    sol: Any  # scipy.integrate.OdeSolution


@dataclass(frozen=True)
class ReferenceImpact:
    """A contact episode (maximal interval with F > 0) of contact ``contact``; it is an impact when its peak
    rises above the force the contact held at rest when it began by more than the impact threshold
    (:meth:`ReferenceResult.force_at_rest_before`).  start, end, time_of_peak in s; peak_force in N."""

    start: float
    end: float
    peak_force: float
    time_of_peak: float
    contact: str = ""

    @property
    def duration(self) -> float:
        """Contact duration in s."""
        return self.end - self.start


@dataclass(frozen=True)
class ContactMetrics:
    """One contact: its peak force (N) and time (s), episodes, impacts (those rising above the threshold) and onsets
    ``(t, v-)`` (s, m/s: the start of every interval with p > 0 and p' there).  Peak and impacts are None
    when an early stop did not prove them final."""

    name: str
    peak_force: float | None
    time_of_peak: float | None
    episodes: list
    impacts: list | None
    onsets: list


@dataclass(frozen=True)
class StopMetrics(ContactMetrics):
    """An end stop: its contact's metrics and its dissipated energy at the end time (J)."""

    dissipated_energy: float = 0.0


@dataclass(frozen=True)
class AbsorberMetrics:
    """One absorber: peak contact force (N) and time (s), largest velocity (m/s) and time, impacts."""

    name: str
    peak_contact_force: float | None
    time_of_peak_contact_force: float | None
    max_velocity: float | None
    time_of_max_velocity: float | None
    impacts: list | None


def _grid(seg: ReferenceSegment) -> np.ndarray:
    """The solver's step points of ``seg``, each step subdivided ``_SUBDIVISIONS`` times."""
    ts = np.asarray(seg.sol.ts, dtype=float)
    ts = ts[(ts >= seg.t0) & (ts <= seg.t1)]
    ts = np.unique(np.concatenate(([seg.t0], ts, [seg.t1])))
    frac = np.arange(_SUBDIVISIONS) / _SUBDIVISIONS
    inner = ts[:-1, None] + np.diff(ts)[:, None] * frac[None, :]
    return np.concatenate((inner.ravel(), ts[-1:]))


def _best(candidates) -> tuple[float, float]:
    """(t, f) with the largest f; the earliest on ties."""
    return max(candidates, key=lambda c: (c[1], -c[0]))


def _peak(segments, value: Callable, deriv: Callable) -> tuple[float, float]:
    """Largest ``f = value(mode, y, t)`` over ``segments`` as ``(t, f)``: segment ends and interior maxima.

    ``deriv(mode, y, t)`` is df/dt, or None where it has no closed form (then a bounded scalar maximisation
    around the segment's grid maximum).  Interior maxima are roots of df/dt where it falls through 0.
    """
    grids = []
    for seg in segments:
        tg = _grid(seg)
        yg = seg.sol(tg)
        grids.append((seg, tg, yg, np.broadcast_to(value(seg.mode, yg, tg), tg.shape)))
    top = max(float(fg.max()) for *_, fg in grids)
    floor = top - _PRUNE * (top - min(float(fg.min()) for *_, fg in grids))
    out = []
    for seg, tg, yg, fg in grids:
        out += [(float(tg[0]), float(fg[0])), (float(tg[-1]), float(fg[-1]))]
        if fg.max() < floor:
            continue
        dg = deriv(seg.mode, yg, tg)
        if dg is None:  # no analytic derivative: bounded scalar maximisation around the grid maximum
            i = int(np.argmax(fg))
            if 0 < i < len(tg) - 1:
                res = minimize_scalar(lambda s: -float(value(seg.mode, seg.sol(s), s)), bounds=(tg[i - 1], tg[i + 1]),
                                      method="bounded", options={"xatol": 1e-15})
                out.append((float(res.x), -float(res.fun)))
            continue
        dg = np.broadcast_to(dg, tg.shape)
        for i in np.nonzero((dg[:-1] > 0) & (dg[1:] <= 0) & (np.maximum(fg[:-1], fg[1:]) >= floor))[0]:
            tr = brentq(lambda s: float(deriv(seg.mode, seg.sol(s), s)), tg[i], tg[i + 1], xtol=1e-16, maxiter=200)
            out.append((float(tr), float(value(seg.mode, seg.sol(tr), tr))))
    return _best(out)


def _first_below(segments, t_from: float, level: float) -> float | None:
    """First time >= ``t_from`` (s) at which x_M <= ``level`` (m) over ``segments``, by a scan of each
    segment's grid (:func:`_grid`) and ``brentq`` on the dense output; None if it stays above."""
    for seg in segments:
        if seg.t1 < t_from:
            continue
        tg = _grid(seg)
        tg = np.concatenate(([max(t_from, seg.t0)], tg[tg > t_from]))
        x = seg.sol(tg)[0]
        below = np.nonzero(x <= level)[0]
        if not below.size:
            continue
        i = int(below[0])
        if i == 0:
            return float(tg[0])
        return float(brentq(lambda s: float(seg.sol(s)[0]) - level, tg[i - 1], tg[i], xtol=1e-16, maxiter=200))
    return None


def _barrel_x(mode, y, t):
    return y[0]


def _barrel_v(mode, y, t):
    return y[1]


def _runs(segments, active: Callable) -> list[list[ReferenceSegment]]:
    """Maximal runs of consecutive segments for which ``active(segment)`` holds."""
    runs, run = [], []
    for seg in segments:
        if active(seg):
            run.append(seg)
        elif run:
            runs.append(run)
            run = []
    return runs + ([run] if run else [])


@dataclass
class ReferenceResult:
    """Dense reference solution of one scene over ``[0, end_time]`` s, with metrics (SI units).

    ``requested_end_time`` is what was asked; ``end_time`` is earlier only when ``stop_when_final``
    stopped the solve (``stop_reason == "metrics_final"``): then metrics not listed in
    ``final_metrics`` (and their times; ``impacts`` too) are None, never values of the shorter window.
    Absorber metrics are None without absorbers; the absorber-specific histories (``absorber_position``,
    ``penetration``, ``contact_force``, ``accelerations``, ``contact_episodes``) read the one absorber
    (0 / None without) and raise ValueError with several (use ``position(name, t)``, ``contacts``).
    """

    scene: Any
    model: Model
    end_time: float
    segments: list[ReferenceSegment]
    method: str = "DOP853"
    rtol: float = 1e-10
    atol: float = 1e-12
    impact_threshold: float = 1000.0
    nfev: int = 0
    wall_time: float = 0.0
    requested_end_time: float | None = None
    stop_reason: str = STOP_END_TIME
    final_metrics: tuple[str, ...] = METRICS
    _starts: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        self._starts = np.array([s.t0 for s in self.segments])
        if self.requested_end_time is None:
            self.requested_end_time = self.end_time

    def _final(self, metric: str) -> bool:
        return metric in self.final_metrics

    # ---------------------------------------------------------------- names
    @property
    def bodies(self) -> tuple[str, ...]:
        """Body names in state order: ``barrel``, then the absorbers."""
        return tuple(b.name for b in self.model.bodies)

    @property
    def connectors(self) -> tuple[str, ...]:
        """Connector names in scene order (only those that exist)."""
        return self.model.names

    def _one_absorber(self):
        """The one absorber's role (None without; ValueError with several)."""
        absorbers = self.model.absorbers
        if len(absorbers) > 1:
            raise ValueError(f"the scene has {len(absorbers)} absorbers ({', '.join(a.name for a in absorbers)}): "
                             f"use position(name, t), velocity(name, t), connector_force(name, t), contacts, "
                             f"absorber_metrics")
        return absorbers[0] if absorbers else None

    # ---------------------------------------------------------------- evaluation
    def _per_segment(self, t, fn: Callable, rows: int | None):
        """Evaluate ``fn(mode, y, t)`` at times ``t`` (scalar or array) using each time's segment (at a
        segment boundary the later one: the state after a shot's velocity jump)."""
        scalar = np.ndim(t) == 0
        ta = np.atleast_1d(np.asarray(t, dtype=float))
        span = 1e-12 * max(1.0, self.end_time)
        if ta.size and (ta.min() < -span or ta.max() > self.end_time + span):
            raise ValueError(f"times must lie in [0, {self.end_time}] s")
        idx = np.clip(np.searchsorted(self._starts, ta, side="right") - 1, 0, len(self.segments) - 1)
        out = np.empty((rows, ta.size) if rows else ta.size)
        for i in np.unique(idx):
            sel = idx == i
            seg = self.segments[i]
            out[..., sel] = fn(seg.mode, seg.sol(ta[sel]), ta[sel])
        return out[..., 0] if scalar else out

    def _evaluated(self, t, pick: Callable, rows: int | None = None):
        """``pick(evaluation, y)`` of :meth:`Model.evaluate` at times ``t``."""
        model = self.model
        return self._per_segment(t, lambda mode, y, ts: pick(model.evaluate(mode, y, t=ts), y), rows)

    def state(self, t):
        """State ``[x_0, v_0, x_1, v_1, ..., D_0, ...]`` at ``t`` (s): shape (n,) or (n, len(t))."""
        return self._per_segment(t, lambda mode, y, ts: y, self.model.n_states)

    def position(self, body: str, t):
        """x of ``body`` (m)."""
        i = self.model.body(body)
        return self._per_segment(t, lambda mode, y, ts: y[2 * i], None)

    def velocity(self, body: str, t):
        """v of ``body`` (m/s)."""
        i = self.model.body(body)
        return self._per_segment(t, lambda mode, y, ts: y[2 * i + 1], None)

    def acceleration(self, body: str, t):
        """a of ``body`` (m/s^2)."""
        i = self.model.body(body)
        return self._evaluated(t, lambda ev, y: ev.accelerations[i])

    def connector_force(self, name: str, t):
        """F of connector ``name`` (N; contacts >= 0): it pushes b towards -x and a towards +x."""
        c = self.model.connector(name)
        return self._evaluated(t, lambda ev, y: c.reported(ev.forces[c.index]))

    def support_force(self, t):
        """S = sum of F over connectors from the ground - sum over connectors to the ground (N, positive in
        the recoil direction): the force on the mount."""
        return self._evaluated(t, lambda ev, y: self._support(ev))

    def _support(self, ev):
        return sum((c.support_sign * c.reported(ev.forces[c.index]) for c in self.model.connectors
                    if c.support_sign != 0), 0.0)

    def barrel_position(self, t):
        """x_M (m)."""
        return self.position("barrel", t)

    def barrel_velocity(self, t):
        """v_M (m/s)."""
        return self.velocity("barrel", t)

    def absorber_position(self, t):
        """x_m (m) of the one absorber; 0 without absorber."""
        a = self._one_absorber()
        return 0.0 * self.barrel_position(t) if a is None else self.position(a.body, t)

    def absorber_velocity(self, t):
        """v_m (m/s) of the one absorber; 0 without absorber."""
        a = self._one_absorber()
        return 0.0 * self.barrel_position(t) if a is None else self.velocity(a.body, t)

    def penetration(self, t):
        """Penetration p (m) of the one absorber's contact; 0 without absorber."""
        a = self._one_absorber()
        if a is None:
            return 0.0 * self.barrel_position(t)
        c = self.model.connector(a.contact)
        return self._per_segment(t, lambda mode, y, ts: c.d_of(y) - c.offset, None)

    def contact_force(self, t):
        """Contact force F (N, >= 0) of the one absorber; 0 without absorber."""
        a = self._one_absorber()
        return 0.0 * self.barrel_position(t) if a is None else self.connector_force(a.contact, t)

    def accelerations(self, t):
        """(a_M, a_m) in m/s^2 (a_m = 0 without absorber), shape (2,) or (2, len(t))."""
        a = self._one_absorber()
        j = None if a is None else self.model.body(a.body)
        return self._evaluated(t, lambda ev, y: np.array([ev.accelerations[0],
                                                          0.0 * y[0] if j is None else ev.accelerations[j]]), 2)

    # ---------------------------------------------------------------- energy
    def kinetic_energy(self, t) -> dict[str, np.ndarray]:
        """m v^2 / 2 per body (J)."""
        return self.model.kinetic_energies(self.state(t))

    def stored_energy(self, t) -> dict[str, np.ndarray]:
        """U per connector that stores energy: springs ``k d^2 / 2``, contacts' elastic energy (J)."""
        return self.model.stored_energies(self.state(t))

    def dissipated_energy_history(self, t) -> dict[str, np.ndarray]:
        """Dissipated energy D per dissipating connector (J) at ``t``."""
        return self.model.dissipated_energies(self.state(t))

    @property
    def dissipated_energy(self) -> dict[str, float]:
        """Dissipated energies at ``end_time`` in J, by connector (``recoil_damper``, ``absorber_damper``,
        ``contact``, ...: only connectors that exist and dissipate)."""
        return {k: float(v) for k, v in self.dissipated_energy_history(self.end_time).items()}

    def work_history(self, t) -> dict[str, np.ndarray]:
        """Work W (J) done on the bodies by each external input at ``t``, by name: a load's
        ``integral_0^t L v_body dt`` (``breech_force``, ...), the velocity jumps' ``sum m ((v + dv)^2 - v^2) / 2``
        (``burst``: the shots after the first).  Empty for a scene without inputs."""
        return self.model.works(self.state(t))

    @property
    def work(self) -> dict[str, float]:
        """:meth:`work_history` at ``end_time`` (J), by input."""
        return {k: float(v) for k, v in self.work_history(self.end_time).items()}

    def load_force(self, name: str, t):
        """The external load ``name`` (N, on its body, positive in the recoil direction) at ``t`` (s)."""
        loads = {load.name: load for load in self.model.loads}
        if name not in loads:
            raise KeyError(f"no load {name!r}; the scene has: {', '.join(loads) or 'none'}")
        return loads[name].force(t)

    def energy_components(self, t) -> dict[str, np.ndarray]:
        """The mechanical and dissipated parts of the energy balance (J): ``kinetic:<body>``,
        ``stored:<connector>``, ``dissipated:<connector>``; :meth:`energy_balance` is their sum minus the
        work of the external inputs (:meth:`work_history`)."""
        y = self.state(t)
        model = self.model
        return {**{f"kinetic:{k}": v for k, v in model.kinetic_energies(y).items()},
                **{f"stored:{k}": v for k, v in model.stored_energies(y).items()},
                **{f"dissipated:{k}": v for k, v in model.dissipated_energies(y).items()}}

    def energy_balance(self, t):
        """Total energy (J): kinetic + stored + dissipated - work of the inputs; constant = initial_energy."""
        total = sum(self.energy_components(t).values())
        if self.model.work_slot:
            total = total - sum(self.work_history(t).values())
        return total

    @property
    def initial_energy(self) -> float:
        """Energy at t = 0 in J (initial kinetic energy, plus elastic energy of an initial interference)."""
        return float(self.energy_balance(0.0))

    def sample(self, n=None) -> dict[str, np.ndarray]:
        """Arrays on a time grid: the solver's step points (``n=None``), ``n`` uniform points, or given times.

        Keys: ``t``; ``x_M``, ``v_M``; ``x:<body>``, ``v:<body>``, ``F:<connector>``, ``E_<connector>``
        (dissipated), ``load:<load>`` (N), ``work:<input>`` (J), ``support_force``; with at most one absorber also ``x_m``, ``v_m``,
        ``contact_force``, ``penetration`` (0 without absorber).
        """
        if n is None:
            ts = [np.asarray(s.sol.ts, dtype=float) for s in self.segments]
            t = np.unique(np.concatenate([[0.0]] + [x[(x >= s.t0) & (x <= s.t1)] for x, s in zip(ts, self.segments)]
                                         + [[self.end_time]]))
        elif np.ndim(n) == 0:
            t = np.linspace(0.0, self.end_time, int(n))
        else:
            t = np.asarray(n, dtype=float)
        y = self.state(t)
        out = {"t": t, "x_M": y[0], "v_M": y[1]}
        for i, name in enumerate(self.bodies):
            out[f"x:{name}"], out[f"v:{name}"] = y[2 * i], y[2 * i + 1]
        for name in self.connectors:
            out[f"F:{name}"] = self.connector_force(name, t)
        for name, history in self.model.dissipated_energies(y).items():
            out[f"E_{name}"] = history
        for load in self.model.loads:
            out[f"load:{load.name}"] = load.force(t)
        for name, history in self.model.works(y).items():
            out[f"work:{name}"] = history
        out["support_force"] = self.support_force(t)
        if len(self.model.absorbers) <= 1:
            out["x_m"], out["v_m"] = self.absorber_position(t), self.absorber_velocity(t)
            out["contact_force"], out["penetration"] = self.contact_force(t), self.penetration(t)
        return out

    # ---------------------------------------------------------------- refined maxima
    def _force_value(self, j: int) -> Callable:
        c, model = self.model.connectors[j], self.model
        return lambda mode, y, t: c.reported(model.evaluate(mode, y, t=t).forces[j])

    def _force_rate(self, j: int) -> Callable:
        """dF/dt of connector j (N/s), or None in a state without a closed form."""
        c, model = self.model.connectors[j], self.model

        def rate(mode, y, t):
            return c.force_rate(mode.states[j], c.d_of(y), c.rate_of(y),
                                model.relative_acceleration(c, model.evaluate(mode, y, t=t)))
        return rate

    @cached_property
    def _barrel_max(self):
        return _peak(self.segments, _barrel_x, _barrel_v)

    @cached_property
    def _velocity_max(self) -> dict[str, tuple[float, float]]:
        """(t, v_max) per absorber."""
        model, out = self.model, {}
        for a in model.absorbers:
            i = model.body(a.body)
            out[a.name] = _peak(self.segments, lambda mode, y, t: y[2 * i + 1],
                                lambda mode, y, t: model.evaluate(mode, y, t=t).accelerations[i])
        return out

    @cached_property
    def _episodes(self) -> dict[str, list[ReferenceImpact]]:
        """Per contact: every episode (maximal run of segments with a force), with its peak."""
        out = {}
        for c in self.model.contacts:
            j, value, rate = c.index, self._force_value(c.index), self._force_rate(c.index)
            episodes = []
            for run in _runs(self.segments, lambda seg: seg.mode.states[j].phase != "off"):
                t_peak, f_peak = _peak(run, value, rate)
                episodes.append(ReferenceImpact(run[0].t0, run[-1].t1, f_peak, t_peak, c.name))
            out[c.name] = episodes
        return out

    def _onsets(self, j: int) -> list[tuple[float, float]]:
        """(t, v-) at the start of every interval with p > 0 of contact j."""
        out, before = [], False
        for seg in self.segments:
            state = seg.mode.states[j]
            if state.penetrated and not before:
                out.append((seg.t0, state.onset_rate))
            before = state.penetrated
        return out

    def _contact_peak(self, name: str) -> tuple[float, float]:
        """(t, F) of the largest force of contact ``name``; (0, 0) if it never touched."""
        episodes = self._episodes[name]
        if not episodes:
            return (0.0, 0.0)
        best = max(episodes, key=lambda e: (e.peak_force, -e.time_of_peak))
        return (best.time_of_peak, best.peak_force)

    def force_at_rest_before(self, contact: str, start: float) -> float:
        """The force (N) that contact ``contact`` held at rest when an episode of it began at ``start`` (s): 0
        for an episode that begins inside the window (the contact was open just before it), the static force
        ``k p(0)^n`` of the initial penetration for an episode going on at t = 0 (an initial interference)."""
        t0 = self.segments[0].t0
        if start > t0:
            return 0.0
        c = self.model.connector(contact)
        return c.static_force(float(c.d_of(self.state(t0))))

    def _impacts_of(self, name: str) -> list[ReferenceImpact]:
        """The episodes of contact ``name`` that are impacts (DESIGN.md, "Outputs every scene gets"): the peak
        force rises above the force the contact held at rest when the episode began
        (:meth:`force_at_rest_before`) by more than ``impact_threshold``.  A preload holding the barrel on its
        stop from t = 0 is then no impact (unless something presses it harder)."""
        return [e for e in self._episodes[name]
                if e.peak_force - self.force_at_rest_before(name, e.start) > self.impact_threshold]

    @cached_property
    def _support_max(self) -> tuple[float, float]:
        """(t, |S|max) over the run."""
        ground = [c for c in self.model.connectors if c.support_sign != 0]
        if not ground:
            return (0.0, 0.0)
        values = {c.index: self._force_value(c.index) for c in ground}
        rates = {c.index: self._force_rate(c.index) for c in ground}

        def support(mode, y, t):
            return sum(c.support_sign * values[c.index](mode, y, t) for c in ground)

        def value(mode, y, t):
            return np.abs(support(mode, y, t))

        def deriv(mode, y, t):
            parts = [rates[c.index](mode, y, t) for c in ground]
            if any(p is None for p in parts):
                return None
            return np.sign(support(mode, y, t)) * sum(c.support_sign * p for c, p in zip(ground, parts))
        return _peak(self.segments, value, deriv)

    # ---------------------------------------------------------------- shots
    def _window(self, k: int, times) -> list[ReferenceSegment]:
        """The segments between shot ``k`` and the next one (or the end): the shot times are time events,
        so segments never straddle them."""
        w0 = times[k]
        w1 = times[k + 1] if k + 1 < len(times) else self.end_time
        return [seg for seg in self.segments if seg.t0 >= w0 and seg.t1 <= w1]

    def _transient_impulse(self, t0: float, t1: float) -> float | None:
        """``integral L dt`` (N s) over [t0, t1] of the loads that end (a breech pulse; not a constant load);
        None without such a load."""
        loads = [load for load in self.model.loads if math.isfinite(load.last_input_time)]
        return sum(load.impulse(t0, t1) for load in loads) if loads else None

    @property
    def pulse_impulse(self) -> float | None:
        """Impulse (N s) of the first shot's breech-force pulse (``integral F dt`` of the loads that end,
        between the first and the second shot); None without a pulse."""
        times = self.model.shot_times or (0.0,)
        return self._transient_impulse(times[0], times[1] if len(times) > 1 else math.inf)

    @cached_property
    def shots(self) -> list[dict[str, Any]] | None:
        """Per shot of a burst fired in ``[0, end_time)``, in order (None without a burst), a dict:

        * ``shot`` (k + 1: 1, 2, ...), ``time`` (t_k, s);
        * ``max_barrel_displacement`` (m) and ``time_of_max_barrel_displacement`` (s): the largest x_M over
          ``[t_k, t_(k+1)]`` (the last shot: ``[t_k, end_time]``), refined on the dense output;
        * ``position_at_next_shot`` (m), ``velocity_at_next_shot`` (m/s): x_M and v_M just before shot k + 1
          fires (before its velocity jump); ``in_battery_at_next_shot``: ``|x_M| <=``
          :data:`BATTERY_TOLERANCE` then (None for the last shot);
        * ``time_to_battery`` (s after t_k): the first time after the window's maximum at which
          ``x_M <= BATTERY_TOLERANCE`` (back within 1 mm of battery), found inside the window (None if it
          does not return before the next shot or the end; the maximum itself if it is within 1 mm).

        After an early stop (``stop_reason == "metrics_final"``) the last shot's maximum is None unless
        ``max_barrel_displacement`` is final and lies in its window, and its ``time_to_battery`` is None
        unless the return happened before the stop.
        """
        if self.model.shot_times is None:
            return None
        times = [t for t in self.model.shot_times if t == 0.0 or t < self.end_time]
        stopped = self.stop_reason == STOP_METRICS_FINAL
        out = []
        for k, t_k in enumerate(times):
            window = self._window(k, times)
            last = k == len(times) - 1
            t_max, x_max = _peak(window, _barrel_x, _barrel_v)
            if last and stopped:
                proven = self._final("max_barrel_displacement") and self._barrel_max[0] >= t_k
                t_max, x_max = (t_max, x_max) if proven else (None, None)
            shot = {"shot": k + 1, "time": t_k, "max_barrel_displacement": x_max,
                    "time_of_max_barrel_displacement": t_max,
                    "position_at_next_shot": None, "velocity_at_next_shot": None, "in_battery_at_next_shot": None}
            if not last:
                y = window[-1].sol(times[k + 1])
                shot.update(position_at_next_shot=float(y[0]), velocity_at_next_shot=float(y[1]),
                            in_battery_at_next_shot=bool(abs(y[0]) <= BATTERY_TOLERANCE))
            if t_max is None:  # the window's maximum is not known: search from the window's largest so far
                t_from = _peak(window, _barrel_x, _barrel_v)[0]
            else:
                t_from = t_max
            back = _first_below(window, t_from, BATTERY_TOLERANCE)
            shot["time_to_battery"] = None if back is None else back - t_k
            out.append(shot)
        return out

    # ---------------------------------------------------------------- metrics
    @property
    def max_barrel_displacement(self) -> float | None:
        """Largest x_M over [0, end_time] in m (None if the solve stopped before proving it final)."""
        return self._barrel_max[1] if self._final("max_barrel_displacement") else None

    @property
    def time_of_max_barrel_displacement(self) -> float | None:
        """Time (s) of :attr:`max_barrel_displacement`."""
        return self._barrel_max[0] if self._final("max_barrel_displacement") else None

    @property
    def time_to_battery(self) -> float | None:
        """Time (s after the shot at t = 0) a single shot's barrel is back in battery (DESIGN.md, "Outputs every
        scene gets"): the first ``t >= t_max`` (the time of :attr:`max_barrel_displacement`) with
        ``x_M(t) <= x_M(0) + BATTERY_TOLERANCE``, by a scan of the dense output and ``brentq``; ``t_max`` when the
        maximum is already that low.  None with a burst (see :attr:`shots`), when the maximum is not final, when
        the maximum is the end of the window with the barrel still moving out, or when it is not back by
        ``end_time``."""
        if self.model.shot_times is not None or not self._final("max_barrel_displacement"):
            return None
        t_max, x_max = self._barrel_max
        first, last = self.segments[0], self.segments[-1]
        if t_max >= last.t1 and float(last.sol(last.t1)[1]) > 0.0:
            return None
        level = float(first.sol(first.t0)[0]) + BATTERY_TOLERANCE
        if x_max <= level:
            return t_max
        return _first_below(self.segments, t_max, level)

    def _largest(self, pairs, metric: str):
        pairs = list(pairs)
        return _best(pairs) if pairs and self._final(metric) else None

    @property
    def max_absorber_velocity(self) -> float | None:
        """Largest absorber velocity (m/s) over all absorbers; None without absorbers."""
        best = self._largest(self._velocity_max.values(), "max_absorber_velocity")
        return None if best is None else best[1]

    @property
    def time_of_max_absorber_velocity(self) -> float | None:
        """Time (s) of :attr:`max_absorber_velocity`."""
        best = self._largest(self._velocity_max.values(), "max_absorber_velocity")
        return None if best is None else best[0]

    @property
    def peak_contact_force(self) -> float | None:
        """Largest absorber contact force (N) over all absorbers; 0 if never in contact; None without."""
        best = self._largest((self._contact_peak(a.contact) for a in self.model.absorbers), "peak_contact_force")
        return None if best is None else best[1]

    @property
    def time_of_peak_contact_force(self) -> float | None:
        """Time (s) of :attr:`peak_contact_force`."""
        best = self._largest((self._contact_peak(a.contact) for a in self.model.absorbers), "peak_contact_force")
        return None if best is None else best[0]

    @property
    def peak_support_force(self) -> float | None:
        """Largest |S| over the run (N, >= 0)."""
        return self._support_max[1] if self._final("peak_support_force") else None

    @property
    def time_of_peak_support_force(self) -> float | None:
        """Time (s) of :attr:`peak_support_force`."""
        return self._support_max[0] if self._final("peak_support_force") else None

    @property
    def impacts(self) -> list[ReferenceImpact] | None:
        """The absorbers' contacts' impacts (episodes whose peak rises above the force at rest they began with by
        more than ``impact_threshold`` N), in time order
        ([] without absorbers; None if the solve stopped before proving the list final)."""
        if not self._final("impacts"):
            return None
        found = [e for a in self.model.absorbers for e in self._impacts_of(a.contact)]
        return sorted(found, key=lambda e: (e.start, e.end))

    @property
    def contact_episodes(self) -> list[ReferenceImpact] | None:
        """Every episode of the one absorber's contact, whatever its peak force; None without absorber."""
        a = self._one_absorber()
        return None if a is None else list(self._episodes[a.contact])

    def _contact_metrics(self, c, cls=ContactMetrics, **extra):
        peak = self._contact_peak(c.name) if self._final("peak_contact_force") else (None, None)
        impacts = self._impacts_of(c.name) if self._final("impacts") else None
        return cls(c.name, peak[1], peak[0], list(self._episodes[c.name]), impacts, self._onsets(c.index), **extra)

    @property
    def contacts(self) -> dict[str, ContactMetrics]:
        """Every contact (absorbers' and stops'), by connector name."""
        return {c.name: self._contact_metrics(c) for c in self.model.contacts}

    @property
    def absorber_metrics(self) -> list[AbsorberMetrics]:
        """Per absorber, in scene order."""
        out = []
        for a in self.model.absorbers:
            contact = self._contact_metrics(self.model.connector(a.contact))
            v = self._velocity_max[a.name] if self._final("max_absorber_velocity") else (None, None)
            out.append(AbsorberMetrics(a.name, contact.peak_force, contact.time_of_peak, v[1], v[0], contact.impacts))
        return out

    @property
    def stop_metrics(self) -> dict[str, StopMetrics]:
        """Per end stop: its contact's metrics and dissipated energy (J)."""
        dissipated = self.dissipated_energy
        return {name: self._contact_metrics(self.model.connector(name), StopMetrics,
                                            dissipated_energy=dissipated[name]) for name in self.model.stops}

    def metrics(self) -> dict[str, Any]:
        """The DESIGN.md metric set as plain Python values (impacts as dicts)."""
        def impacts(items):
            return None if items is None else [asdict(i) for i in items]

        def contact(m):
            out = asdict(m)
            out["episodes"], out["impacts"] = impacts(m.episodes), impacts(m.impacts)
            out["onsets"] = [list(o) for o in m.onsets]
            return out
        return {
            "max_barrel_displacement": self.max_barrel_displacement,
            "time_of_max_barrel_displacement": self.time_of_max_barrel_displacement,
            "peak_contact_force": self.peak_contact_force,
            "time_of_peak_contact_force": self.time_of_peak_contact_force,
            "max_absorber_velocity": self.max_absorber_velocity,
            "time_of_max_absorber_velocity": self.time_of_max_absorber_velocity,
            "impacts": impacts(self.impacts),
            "peak_support_force": self.peak_support_force,
            "time_of_peak_support_force": self.time_of_peak_support_force,
            "time_to_battery": self.time_to_battery,
            "absorbers": [{**asdict(m), "impacts": impacts(m.impacts)} for m in self.absorber_metrics],
            "stops": {name: contact(m) for name, m in self.stop_metrics.items()},
            "end_time": self.end_time,
            "requested_end_time": self.requested_end_time,
            "stop_reason": self.stop_reason,
            "final_metrics": list(self.final_metrics),
            "dissipated_energy": self.dissipated_energy,
            "wall_time": self.wall_time,
            **self._input_metrics(),
        }

    def _input_metrics(self) -> dict[str, Any]:
        """``pulse_impulse`` (with a pulse), ``shots`` (with a burst), ``work`` (with external inputs): only
        for scenes that have them (the version-1 keys stay as they were)."""
        out: dict[str, Any] = {}
        if self.pulse_impulse is not None:
            out["pulse_impulse"] = self.pulse_impulse
        if self.shots is not None:
            out["shots"] = [dict(s) for s in self.shots]
        if self.model.work_slot:
            out["work"] = self.work
        return out
