"""What accuracy costs in time: work-precision study of every solver, and the accuracy presets.

``recoil precision [SCENE] --out DIR`` calls :func:`run_study` and :meth:`Study.write`.

The study
---------
One scene (the shipped ``model_ii``, m = 1000 kg, gap 0, by default) is solved with a grid of settings
(:func:`default_grid`):

* every Exudyn dynamic solver the engine accepts (:data:`mbs_models.engine.accuracy.SOLVERS`): the adaptive
  ones (DOPRI5, ODE23) swept over the relative tolerance (absolute tolerance ``rtol * 1e-2``, max step
  :data:`STUDY_MAX_STEP`), the fixed-step explicit (RK44, RK67, RK33, ExplicitMidpoint, ExplicitEuler,
  VelocityVerlet) and implicit (GeneralizedAlpha, TrapezoidalIndex2) ones over the step size; with
  symbolic (C++) user functions, and for a subset with Python user functions.  Exudyn's DVERK6 raises
  ``NotImplementedFeatureError`` in 1.13.6 and is not in the grid.
* scipy's RK45, DOP853, LSODA and Radau on the same equations (:func:`plain_rhs`: the Hunt-Crossley
  force with ``max(p, 0)`` and clipping, the damper switching on the sign of the velocity -- the plain,
  non-event-driven formulation the engine integrates too), with dense output; maxima are refined on the
  dense output (bounded Brent search around the best grid point).

Every setting is timed as the median wall time of ``repeats`` complete runs (the user-visible call:
``simulate()`` with its post-processing, or ``solve_ivp`` with the metric refinement; a run longer than
``long_run`` s is not repeated).  Its errors are measured against a tight *truth*
(:func:`compute_truth`: the event-driven reference :func:`validation.reference.solve_reference`, DOP853 at
``rtol = 1e-12``), whose own uncertainty is estimated against a second reference at ``rtol = 1e-10``:

* relative error of the max barrel displacement, of the peak contact force (relative to
  ``max(|F_truth|, impact threshold)``, so a scene without contact does not divide by 0), and of the
  max absorber velocity;
* relative L2 error of the barrel trajectory on a uniform 0.5 ms grid: ``rms(x - x_truth) / rms(x_truth)``
  (the engine's step-end samples interpolated with cubic Hermite polynomials).

A setting *fails* (:class:`Outcome.status`) when it is refused before solving (``refused``: the engine's
stability check, the reason quoted; the setting is then run once *unguarded*, straight through Exudyn,
to show what the check prevented), when the solve blows up (``blow-up``: non-finite state), stops
(``stopped``: early stop, step budget, solver failure), breaks the energy balance (``energy``), or misses
the contact (``missed contact``: the engine reports a stepped-over contact, or the run has fewer contact
episodes with a peak above half the impact threshold than the truth has above twice it -- counts that a
peak near the threshold cannot flip; ``extra impact`` for the converse).  Failed settings never count as
"cheapest"; errors of settings that ran are kept either way.

The presets
-----------
:func:`preset_study` runs each accuracy preset on the 19 paper cases (:func:`paper_cases`) against a
truth per case and reports the worst relative errors and the median time per 10-s run;
:data:`PRESET_ERROR_BOUNDS` are the errors each preset is stated to meet (checked by
``tests/test_presets.py``).
"""

from __future__ import annotations

import csv
import io
import math
import re
import statistics
import time
import warnings
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from mbs_models.scene.models import model_i, model_ii, simplified_model
from mbs_models.results.peaks import runs_of_true
from mbs_models.scene import Scene

from .progress import counter


#: Metrics of the study, in the order of the tables and figures.
METRICS = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "barrel_trajectory_l2")
METRIC_LABELS = {
    "max_barrel_displacement": "max barrel displacement",
    "peak_contact_force": "peak contact force",
    "max_absorber_velocity": "max absorber velocity",
    "barrel_trajectory_l2": "barrel trajectory (relative L2)",
}
#: Error targets of the summary ("cheapest setting for ...").
TARGETS = (1e-2, 1e-4, 1e-6)
#: Max step (s) of the adaptive settings of the study (Exudyn and scipy alike).
STUDY_MAX_STEP = 1e-2
#: Truth: the event-driven reference at these tolerances, checked against one at CHECK_RTOL.
TRUTH_RTOL, TRUTH_ATOL, CHECK_RTOL = 1e-12, 1e-14, 1e-10
#: Spacing (s) of the uniform grid of the trajectory error.
TRAJECTORY_SPACING = 5e-4
#: Impact counting that is robust to peaks near the threshold: a run *misses a contact* when it has fewer
#: contact episodes with a peak above LENIENT_IMPACT x threshold than the truth has above SIGNIFICANT_IMPACT
#: x threshold (and has an *extra impact* in the converse case).
SIGNIFICANT_IMPACT, LENIENT_IMPACT = 2.0, 0.5
#: Statuses that are failures.
FAILED_STATUSES = ("refused", "blow-up", "stopped", "energy", "missed contact", "extra impact", "failed")

Progress = Callable[[str], None]


def _silent(message: str) -> None:
    pass


# ================================================================================================
# Settings

@dataclass(frozen=True)
class Setting:
    """One point of the grid: an engine (``"exudyn"`` or ``"scipy"``), a solver and its parameter.

    Exudyn: ``user_functions`` ``"symbolic"``/``"python"``; adaptive solvers use ``relative_tolerance``
    (absolute ``rtol * 1e-2``) and ``max_step`` (s), fixed-step ones ``step`` (s).  scipy: a
    ``solve_ivp`` method with ``relative_tolerance`` and ``max_step``.
    """

    engine: str
    solver: str
    relative_tolerance: float | None = None
    step: float | None = None
    user_functions: str | None = None
    max_step: float | None = STUDY_MAX_STEP

    @property
    def adaptive(self) -> bool:
        return self.step is None

    @property
    def family(self) -> str:
        """The line of the work-precision figure this setting belongs to."""
        if self.engine == "scipy":
            return f"scipy {self.solver}"
        return f"Exudyn {self.solver} ({self.user_functions})"

    @property
    def parameter(self) -> str:
        return "rtol" if self.adaptive else "step"

    @property
    def value(self) -> float:
        return self.relative_tolerance if self.adaptive else self.step

    @property
    def absolute_tolerance(self) -> float | None:
        return None if self.relative_tolerance is None else self.relative_tolerance * 1e-2

    def label(self) -> str:
        unit = "" if self.adaptive else " s"
        return f"{self.family} {self.parameter}={self.value:g}{unit}"

    def solver_settings(self):
        """The engine's :class:`~mbs_models.engine.accuracy.SolverSettings` (Exudyn settings only)."""
        from mbs_models.engine.accuracy import SolverSettings

        if self.adaptive:
            return SolverSettings(solver=self.solver, relative_tolerance=self.relative_tolerance,
                                  absolute_tolerance=self.absolute_tolerance, max_step=self.max_step,
                                  user_functions=self.user_functions)
        return SolverSettings(solver=self.solver, relative_tolerance=None, absolute_tolerance=None, max_step=None,
                              step=self.step, user_functions=self.user_functions)


