"""Result of the scipy reference solve: dense output per smooth segment, and refined metrics.

Every metric is located on the dense interpolant, not on samples: a maximum of ``f`` is found at a root of
``f'`` (``brentq`` on the interpolated derivative, bracketed on the solver's steps subdivided 4 times)
or at a segment end (segment ends are the exact events of :mod:`validation.reference`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Callable

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from mbs_models.scene import Scene

from . import equations as eq
from .equations import OFF, ON, Mode, Parameters

#: Why a solve ended (:attr:`ReferenceResult.stop_reason`).
STOP_END_TIME = "end_time"
STOP_METRICS_FINAL = "metrics_final"
STOP_NO_BOUND = "end_time_no_energy_bound"
_ALL_FINAL = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "impacts")
_SUBDIVISIONS = 4
_STATE_NAMES = ("x_M", "v_M", "x_m", "v_m", "E_recoil_damper", "E_absorber_damper", "E_contact")
_DISSIPATION_KEYS = ("recoil_damper", "absorber_damper", "contact")


@dataclass(frozen=True)
class ReferenceSegment:
    """One smooth piece ``[t0, t1]`` (s) integrated in one ``mode``; ``sol(t)`` is the 7-state dense output."""

    t0: float
    t1: float
    mode: Mode
    sol: Any  # scipy.integrate.OdeSolution


@dataclass(frozen=True)
class ReferenceImpact:
    """A contact episode (maximal interval with F > 0) whose peak force exceeds the impact threshold.

    start, end, time_of_peak in s; peak_force in N.
    """

    start: float
    end: float
    peak_force: float
    time_of_peak: float

    @property
    def duration(self) -> float:
        """Contact duration in s."""
        return self.end - self.start


def _grid(seg: ReferenceSegment) -> np.ndarray:
    """The solver's step points of ``seg``, each step subdivided ``_SUBDIVISIONS`` times."""
    ts = np.asarray(seg.sol.ts, dtype=float)
    ts = ts[(ts >= seg.t0) & (ts <= seg.t1)]
    ts = np.unique(np.concatenate(([seg.t0], ts, [seg.t1])))
    frac = np.arange(_SUBDIVISIONS) / _SUBDIVISIONS
    inner = ts[:-1, None] + np.diff(ts)[:, None] * frac[None, :]
    return np.concatenate((inner.ravel(), ts[-1:]))


def _segment_maxima(seg: ReferenceSegment, value: Callable, deriv: Callable | None) -> list[tuple[float, float]]:
    """Candidate maxima ``(t, f)`` of ``f = value(mode, y)`` in a segment: its ends and interior peaks."""
    tg = _grid(seg)
    yg = seg.sol(tg)
    fg = np.broadcast_to(value(seg.mode, yg), tg.shape)
    out = [(float(tg[0]), float(fg[0])), (float(tg[-1]), float(fg[-1]))]
    if deriv is None:  # no analytic derivative: bounded scalar maximisation around the grid maximum
        i = int(np.argmax(fg))
        if 0 < i < len(tg) - 1:
            res = minimize_scalar(lambda s: -float(value(seg.mode, seg.sol(s))), bounds=(tg[i - 1], tg[i + 1]),
                                  method="bounded", options={"xatol": 1e-15})
            out.append((float(res.x), -float(res.fun)))
        return out
    dg = np.broadcast_to(deriv(seg.mode, yg), tg.shape)
    for i in np.nonzero((dg[:-1] > 0) & (dg[1:] <= 0))[0]:
        tr = brentq(lambda s: float(deriv(seg.mode, seg.sol(s))), tg[i], tg[i + 1], xtol=1e-16, maxiter=200)
        out.append((float(tr), float(value(seg.mode, seg.sol(tr)))))
    return out


def _best(candidates) -> tuple[float, float]:
    """(t, f) with the largest f; the earliest on ties."""
    return max(candidates, key=lambda c: (c[1], -c[0]))