def _exudyn(solver: str, values: Sequence[float], user_functions: str = "symbolic") -> list[Setting]:
    from mbs_models.engine.accuracy import ADAPTIVE_SOLVERS

    if solver in ADAPTIVE_SOLVERS:
        return [Setting("exudyn", solver, relative_tolerance=v, user_functions=user_functions) for v in values]
    return [Setting("exudyn", solver, step=v, user_functions=user_functions, max_step=None) for v in values]


def _scipy(method: str, values: Sequence[float]) -> list[Setting]:
    return [Setting("scipy", method, relative_tolerance=v) for v in values]


def _decades(first: int, last: int) -> list[float]:
    return [10.0 ** -k for k in range(first, last + 1)]


def default_grid(quick: bool = False) -> list[Setting]:
    """The settings of the study: the full grid (a few minutes for a 10-s run), or a tiny one."""
    if quick:
        return (_exudyn("DOPRI5", [1e-4, 1e-7, 1e-10]) + _exudyn("ODE23", [1e-4, 1e-7])
                + _exudyn("RK44", [2e-2, 2e-3, 5e-4]) + _exudyn("GeneralizedAlpha", [2e-3])
                + _exudyn("DOPRI5", [1e-6], "python")
                + _scipy("LSODA", [1e-4, 1e-7]) + _scipy("RK45", [1e-5]))
    # fixed steps from far beyond the engine's safe limit (refused; run unguarded to show why) to fine
    steps = [5e-2, 2e-2, 1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5]
    return (_exudyn("DOPRI5", _decades(3, 12)) + _exudyn("ODE23", _decades(3, 10))
            + _exudyn("RK44", steps) + _exudyn("RK67", steps[:8]) + _exudyn("RK33", [5e-2, *steps[2:9]])
            + _exudyn("ExplicitMidpoint", [5e-2, *steps[3:9]]) + _exudyn("ExplicitEuler", [5e-2, 1e-3, 1e-4, 5e-5, 2e-5])
            + _exudyn("VelocityVerlet", [5e-2, *steps[2:9]])
            + _exudyn("GeneralizedAlpha", steps) + _exudyn("TrapezoidalIndex2", steps)
            + _exudyn("DOPRI5", [1e-3, 1e-5, 1e-7, 1e-9, 1e-11], "python")
            + _exudyn("ODE23", [1e-3, 1e-5, 1e-7, 1e-9], "python")
            + _exudyn("RK44", [5e-3, 1e-3, 2e-4], "python") + _exudyn("GeneralizedAlpha", [5e-3, 1e-3, 2e-4], "python")
            + _scipy("RK45", _decades(3, 10)) + _scipy("DOP853", _decades(3, 12))
            + _scipy("LSODA", _decades(3, 10)) + _scipy("Radau", _decades(3, 9)))


# ================================================================================================
# Truth

@dataclass(frozen=True)
class Truth:
    """The tight reference of one scene: metrics, impacts ``(start, end, peak)`` and the barrel
    trajectory on ``grid`` (s, m); ``uncertainty`` holds the relative differences to a looser check
    reference (an estimate of the truth's own error)."""

    scene: Scene
    end_time: float
    max_barrel_displacement: float
    peak_contact_force: float | None
    max_absorber_velocity: float | None
    impacts: tuple[tuple[float, float, float], ...]
    episodes: tuple[tuple[float, float, float], ...]
    grid: np.ndarray = field(repr=False)
    barrel_position: np.ndarray = field(repr=False)
    uncertainty: dict[str, float | None] = field(default_factory=dict)
    rtol: float = TRUTH_RTOL
    impact_threshold: float = 1000.0
    wall_time: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        return {"scene": self.scene.name, "end_time": self.end_time, "method": "event-driven DOP853",
                "rtol": self.rtol, "max_barrel_displacement": self.max_barrel_displacement,
                "peak_contact_force": self.peak_contact_force, "max_absorber_velocity": self.max_absorber_velocity,
                "impacts": [list(i) for i in self.impacts], "uncertainty": dict(self.uncertainty),
                "wall_time": self.wall_time}


def trajectory_grid(end_time: float) -> np.ndarray:
    """Uniform grid (s) of the trajectory error: :data:`TRAJECTORY_SPACING`, at least 2001 points."""
    return np.linspace(0.0, end_time, max(2001, int(round(end_time / TRAJECTORY_SPACING)) + 1))


def compute_truth(scene: Scene, end_time: float = 10.0, *, rtol: float = TRUTH_RTOL, atol: float = TRUTH_ATOL,
                  check_rtol: float | None = CHECK_RTOL, impact_threshold: float = 1000.0) -> Truth:
    """The event-driven reference at ``rtol``; with ``check_rtol`` also its uncertainty (see :class:`Truth`)."""
    from ..reference import solve_reference

    start = time.perf_counter()
    reference = solve_reference(scene, end_time, rtol=rtol, atol=atol, impact_threshold=impact_threshold)
    grid = trajectory_grid(end_time)
    truth = Truth(scene=scene, end_time=float(end_time), max_barrel_displacement=reference.max_barrel_displacement,
                  peak_contact_force=reference.peak_contact_force,
                  max_absorber_velocity=reference.max_absorber_velocity,
                  impacts=tuple((i.start, i.end, i.peak_force) for i in reference.impacts),
                  episodes=tuple((e.start, e.end, e.peak_force) for e in reference.contact_episodes or ()
                                 if e.peak_force > LENIENT_IMPACT * impact_threshold),
                  grid=grid, barrel_position=np.asarray(reference.barrel_position(grid), dtype=float),
                  rtol=rtol, impact_threshold=impact_threshold)
    uncertainty: dict[str, float | None] = {}
    if check_rtol is not None:
        check = solve_reference(scene, end_time, rtol=check_rtol, atol=check_rtol * 1e-2,
                                impact_threshold=impact_threshold)
        values = RunValues(max_barrel_displacement=check.max_barrel_displacement,
                           peak_contact_force=check.peak_contact_force,
                           max_absorber_velocity=check.max_absorber_velocity,
                           impacts=[(i.start, i.end, i.peak_force) for i in check.impacts],
                           lenient_impacts=sum(1 for e in check.contact_episodes or ()
                                               if e.peak_force > LENIENT_IMPACT * impact_threshold),
                           trajectory=np.asarray(check.barrel_position(grid), dtype=float))
        uncertainty = relative_errors(values, truth)
    return replace(truth, uncertainty=uncertainty, wall_time=time.perf_counter() - start)


def _truth_job(job: tuple[Scene, float, float | None]) -> Truth:
    scene, end_time, check_rtol = job
    return compute_truth(scene, end_time, check_rtol=check_rtol)


def compute_truths(scenes: Sequence[Scene], end_time: float = 10.0, *, check_rtol: float | None = None,
                   workers: int | None = None, progress: Progress = _silent) -> list[Truth]:
    """:func:`compute_truth` of many scenes in worker processes (not timed, so parallel is fine)."""
    from mbs_models.studies.sweep import parallel_map

    return parallel_map(_truth_job, [(s, float(end_time), check_rtol) for s in scenes], workers=workers,
                        progress=counter(progress, "truths (event-driven reference)", "case"))


# ================================================================================================
# Errors

@dataclass
class RunValues:
    """What one run gives for comparison: metrics, impacts ``(start, end, peak)``, barrel trajectory on the
    truth's grid (m)."""

    max_barrel_displacement: float
    peak_contact_force: float | None
    max_absorber_velocity: float | None
    impacts: list[tuple[float, float, float]]
    trajectory: np.ndarray
    lenient_impacts: int = 0
    steps: int | None = None
    solve_time: float | None = None
    note: str = ""


def _relative(value: float | None, truth: float | None, floor: float) -> float | None:
    if value is None or truth is None:
        return None
    if not math.isfinite(value):
        return math.inf
    return abs(value - truth) / max(abs(truth), floor)


def relative_errors(values: RunValues, truth: Truth) -> dict[str, float | None]:
    """Relative errors of the four :data:`METRICS` (None where the scene has no such quantity)."""
    reference = truth.barrel_position
    rms = float(np.sqrt(np.mean(reference ** 2)))
    difference = np.asarray(values.trajectory, dtype=float) - reference
    l2 = float(np.sqrt(np.mean(difference ** 2)) / rms) if np.all(np.isfinite(difference)) else math.inf
    return {
        "max_barrel_displacement": _relative(values.max_barrel_displacement, truth.max_barrel_displacement, 1e-300),
        "peak_contact_force": _relative(values.peak_contact_force, truth.peak_contact_force, truth.impact_threshold),
        "max_absorber_velocity": _relative(values.max_absorber_velocity, truth.max_absorber_velocity, 1e-300),
        "barrel_trajectory_l2": l2,
    }


def impact_mismatch(values: RunValues, truth: Truth) -> tuple[int, int]:
    """(missed, extra) contacts of a run against the truth, by counts that a peak near the impact
    threshold cannot flip: missed = truth episodes above SIGNIFICANT_IMPACT x threshold minus run episodes
    above LENIENT_IMPACT x threshold (if positive); extra = the converse."""
    limit = SIGNIFICANT_IMPACT * truth.impact_threshold
    truth_significant = sum(1 for e in truth.episodes if e[2] > limit)
    run_significant = sum(1 for e in values.impacts if e[2] > limit)
    return max(0, truth_significant - values.lenient_impacts), max(0, run_significant - len(truth.episodes))


# ================================================================================================
# scipy on the same equations, without events

@dataclass(frozen=True)
class Parameters:
    """The numbers of a paper scene (one Hunt-Crossley absorber at most) for the plain right-hand side, SI units.

    ``lam`` is the signed damping factor (``-lambda`` with ``literal_lambda_sign``); ``gap_offset`` the gap
    subtracted from ``x_M - x_m`` (``-gap`` with ``literal_gap_sign``).  The study covers the paper's
    models: :meth:`from_scene` refuses scenes with several absorbers, stops or other contact laws.
    """

    M: float
    k: float
    c_recoil: float
    c_counter: float
    v0: float
    has_absorber: bool = False
    m: float = 1.0
    on_barrel: bool = False
    kr: float = 0.0
    cr: float = 0.0
    kc: float = 0.0
    n: float = 1.0
    lam: float = 0.0
    gap_offset: float = 0.0
    compression_only: bool = False

    @classmethod
    def from_scene(cls, scene: Scene) -> "Parameters":
        paper_tables = {"barrel", "firing", "recoil_spring", "recoil_damper", "absorber"}
        if len(scene.absorbers) > 1 or any(key not in paper_tables for key, _ in scene.tables()) or \
                (scene.contact is not None and scene.contact.law != "hunt-crossley"):
            raise ValueError("the work-precision study covers the paper's models: one Hunt-Crossley absorber, no stops")
        spring, damper = scene.recoil_spring, scene.recoil_damper
        base = dict(M=scene.barrel.mass, k=spring.stiffness if spring else 0.0,
                    c_recoil=damper.recoil if damper else 0.0, c_counter=damper.counter_recoil if damper else 0.0,
                    v0=float(scene.initial_velocity))
        a, c, conv = scene.absorber, scene.contact, scene.conventions
        if a is None:
            return cls(**base)
        return cls(**base, has_absorber=True, m=a.mass, on_barrel=(a.mount == "barrel"), kr=a.stiffness,
                   cr=a.damping, kc=c.stiffness, n=c.exponent,
                   lam=-c.damping_factor if conv.literal_lambda_sign else c.damping_factor,
                   gap_offset=-c.gap if conv.literal_gap_sign else c.gap, compression_only=conv.compression_only)


def plain_rhs(P: Parameters) -> Callable[[float, np.ndarray], list[float]]:
    """Right-hand side ``f(t, y)``, ``y = [x_M, v_M, x_m, v_m]``, of Eqs. (1)-(8) as the engine integrates
    them: damper coefficient from the sign of the barrel velocity, Hunt-Crossley force
    ``k_c max(p, 0)^n (1 + lambda p')`` clipped to >= 0 (the same laws as :mod:`validation.reference.equations`,
    written with plain floats for speed)."""
    M, k, c_rec, c_cnt = P.M, P.k, P.c_recoil, P.c_counter
    if not P.has_absorber:
        def f(t, y):
            x, v = y[0], y[1]
            return [v, (-k * x - (c_rec if v > 0 else c_cnt) * v) / M, 0.0, 0.0]
        return f
    m, kr, cr, kc, n, lam, offset = P.m, P.kr, P.cr, P.kc, P.n, P.lam, P.gap_offset
    on_barrel, compression_only = P.on_barrel, P.compression_only

    def f(t, y):
        x, v, xa, va = y[0], y[1], y[2], y[3]
        f_M = -k * x - (c_rec if v > 0 else c_cnt) * v
        if on_barrel:
            f_r = kr * (x - xa) + cr * (v - va)
            f_M -= f_r
            f_m = f_r
        else:
            f_m = -kr * xa - cr * va
        p = x - xa - offset
        force = 0.0
        if p > 0:
            rate = v - va
            force = kc * p ** n * (1.0 + lam * rate)
            if force < 0 or (compression_only and rate <= 0):
                force = 0.0
        return [v, (f_M - force) / M, va, (f_m + force) / m]
    return f


def plain_contact_force(P: Parameters, y: np.ndarray) -> np.ndarray:
    """Contact force (N) of :func:`plain_rhs` on states ``y`` of shape (4, N)."""
    if not P.has_absorber:
        return np.zeros(np.shape(y)[1:])
    p = np.maximum(y[0] - y[2] - P.gap_offset, 0.0)
    rate = y[1] - y[3]
    force = np.maximum(P.kc * p ** P.n * (1.0 + P.lam * rate), 0.0)
    if P.compression_only:
        force = force * (rate > 0)
    return force


class PlainSolveError(RuntimeError):
    """A plain solve_ivp run failed; the message says why (prefixed by the failure class)."""


@dataclass
class PlainSolution:
    """A plain (non-event-driven) solve_ivp run with its refined metrics."""

    sol: Any
    steps: int
    nfev: int
    solve_time: float
    max_barrel_displacement: float
    peak_contact_force: float | None
    max_absorber_velocity: float | None
    impacts: list[tuple[float, float, float]]
    episodes: list[tuple[float, float, float]]


def _refined_max(fn: Callable[[float], float], grid: np.ndarray, values: np.ndarray, i: int) -> float:
    best = float(values[i])
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    if hi > lo:
        res = minimize_scalar(lambda s: -fn(s), bounds=(lo, hi), method="bounded", options={"xatol": 1e-13})
        best = max(best, -float(res.fun))
    return best