@dataclass
class ReferenceResult:
    """Dense reference solution of one scene over ``[0, end_time]`` s, with metrics (SI units).

    Metrics for the absorber and the contact are ``None`` for the simplified model (no absorber).
    ``requested_end_time`` is what was asked; ``end_time`` is earlier only when ``stop_when_final``
    stopped the solve (``stop_reason == "metrics_final"``): then metrics not listed in
    ``final_metrics`` (and their times; ``impacts`` too) are None, never values of the shorter window.
    """

    scene: Scene
    end_time: float
    segments: list[ReferenceSegment]
    parameters: Parameters
    method: str = "DOP853"
    rtol: float = 1e-10
    atol: float = 1e-12
    impact_threshold: float = 1000.0
    nfev: int = 0
    wall_time: float = 0.0
    requested_end_time: float | None = None
    stop_reason: str = STOP_END_TIME
    final_metrics: tuple[str, ...] = _ALL_FINAL
    _starts: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        self._starts = np.array([s.t0 for s in self.segments])
        if self.requested_end_time is None:
            self.requested_end_time = self.end_time

    def _final(self, metric: str) -> bool:
        return metric in self.final_metrics

    # ---------------------------------------------------------------- evaluation
    def _per_segment(self, t, fn: Callable, rows: int | None):
        """Evaluate ``fn(mode, y)`` at times ``t`` (scalar or array) using each time's segment."""
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
            out[..., sel] = fn(seg.mode, seg.sol(ta[sel]))
        return out[..., 0] if scalar else out

    def state(self, t):
        """State ``[x_M, v_M, x_m, v_m, E_rd, E_ad, E_c]`` at ``t`` (s): shape (7,) or (7, len(t))."""
        return self._per_segment(t, lambda mode, y: y, 7)

    def barrel_position(self, t):
        """x_M (m)."""
        return self.state(t)[0]

    def barrel_velocity(self, t):
        """v_M (m/s)."""
        return self.state(t)[1]

    def absorber_position(self, t):
        """x_m (m); 0 for the simplified model."""
        return self.state(t)[2]

    def absorber_velocity(self, t):
        """v_m (m/s); 0 for the simplified model."""
        return self.state(t)[3]

    def penetration(self, t):
        """Contact penetration p (m); 0 for the simplified model."""
        P = self.parameters
        return self._per_segment(t, lambda mode, y: eq.penetration(P, y) if P.has_absorber else 0.0 * y[0], None)

    def contact_force(self, t):
        """Contact force F (N), >= 0; 0 for the simplified model."""
        P = self.parameters
        return self._per_segment(t, lambda mode, y: eq.contact_force(P, y, mode), None)

    def accelerations(self, t):
        """(a_M, a_m) in m/s^2, shape (2,) or (2, len(t))."""
        P = self.parameters
        return self._per_segment(t, lambda mode, y: np.array(eq.accelerations(P, y, mode)), 2)

    def energy_components(self, t) -> dict[str, np.ndarray]:
        """Energies (J) at ``t``: kinetic, springs, contact elastic, and the three dissipated energies."""
        return eq.energy_components(self.parameters, self.state(t))

    def energy_balance(self, t):
        """Total energy (J): kinetic + springs + contact elastic + dissipated; constant = initial_energy."""
        return sum(self.energy_components(t).values())

    @property
    def initial_energy(self) -> float:
        """Energy at t = 0 in J (initial kinetic energy, plus elastic energy with an initial interference)."""
        return float(self.energy_balance(0.0))

    def dissipated_energy_history(self, t) -> dict[str, np.ndarray | None]:
        """Dissipated energies (J) at ``t``; ``None`` entries for the absorber parts of the simplified model."""
        y = self.state(t)
        return {key: (y[4 + i] if (i == 0 or self.parameters.has_absorber) else None)
                for i, key in enumerate(_DISSIPATION_KEYS)}

    @property
    def dissipated_energy(self) -> dict[str, float | None]:
        """Dissipated energies at ``end_time`` in J: recoil_damper, absorber_damper, contact."""
        return {k: (None if v is None else float(v))
                for k, v in self.dissipated_energy_history(self.end_time).items()}

    def sample(self, n=None) -> dict[str, np.ndarray]:
        """Arrays on a time grid: the solver's step points (``n=None``), ``n`` uniform points, or given times."""
        if n is None:
            ts = [np.asarray(s.sol.ts, dtype=float) for s in self.segments]
            t = np.unique(np.concatenate([[0.0]] + [x[(x >= s.t0) & (x <= s.t1)] for x, s in zip(ts, self.segments)]
                                         + [[self.end_time]]))
        elif np.ndim(n) == 0:
            t = np.linspace(0.0, self.end_time, int(n))
        else:
            t = np.asarray(n, dtype=float)
        y = self.state(t)
        out = {"t": t, **{name: y[i] for i, name in enumerate(_STATE_NAMES)}}
        out["contact_force"] = self.contact_force(t)
        out["penetration"] = self.penetration(t)
        return out

    # ---------------------------------------------------------------- metrics
    def _global_max(self, value, deriv) -> tuple[float, float]:
        return _best(c for seg in self.segments for c in _segment_maxima(seg, value, deriv))

    @cached_property
    def _barrel_max(self):
        return self._global_max(lambda mode, y: y[0], lambda mode, y: y[1])

    @property
    def max_barrel_displacement(self) -> float | None:
        """Largest x_M over [0, end_time] in m (None if the solve stopped before proving it final)."""
        return self._barrel_max[1] if self._final("max_barrel_displacement") else None

    @property
    def time_of_max_barrel_displacement(self) -> float | None:
        """Time (s) of :attr:`max_barrel_displacement`."""
        return self._barrel_max[0] if self._final("max_barrel_displacement") else None

    @cached_property
    def _absorber_max(self):
        P = self.parameters
        if not P.has_absorber:
            return None
        return self._global_max(lambda mode, y: y[3], lambda mode, y: eq.accelerations(P, y, mode)[1])

    @property
    def max_absorber_velocity(self) -> float | None:
        """Largest absorber velocity v_m (m/s); None for the simplified model."""
        if self._absorber_max is None or not self._final("max_absorber_velocity"):
            return None
        return self._absorber_max[1]

    @property
    def time_of_max_absorber_velocity(self) -> float | None:
        """Time (s) of :attr:`max_absorber_velocity`; None for the simplified model."""
        if self._absorber_max is None or not self._final("max_absorber_velocity"):
            return None
        return self._absorber_max[0]

    def _force_derivative(self, mode: Mode, y):
        """dF/dt (N/s) in the ON mode: k_c [n p^(n-1) p' s + p^n lambda p'']."""
        P = self.parameters
        p, pd, s = eq.penetration(P, y), eq.penetration_rate(P, y), eq.damping_term(P, y)
        a_M, a_m = eq.accelerations(P, y, mode)
        pp = np.maximum(p, 0.0)
        dpow = P.n * np.where(pp > 0, pp, 1.0) ** (P.n - 1.0) * (pp > 0)
        return P.kc * (dpow * pd * s + pp ** P.n * P.lam * (a_M - a_m))

    @cached_property
    def _episodes(self) -> list[ReferenceImpact]:
        """All contact episodes (maximal runs of segments with a contact force), with their peaks."""
        P = self.parameters
        if not P.has_absorber:
            return []
        force = lambda mode, y: eq.contact_force(P, y, mode)  # noqa: E731
        episodes, run = [], []
        for seg in self.segments + [None]:
            if seg is not None and seg.mode.contact != OFF:
                run.append(seg)
                continue
            if run:
                cands = [c for s in run for c in
                         _segment_maxima(s, force, self._force_derivative if s.mode.contact == ON else None)]
                t_peak, f_peak = _best(cands)
                episodes.append(ReferenceImpact(run[0].t0, run[-1].t1, f_peak, t_peak))
                run = []
        return episodes

    @property
    def contact_episodes(self) -> list[ReferenceImpact] | None:
        """Every contact episode, whatever its peak force; None for the simplified model."""
        return list(self._episodes) if self.parameters.has_absorber else None

    @property
    def impacts(self) -> list[ReferenceImpact] | None:
        """Contact episodes whose peak force exceeds ``impact_threshold`` N ([] for the simplified model;
        None if the solve stopped before proving the list final)."""
        if not self._final("impacts"):
            return None
        return [e for e in self._episodes if e.peak_force > self.impact_threshold]

    @cached_property
    def _force_max(self):
        if not self.parameters.has_absorber:
            return None
        if not self._episodes:
            return (0.0, 0.0)
        best = max(self._episodes, key=lambda e: (e.peak_force, -e.time_of_peak))
        return (best.time_of_peak, best.peak_force)

    @property
    def peak_contact_force(self) -> float | None:
        """Largest contact force (N) over [0, end_time]; 0 if never in contact; None without absorber."""
        return None if self._force_max is None or not self._final("peak_contact_force") else self._force_max[1]

    @property
    def time_of_peak_contact_force(self) -> float | None:
        """Time (s) of :attr:`peak_contact_force`; None without absorber."""
        return None if self._force_max is None or not self._final("peak_contact_force") else self._force_max[0]

    def metrics(self) -> dict[str, Any]:
        """The DESIGN.md metric set as plain Python values (impacts as dicts)."""
        return {
            "max_barrel_displacement": self.max_barrel_displacement,
            "time_of_max_barrel_displacement": self.time_of_max_barrel_displacement,
            "peak_contact_force": self.peak_contact_force,
            "time_of_peak_contact_force": self.time_of_peak_contact_force,
            "max_absorber_velocity": self.max_absorber_velocity,
            "time_of_max_absorber_velocity": self.time_of_max_absorber_velocity,
            "impacts": None if self.impacts is None else [
                {"start": i.start, "end": i.end, "peak_force": i.peak_force, "time_of_peak": i.time_of_peak}
                for i in self.impacts],
            "end_time": self.end_time,
            "requested_end_time": self.requested_end_time,
            "stop_reason": self.stop_reason,
            "final_metrics": list(self.final_metrics),
            "dissipated_energy": self.dissipated_energy,
            "wall_time": self.wall_time,
        }