def solve_plain(scene: Scene, end_time: float, method: str, rtol: float, atol: float | None = None,
                max_step: float = STUDY_MAX_STEP, impact_threshold: float = 1000.0) -> PlainSolution:
    """Integrate :func:`plain_rhs` with ``solve_ivp(method)`` and refine the metrics on the dense output.

    Raises :class:`PlainSolveError` (``"stopped: ..."`` or ``"blow-up: ..."``).
    """
    P = Parameters.from_scene(scene)
    atol = rtol * 1e-2 if atol is None else atol
    start = time.perf_counter()
    with np.errstate(all="ignore"):
        sol = solve_ivp(plain_rhs(P), (0.0, float(end_time)), [0.0, P.v0, 0.0, 0.0], method=method, rtol=rtol,
                        atol=atol, max_step=max_step, dense_output=True)
    solve_time = time.perf_counter() - start
    if sol.status < 0:
        raise PlainSolveError(f"stopped: solve_ivp {method} at t = {sol.t[-1]:.6g} s: {sol.message}")
    if not np.all(np.isfinite(sol.y)):
        raise PlainSolveError(f"blow-up: solve_ivp {method} produced a non-finite state")
    dense = sol.sol
    ts = np.asarray(sol.t, dtype=float)
    grid = np.concatenate(((ts[:-1, None] + np.diff(ts)[:, None] * np.arange(4)[None, :] / 4).ravel(), ts[-1:]))
    y = dense(grid)
    x_max = _refined_max(lambda s: float(dense(s)[0]), grid, y[0], int(np.argmax(y[0])))
    force_max = v_max = None
    impacts: list[tuple[float, float, float]] = []
    episodes: list[tuple[float, float, float]] = []
    if P.has_absorber:
        v_max = _refined_max(lambda s: float(dense(s)[3]), grid, y[3], int(np.argmax(y[3])))
        force = plain_contact_force(P, y)

        def force_at(s: float) -> float:
            return float(plain_contact_force(P, dense(s)[:, None])[0])

        force_max = 0.0
        for i0, i1 in runs_of_true(force > 0):
            k = i0 + int(np.argmax(force[i0:i1 + 1]))
            peak = _refined_max(force_at, grid, force, k)
            force_max = max(force_max, peak)
            episode = (float(grid[max(i0 - 1, 0)]), float(grid[min(i1 + 1, len(grid) - 1)]), peak)
            episodes.append(episode)
            if peak > impact_threshold:
                impacts.append(episode)
    return PlainSolution(sol=dense, steps=len(ts) - 1, nfev=int(sol.nfev), solve_time=solve_time,
                         max_barrel_displacement=x_max,
                         peak_contact_force=force_max, max_absorber_velocity=v_max, impacts=impacts,
                         episodes=episodes)


# ================================================================================================
# Running one setting

@dataclass
class Outcome:
    """One setting of the study: status, reason, errors vs the truth, and cost.

    ``median_time`` (s) is the median wall time of ``runs`` complete runs; ``solve_time`` (s) the
    median time of the integration alone (Exudyn's solve; scipy's solve_ivp); ``cpu_time`` (s) the median
    CPU time of this process per run (close to ``median_time`` unless the machine was busy).
    """

    setting: Setting
    status: str
    reason: str = ""
    errors: dict[str, float | None] = field(default_factory=dict)
    values: dict[str, float | None] = field(default_factory=dict)
    impacts: int | None = None
    truth_impacts: int | None = None
    median_time: float | None = None
    solve_time: float | None = None
    cpu_time: float | None = None
    runs: int = 0
    steps: int | None = None
    warnings: list[str] = field(default_factory=list)
    actual_settings: str = ""
    times: list[float] = field(default_factory=list, repr=False)
    solve_times: list[float] = field(default_factory=list, repr=False)
    cpu_times: list[float] = field(default_factory=list, repr=False)

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def worst_error(self) -> float | None:
        """Largest error over the metrics the scene has (None if failed)."""
        values = [e for e in self.errors.values() if e is not None]
        return max(values) if values and self.ok else None

    def to_dict(self) -> dict[str, Any]:
        s = self.setting
        return {"family": s.family, "engine": s.engine, "solver": s.solver, "user_functions": s.user_functions,
                "parameter": s.parameter, "value": s.value, "max_step": s.max_step if s.adaptive else None,
                "label": s.label(), "status": self.status, "reason": self.reason,
                "errors": {k: _finite(v) for k, v in self.errors.items()},
                "values": {k: _finite(v) for k, v in self.values.items()},
                "impacts": self.impacts, "truth_impacts": self.truth_impacts, "median_time": self.median_time,
                "solve_time": self.solve_time, "cpu_time": self.cpu_time, "times": self.times, "runs": self.runs,
                "steps": self.steps, "warnings": self.warnings,
                "actual_settings": self.actual_settings}


def _finite(value):
    if value is None:
        return None
    return float(value) if math.isfinite(value) else None


def classify_failure(message: str) -> str:
    """Failure class of an engine/solver message (see the module docstring)."""
    text = message.lower()
    if "non-finite" in text or "nan" in text.split() or "blow-up" in text or "diverged" in text:
        return "blow-up"
    if "stepped over" in text or "missed" in text:
        return "missed contact"
    if "energy balance" in text:
        return "energy"
    if "stopped" in text or "step budget" in text or "reported failure" in text or "output ends" in text:
        return "stopped"
    return "failed"


def _sample_episodes(force: np.ndarray | None, threshold: float) -> int:
    """Contact episodes (runs of samples with force > 0) whose sampled peak exceeds ``threshold`` (N)."""
    if force is None or not len(force):
        return 0
    active = np.concatenate(([False], force > 0, [False])).astype(np.int8)
    starts, ends = np.flatnonzero(np.diff(active) == 1), np.flatnonzero(np.diff(active) == -1)
    return sum(1 for a, b in zip(starts, ends) if force[a:b].max() > threshold)


def _engine_values(result, truth: Truth) -> RunValues:
    from mbs_models.results.peaks import HermiteTrajectory

    trajectory = HermiteTrajectory(result.time, result.barrel_position, result.barrel_velocity)(truth.grid)
    return RunValues(max_barrel_displacement=result.max_barrel_displacement,
                     peak_contact_force=result.peak_contact_force,
                     max_absorber_velocity=result.max_absorber_velocity,
                     impacts=[(i.start, i.end, i.peak_force) for i in result.impacts], trajectory=trajectory,
                     lenient_impacts=_sample_episodes(result.contact_force, LENIENT_IMPACT * truth.impact_threshold),
                     steps=result.steps, solve_time=result.timings.get("solve"))


def _plain_values(solution: PlainSolution, truth: Truth) -> RunValues:
    return RunValues(max_barrel_displacement=solution.max_barrel_displacement,
                     peak_contact_force=solution.peak_contact_force,
                     max_absorber_velocity=solution.max_absorber_velocity, impacts=solution.impacts,
                     lenient_impacts=sum(1 for e in solution.episodes if e[2] > LENIENT_IMPACT * truth.impact_threshold),
                     trajectory=np.asarray(solution.sol(truth.grid)[0], dtype=float), steps=solution.steps)


def unguarded_run(setting: Setting, scene: Scene, truth: Truth) -> str:
    """Run an Exudyn setting straight through Exudyn, without the engine's safety checks, and say what
    happens (used for settings the engine refuses): ``"<class>: <what>"``."""
    import exudyn

    from mbs_models.engine.assembly import assemble
    from mbs_models.engine.simulation import exudyn_simulation_settings

    settings = setting.solver_settings()
    end_time = truth.end_time
    assembly = assemble(scene, settings.user_functions)
    printing = exudyn.config.printToConsole
    exudyn.config.printToConsole = False
    try:
        mbs = assembly.mbs
        try:
            success = mbs.SolveDynamic(exudyn_simulation_settings(settings, end_time),
                                       solverType=getattr(exudyn.DynamicSolverType, settings.solver))
        except Exception as exc:  # noqa: BLE001 - Exudyn's own error types
            return f"failed: Exudyn raised {' '.join(str(exc).split())[:200]}"
        reached = float(mbs.sys["dynamicSolver"].it.currentTime)
        data = {name: np.asarray(mbs.GetSensorStoredData(index), dtype=float)
                for name, index in assembly.sensors.items()}
    finally:
        exudyn.config.printToConsole = printing
        assembly.close()
    position = data["barrel_position"]
    bad = ~np.all(np.isfinite(position), axis=1)
    if bad.any() or np.nanmax(np.abs(position[:, 1])) > 100.0 * truth.max_barrel_displacement:
        t_bad = position[int(np.argmax(bad)), 0] if bad.any() else \
            position[int(np.argmax(np.abs(position[:, 1]) > 100.0 * truth.max_barrel_displacement)), 0]
        return f"blow-up: the unguarded run diverges (non-finite or > 100x the true displacement) at t = {t_bad:.4g} s"
    if not success or reached < end_time * (1 - 1e-9):
        return f"stopped: the unguarded run stops at t = {reached:.4g} s of {end_time:g} s"
    if "contact_force" in data and truth.impacts:
        force = data["contact_force"][:, 1]
        samples = int(np.count_nonzero(force > 0))
        if samples == 0:
            return "missed contact: the unguarded run steps over every contact (no contact-force sample)"
        peak = float(force.max())
        error = abs(peak - truth.peak_contact_force) / truth.peak_contact_force
        if error > 0.5:
            return (f"missed contact: the unguarded run under-resolves the impacts ({samples} contact samples, "
                    f"sampled peak force {peak:.3g} N vs {truth.peak_contact_force:.3g} N)")
    x_max = float(position[:, 1].max())
    error = abs(x_max - truth.max_barrel_displacement) / truth.max_barrel_displacement
    text = f"ran: the unguarded run completes; sampled max barrel displacement off by {error:.2g} (relative)"
    if "contact_force" in data and truth.impacts:
        force = data["contact_force"][:, 1]
        text += (f", {int(np.count_nonzero(force > 0))} contact samples, sampled peak force off by "
                 f"{abs(float(force.max()) - truth.peak_contact_force) / truth.peak_contact_force:.2g}")
    return text


def _run_once(setting: Setting, scene: Scene, end_time: float, impact_threshold: float):
    """One timed call; returns (result object, wall time s, CPU time s of this process)."""
    if setting.engine == "scipy":
        wall, cpu = time.perf_counter(), time.process_time()
        solution = solve_plain(scene, end_time, setting.solver, setting.relative_tolerance,
                               max_step=setting.max_step, impact_threshold=impact_threshold)
        return solution, time.perf_counter() - wall, time.process_time() - cpu
    from mbs_models.engine.simulation import simulate

    settings = setting.solver_settings()
    wall, cpu = time.perf_counter(), time.process_time()
    result = simulate(scene, end_time, settings, impact_threshold=impact_threshold)
    return result, time.perf_counter() - wall, time.process_time() - cpu


def _record(outcome: Outcome, obj, wall: float, cpu: float) -> None:
    outcome.times.append(wall)
    outcome.cpu_times.append(cpu)
    outcome.solve_times.append(obj.timings.get("solve", wall) if outcome.setting.engine == "exudyn"
                               else obj.solve_time)
    outcome.median_time = statistics.median(outcome.times)
    outcome.cpu_time = statistics.median(outcome.cpu_times)
    outcome.solve_time = statistics.median(outcome.solve_times)
    outcome.runs = len(outcome.times)


def time_again(outcome: Outcome, scene: Scene, truth: Truth) -> None:
    """One more timed run of a setting that ran (its results are deterministic: only the time is kept)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        obj, wall, cpu = _run_once(outcome.setting, scene, truth.end_time, truth.impact_threshold)
    _record(outcome, obj, wall, cpu)


def run_setting(setting: Setting, scene: Scene, truth: Truth, *, repeats: int = 3, long_run: float = 1.5,
                unguarded: bool = True) -> Outcome:
    """Run one setting, judge it against ``truth`` and return its :class:`Outcome` (failures are captured,
    never raised); time it ``repeats`` times in a row (once if a run takes longer than ``long_run`` s).
    :func:`run_study` instead times in interleaved rounds (``repeats=1`` here, then :func:`time_again`)."""
    from mbs_models.errors import SceneError, SimulationError

    truth_impacts = len(truth.impacts) if truth.scene.has_absorber else None
    outcome = Outcome(setting=setting, status="ok", truth_impacts=truth_impacts)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            obj, wall, cpu = _run_once(setting, scene, truth.end_time, truth.impact_threshold)
        except SceneError as exc:
            message = re.sub(r"; contact natural frequency.*?(?=; the safe limit)", "", exc.message)
            outcome.status, outcome.reason = "refused", f"refused by the engine: {message}"
            if unguarded and setting.engine == "exudyn":
                outcome.reason += f" -- unguarded: {unguarded_run(setting, scene, truth)}"
            return outcome
        except SimulationError as exc:
            outcome.status, outcome.reason = classify_failure(str(exc)), str(exc)
            return outcome
        except PlainSolveError as exc:
            outcome.status, outcome.reason = str(exc).split(":", 1)[0], str(exc)
            return outcome
    outcome.warnings = sorted({str(w.message)[:300] for w in caught})
    _record(outcome, obj, wall, cpu)
    values = _engine_values(obj, truth) if setting.engine == "exudyn" else _plain_values(obj, truth)
    if setting.engine == "exudyn":
        outcome.actual_settings = obj.settings.label()
        if obj.settings != setting.solver_settings():
            outcome.warnings.append(f"the engine re-solved with {obj.settings.label()} "
                                    f"(max_step {obj.settings.max_step:g} s) after stepping over a contact")
    outcome.errors = relative_errors(values, truth)
    outcome.values = {"max_barrel_displacement": values.max_barrel_displacement,
                      "peak_contact_force": values.peak_contact_force,
                      "max_absorber_velocity": values.max_absorber_velocity}
    outcome.impacts = len(values.impacts) if truth.scene.has_absorber else None
    outcome.steps = values.steps
    if truth.scene.has_absorber:
        missed, extra = impact_mismatch(values, truth)
        if missed:
            outcome.status = "missed contact"
            outcome.reason = (f"{missed} contact(s) missed: {values.lenient_impacts} episodes with a peak above "
                              f"{LENIENT_IMPACT * truth.impact_threshold:g} N where the truth has "
                              f"{sum(1 for e in truth.episodes if e[2] > SIGNIFICANT_IMPACT * truth.impact_threshold)} "
                              f"above {SIGNIFICANT_IMPACT * truth.impact_threshold:g} N; peak force error "
                              f"{outcome.errors['peak_contact_force']:.2g}")
        elif extra:
            outcome.status = "extra impact"
            outcome.reason = (f"{extra} impact(s) the truth does not have: "
                              f"{sum(1 for e in values.impacts if e[2] > SIGNIFICANT_IMPACT * truth.impact_threshold)} "
                              f"above {SIGNIFICANT_IMPACT * truth.impact_threshold:g} N where the truth has "
                              f"{len(truth.episodes)} above {LENIENT_IMPACT * truth.impact_threshold:g} N")
    if outcome.status == "ok" and any(e is not None and not math.isfinite(e) for e in outcome.errors.values()):
        outcome.status, outcome.reason = "blow-up", "non-finite metric"
    for _ in range(max(1, repeats) - 1):
        if outcome.median_time > long_run:
            break
        time_again(outcome, scene, truth)
    return outcome


# ================================================================================================
# The study

@dataclass
class Study:
    """All outcomes of one scene's work-precision study, and its truth."""

    scene: Scene
    truth: Truth
    outcomes: list[Outcome]
    repeats: int
    wall_time: float = 0.0

    def failures(self) -> list[Outcome]:
        return [o for o in self.outcomes if not o.ok]

    def metrics(self) -> list[str]:
        """The metrics this scene has (no contact metrics for the simplified model)."""
        return [m for m in METRICS if self.truth.scene.has_absorber or m in ("max_barrel_displacement",
                                                                              "barrel_trajectory_l2")]

    def cheapest(self, target: float, metrics: Sequence[str] | None = None) -> Outcome | None:
        """The fastest (median time) successful setting whose errors on ``metrics`` (default all) are <= target."""
        metrics = list(metrics or self.metrics())
        fitting = [o for o in self.outcomes if o.ok and o.median_time is not None
                   and all(o.errors.get(m) is not None and o.errors[m] <= target for m in metrics)]
        return min(fitting, key=lambda o: o.median_time) if fitting else None

    def cheapest_per_family(self, target: float) -> dict[str, Outcome]:
        out: dict[str, Outcome] = {}
        for o in self.outcomes:
            if o.ok and o.median_time is not None and all(
                    o.errors.get(m) is not None and o.errors[m] <= target for m in self.metrics()):
                best = out.get(o.setting.family)
                if best is None or o.median_time < best.median_time:
                    out[o.setting.family] = o
        return out

    def load_ratio(self) -> float | None:
        """Median wall / CPU time over the timed runs: ~1 on an idle machine, larger when it was shared."""
        ratios = [w / c for o in self.outcomes for w, c in zip(o.times, o.cpu_times) if c > 0]
        return statistics.median(ratios) if ratios else None

    def load_note(self) -> str:
        ratio = self.load_ratio()
        if ratio is None:
            return ""
        verdict = "the machine was idle enough" if ratio < 1.15 else "the machine was shared: times are inflated"
        return f"Median wall/CPU time ratio {ratio:.2f} ({verdict}; CPU times are in the CSV)."

    # --------------------------------------------------------------------------------------- output
    def to_dict(self) -> dict[str, Any]:
        cheapest = {}
        for target in TARGETS:
            best = self.cheapest(target)
            cheapest[f"{target:g}"] = {
                "all_metrics": None if best is None else best.setting.label(),
                "median_time": None if best is None else best.median_time,
                "per_metric": {m: (lambda o: None if o is None else o.setting.label())(self.cheapest(target, [m]))
                               for m in self.metrics()},
            }
        return {"scene": self.scene.name, "end_time": self.truth.end_time, "repeats": self.repeats,
                "study_max_step": STUDY_MAX_STEP, "wall_over_cpu": self.load_ratio(), "truth": self.truth.to_dict(), "cheapest": cheapest,
                "settings": [o.to_dict() for o in self.outcomes], "wall_time": self.wall_time}

    def csv_text(self) -> str:
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(["family", "engine", "solver", "user_functions", "parameter", "value", "status",
                         "median_time_s", "solve_time_s", "cpu_time_s", "runs", "steps", "impacts", "truth_impacts",
                         *[f"error_{m}" for m in METRICS], "reason"])
        for o in self.outcomes:
            s = o.setting
            writer.writerow([s.family, s.engine, s.solver, s.user_functions or "", s.parameter, f"{s.value:g}",
                             o.status, _fmt(o.median_time), _fmt(o.solve_time), _fmt(o.cpu_time), o.runs, _fmt(o.steps),
                             _fmt(o.impacts), _fmt(o.truth_impacts), *[_fmt(o.errors.get(m)) for m in METRICS],
                             o.reason])
        return buffer.getvalue()

    def summary_markdown(self) -> str:
        t = self.truth
        lines = [f"# Work-precision study: {self.scene.name}", "",
                 f"{t.end_time:g} s simulated; errors against the event-driven scipy reference (DOP853, rtol "
                 f"{t.rtol:g}), whose own uncertainty (vs rtol {CHECK_RTOL:g}) is "
                 + ", ".join(f"{METRIC_LABELS[m]} {_fmt(t.uncertainty.get(m), '.1e')}" for m in self.metrics())
                 + f". Time: median wall time of {self.repeats} complete runs (a run longer than 1.5 s once), "
                 "timed in interleaved rounds in this process; adaptive settings use max step "
                 f"{STUDY_MAX_STEP:g} s and atol = rtol x 1e-2. {self.load_note()}", "",
                 "## Cheapest setting per error target", "",
                 "Errors on every metric (" + ", ".join(METRIC_LABELS[m] for m in self.metrics()) + ") at most the target.",
                 "", "| target | cheapest setting | median time [s] | worst error | runner-up (other family) |",
                 "|---:|---|---:|---:|---|"]
        for target in TARGETS:
            best = self.cheapest(target)
            if best is None:
                lines.append(f"| {target:g} | none in the grid | | | |")
                continue
            per_family = sorted(self.cheapest_per_family(target).values(), key=lambda o: o.median_time)
            runner = next((o for o in per_family if o.setting.family != best.setting.family), None)
            runner_text = "-" if runner is None else f"{runner.setting.label()} ({runner.median_time:.3g} s)"
            lines.append(f"| {target:g} | {best.setting.label()} | {best.median_time:.3g} | "
                         f"{best.worst_error():.2g} | {runner_text} |")
        lines += ["", "Per metric (cheapest setting whose error on that metric alone is at most the target):", "",
                  "| target | " + " | ".join(METRIC_LABELS[m] for m in self.metrics()) + " |",
                  "|---:|" + "---|" * len(self.metrics())]
        for target in TARGETS:
            cells = []
            for m in self.metrics():
                o = self.cheapest(target, [m])
                cells.append("none" if o is None else f"{o.setting.label()} ({o.median_time:.3g} s)")
            lines.append(f"| {target:g} | " + " | ".join(cells) + " |")
        failures = self.failures()
        lines += ["", f"## Failing settings ({len(failures)} of {len(self.outcomes)})", ""]
        if not failures:
            lines.append("None.")
        else:
            lines += ["| setting | failure | reason |", "|---|---|---|"]
            for o in failures:
                lines.append(f"| {o.setting.label()} | {o.status} | {o.reason.replace('|', '/')[:700]} |")
        lines += ["", "## All settings", "", "| setting | status | median time [s] | steps | "
                  + " | ".join(METRIC_LABELS[m] for m in self.metrics()) + " |",
                  "|---|---|---:|---:|" + "---:|" * len(self.metrics())]
        for o in self.outcomes:
            lines.append(f"| {o.setting.label()} | {o.status} | {_fmt(o.median_time, '.3g')} | {_fmt(o.steps)} | "
                         + " | ".join(_fmt(o.errors.get(m), '.1e') for m in self.metrics()) + " |")
        lines += ["", "Files: `precision.csv`, `precision.json`, `work_precision_<metric>.png`.", ""]
        return "\n".join(lines)

    def figure(self, metric: str):
        """Log-log work-precision figure of one metric: relative error vs median wall time, one line per
        family; left the complete run (what a user waits for), right the integration alone."""
        from mbs_models.results.plotting import new_figure

        fig, axes = new_figure(1, 2, width=14.0, row_height=7.0)
        families = list(dict.fromkeys(o.setting.family for o in self.outcomes))
        colours = _colours(len(families))
        markers = "osD^v<>ph*XP8"
        floor = max(_positive_or(self.truth.uncertainty.get(metric), 1e-16), 1e-16)
        for col, (attribute, what) in enumerate((("median_time", "complete run (solve + post-processing)"),
                                                  ("solve_time", "integration only"))):
            ax = axes[0, col]
            for i, family in enumerate(families):
                points = [o for o in self.outcomes if o.setting.family == family and getattr(o, attribute)
                          and o.errors.get(metric) is not None and math.isfinite(o.errors[metric])]
                style = ":" if family.startswith("scipy") else ("--" if "(python)" in family else "-")
                ok = [o for o in points if o.ok]
                bad = [o for o in points if not o.ok]
                if ok:
                    ax.plot([max(o.errors[metric], floor * 0.1) for o in ok], [getattr(o, attribute) for o in ok],
                            style, marker=markers[i % len(markers)], color=colours[i], ms=5, lw=1.2, label=family)
                if bad:
                    ax.plot([max(o.errors[metric], floor * 0.1) for o in bad], [getattr(o, attribute) for o in bad],
                            "x", color=colours[i], ms=8, mew=1.5, label=None if ok else f"{family} (failed)")
            for target in TARGETS:
                ax.axvline(target, color="0.5", lw=0.8, ls="--")
            ax.axvspan(floor * 0.1, floor, color="0.85", zorder=0, label="truth uncertainty")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(f"relative error of the {METRIC_LABELS[metric]} [-]")
            ax.set_ylabel("median wall time per run [s]")
            ax.set_title(what, fontsize=10)
        handles, labels = axes[0, 0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncol=5, fontsize=8)
        fig.suptitle(f"Work-precision, {METRIC_LABELS[metric]}: {self.scene.name}, {self.truth.end_time:g} s "
                     "(x = missed/extra impact; dashed: Python user functions, dotted: scipy)", fontsize=11)
        return fig

    def write(self, out: str | Path) -> dict[str, Path]:
        """Write ``precision.csv``, ``precision.json``, ``precision.md`` and one figure per metric."""
        from mbs_models.outputs import atomic_write_json, atomic_write_text, prepare_output_dir
        from mbs_models.results.plotting import save_figure

        directory = prepare_output_dir(out)
        written = {"csv": atomic_write_text(directory / "precision.csv", self.csv_text()),
                   "json": atomic_write_json(directory / "precision.json", self.to_dict()),
                   "markdown": atomic_write_text(directory / "precision.md", self.summary_markdown())}
        for metric in self.metrics():
            written[metric] = save_figure(self.figure(metric), directory / f"work_precision_{metric}.png")
        return written


def _positive_or(value, default):
    return value if value is not None and value > 0 else default


def _colours(n: int) -> list:
    from matplotlib import colormaps

    cmap = colormaps["tab20"]
    return [cmap(i % 20) for i in range(n)]


def _fmt(value, spec: str = ".6g") -> str:
    if value is None:
        return "-"
    if isinstance(value, int):
        return str(value)
    return format(value, spec) if math.isfinite(value) else "inf"


def _warm_up(scene: Scene, end_time: float) -> None:
    """One untimed run, so that first-call costs (Exudyn, symbolic recording, numpy) are not timed."""
    from mbs_models.engine.simulation import simulate

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        simulate(scene, min(end_time, 1.0), "draft")
        solve_plain(scene, min(end_time, 1.0), "RK45", 1e-3)


def run_study(scene: Scene, settings: Sequence[Setting] | None = None, *, end_time: float = 10.0,
              repeats: int = 3, truth: Truth | None = None, quick: bool = False, long_run: float = 1.5,
              progress: Progress = _silent) -> Study:
    """The work-precision study of ``scene`` over ``settings`` (default :func:`default_grid`).

    Every setting is run once (status, errors, first time), then timed ``repeats - 1`` more times in
    interleaved rounds over the whole grid -- so that a burst of load on a shared machine spreads over all
    settings instead of spoiling one -- except runs longer than ``long_run`` s.
    """
    start = time.perf_counter()
    settings = list(settings if settings is not None else default_grid(quick))
    if truth is None:
        progress(f"truth: event-driven reference at rtol {TRUTH_RTOL:g} (and {CHECK_RTOL:g} as a check)")
        truth = compute_truth(scene, end_time)
    _warm_up(scene, end_time)
    outcomes = []
    first_runs = counter(progress, "settings, first run", "setting")
    for i, setting in enumerate(settings):
        outcome = run_setting(setting, scene, truth, repeats=1, long_run=long_run)
        outcomes.append(outcome)
        first_runs(i + 1, len(settings), f"{setting.label()}: {outcome.status}"
                   + (f", {outcome.median_time:.3g} s" if outcome.median_time is not None else ""))
    for round_ in range(2, max(1, repeats) + 1):
        timed = [o for o in outcomes if o.median_time is not None and o.median_time <= long_run]
        timing = counter(progress, f"timing round {round_}/{repeats}", "setting")
        for i, outcome in enumerate(timed):
            time_again(outcome, scene, truth)
            timing(i + 1, len(timed))
    return Study(scene=scene, truth=truth, outcomes=outcomes, repeats=repeats, wall_time=time.perf_counter() - start)


# ================================================================================================
# Accuracy presets on the paper cases

#: Relative errors each preset is stated to meet on all 19 paper cases (max barrel displacement, peak
#: contact force, max absorber velocity), measured by :func:`preset_study` (docs/guide/accuracy.md).
PRESET_ERROR_BOUNDS: dict[str, dict[str, float]] = {
    "draft": {"max_barrel_displacement": 1e-4, "peak_contact_force": 1e-3, "max_absorber_velocity": 1e-3},
    "standard": {"max_barrel_displacement": 1e-7, "peak_contact_force": 1e-6, "max_absorber_velocity": 1e-5},
    "reference": {"max_barrel_displacement": 1e-9, "peak_contact_force": 1e-8, "max_absorber_velocity": 1e-7},
}
PRESET_METRICS = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity")


def paper_cases() -> list[tuple[str, Scene]]:
    """The 19 paper cases: the simplified model, and models (i), (ii) x m = 100/500/1000 kg x gap 0/40/80 mm."""
    cases = [("simplified", simplified_model())]
    for label, factory in (("model-i", model_i), ("model-ii", model_ii)):
        for mass in (100.0, 500.0, 1000.0):
            for gap in (0.0, 0.04, 0.08):
                cases.append((f"{label}-m{mass:g}-gap{gap * 1000:g}mm", factory(mass, gap)))
    return cases


@dataclass
class PresetCase:
    """One preset on one case: errors, impacts, median time (s) and steps."""

    case: str
    errors: dict[str, float | None]
    impacts: int
    truth_impacts: int
    impacts_ok: bool
    median_time: float
    steps: int


@dataclass
class PresetStudy:
    """Each preset on the paper cases: per-case errors and times, worst errors, median time per run."""

    end_time: float
    presets: dict[str, Any]
    cases: dict[str, list[PresetCase]]
    truths: list[Truth]
    repeats: int

    def worst(self, preset: str) -> dict[str, float]:
        out = {}
        for m in PRESET_METRICS:
            values = [c.errors[m] for c in self.cases[preset] if c.errors.get(m) is not None]
            out[m] = max(values) if values else 0.0
        return out

    def median_time(self, preset: str) -> float:
        return statistics.median(c.median_time for c in self.cases[preset])

    def total_time(self, preset: str) -> float:
        return sum(c.median_time for c in self.cases[preset])

    def meets_bounds(self, preset: str, bounds: dict[str, float] | None = None) -> list[str]:
        """Violations of the stated bounds (empty: the preset meets them on every case)."""
        bounds = bounds or PRESET_ERROR_BOUNDS[preset]
        problems = []
        for c in self.cases[preset]:
            for m, bound in bounds.items():
                e = c.errors.get(m)
                if e is not None and not e <= bound:
                    problems.append(f"{preset} {c.case}: {m} error {e:.2e} > {bound:g}")
            if not c.impacts_ok:
                problems.append(f"{preset} {c.case}: impacts {c.impacts} vs truth {c.truth_impacts}")
        return problems

    def table_markdown(self) -> str:
        """The presets table: preset, solver settings, worst relative errors, median time per run."""
        n = len(next(iter(self.cases.values())))
        lines = [f"| preset | solver settings | worst relative error on the {n} paper cases: displacement / "
                 "force / absorber velocity | stated bound | median time per "
                 f"{self.end_time:g}-s run | all {n} cases |", "|---|---|---|---|---:|---:|"]
        fastest = min(self.total_time(p) for p in self.presets)
        for name, s in self.presets.items():
            w = self.worst(name)
            bound = PRESET_ERROR_BOUNDS.get(name, {})
            bound_text = " / ".join(f"{bound[m]:.0e}" for m in PRESET_METRICS) if bound else "-"
            label = f"`{name}`" + (" (default)" if name == "standard" else "")
            lines.append(f"| {label} | {s.solver} rtol {s.relative_tolerance:g}, atol {s.absolute_tolerance:g}, "
                         f"max step {s.max_step * 1e3:g} ms, {s.user_functions} | "
                         + " / ".join(f"{w[m]:.1e}" for m in PRESET_METRICS)
                         + f" | {bound_text} | {self.median_time(name) * 1e3:.0f} ms | "
                         f"{self.total_time(name):.2f} s ({self.total_time(name) / fastest:.1f}x) |")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        return {"end_time": self.end_time, "repeats": self.repeats,
                "presets": {name: {"settings": asdict(s), "worst": self.worst(name),
                                   "bounds": PRESET_ERROR_BOUNDS.get(name),
                                   "median_time": self.median_time(name), "total_time": self.total_time(name),
                                   "violations": self.meets_bounds(name) if name in PRESET_ERROR_BOUNDS else [],
                                   "cases": [{**asdict(c), "errors": {k: _finite(v) for k, v in c.errors.items()}}
                                             for c in self.cases[name]]}
                            for name, s in self.presets.items()},
                "truths": [t.to_dict() for t in self.truths]}

    def write(self, out: str | Path) -> dict[str, Path]:
        from mbs_models.outputs import atomic_write_json, atomic_write_text, prepare_output_dir

        directory = prepare_output_dir(out)
        text = (f"# Accuracy presets on the 19 paper cases ({self.end_time:g} s each)\n\n"
                "Errors against the event-driven scipy reference (DOP853, rtol 1e-12) of each case; time: median over "
                f"the cases of the median of {self.repeats} complete `simulate()` runs.\n\n"
                + self.table_markdown() + "\n")
        return {"presets_md": atomic_write_text(directory / "presets.md", text),
                "presets_json": atomic_write_json(directory / "presets.json", self.to_dict())}


def preset_study(presets: dict[str, Any] | None = None, cases: Sequence[tuple[str, Scene]] | None = None, *,
                 end_time: float = 10.0, repeats: int = 3, truths: Sequence[Truth] | None = None,
                 workers: int | None = None, progress: Progress = _silent) -> PresetStudy:
    """Run each preset (name -> SolverSettings; default ACCURACY_PRESETS) on ``cases`` (default the 19
    paper cases) against a truth per case (computed in parallel if not given); time each run serially."""
    from mbs_models.engine.accuracy import ACCURACY_PRESETS
    from mbs_models.engine.simulation import simulate

    presets = dict(presets or ACCURACY_PRESETS)
    cases = list(cases if cases is not None else paper_cases())
    if truths is None:
        truths = compute_truths([scene for _, scene in cases], end_time, workers=workers, progress=progress)
    _warm_up(cases[0][1], end_time)
    times: dict[tuple[str, str], list[float]] = {}
    results: dict[str, list[PresetCase]] = {name: [] for name in presets}
    done = counter(progress, "presets, first run", "case")
    for number, ((case, scene), truth) in enumerate(zip(cases, truths), 1):
        for name, settings in presets.items():
            start = time.perf_counter()
            result = simulate(scene, end_time, settings)
            times[case, name] = [time.perf_counter() - start]
            values = _engine_values(result, truth)
            errors = relative_errors(values, truth)
            missed, extra = impact_mismatch(values, truth) if scene.has_absorber else (0, 0)
            results[name].append(PresetCase(case=case, errors=errors, impacts=len(values.impacts),
                                            truth_impacts=len(truth.impacts), impacts_ok=not (missed or extra),
                                            median_time=0.0, steps=result.steps))
        done(number, len(cases), case)
    for _ in range(max(1, repeats) - 1):  # interleaved timing rounds (see run_study)
        for case, scene in cases:
            for name, settings in presets.items():
                start = time.perf_counter()
                simulate(scene, end_time, settings)
                times[case, name].append(time.perf_counter() - start)
    for name in presets:
        for entry in results[name]:
            entry.median_time = statistics.median(times[entry.case, name])
    return PresetStudy(end_time=float(end_time), presets=presets, cases=results, truths=list(truths),
                       repeats=repeats)
