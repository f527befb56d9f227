"""Event-driven scipy reference solution of a scene's equations of motion (DESIGN.md).

:func:`solve_reference` builds the scene's :class:`~validation.reference.model.Model` from the terms
(:mod:`validation.reference.assembly`) and integrates ``m_i x_i'' = sum of connector forces`` with
``scipy.integrate.solve_ivp`` in segments on which the right-hand side is smooth: every connector's
discrete state is fixed for a segment (a :class:`~validation.reference.model.Mode`), and a segment stops
at the first switching surface the state crosses (terminal events, located by root finding on the dense
output; the surfaces are the connectors', e.g. a contact's onset, release and clipping, the recoil
damper's velocity sign).  At each restart the mode is chosen from the state
(:class:`~validation.reference.switching.Restart`).  Metrics are refined on the dense output (root
finding on the derivative), not taken from samples; see :mod:`validation.reference.result`.

External inputs (:class:`~validation.reference.model.Load`, :class:`~validation.reference.model.Impulse`)
add **time events** (:attr:`Model.time_events`): the breakpoints of every load (a segment integrates one
smooth piece of its law), the times of the velocity jumps and the shot times.  A segment ends at the next
time event at the latest; there the jumps firing at that time are applied to the state
(:meth:`Model.apply_impulses`: ``v += dv``, the work ``m ((v + dv)^2 - v^2) / 2`` added) and the solve
restarts with the mode classified again from the new state.  A scene without inputs or burst has none.
"""

from __future__ import annotations

import bisect
import time

import numpy as np
from scipy.integrate import OdeSolution, solve_ivp

from .assembly import build_model
from .dense import DenseSolution
from .finality import METRICS, Finality, check_names
from .result import STOP_END_TIME, STOP_METRICS_FINAL, STOP_NO_BOUND, ReferenceImpact, ReferenceResult, ReferenceSegment
from .switching import NonFiniteEvent, Restart, missed_crossing

__all__ = ["METHODS", "ReferenceSolveError", "solve_reference", "ReferenceResult", "ReferenceImpact",
           "ReferenceSegment"]

#: solve_ivp methods accepted by :func:`solve_reference`.
METHODS = ("DOP853", "RK45", "Radau", "LSODA")
#: consecutive zero-length segments tolerated before declaring chattering.
_MAX_STALLS = 50
#: The solver step that crosses a surface where the right-hand side is only C^1 (``rough_events``) is
#: integrated again from its start in at least this many steps.
_SUBSTEPS = 16


class ReferenceSolveError(RuntimeError):
    """The reference solve failed (solver error, non-finite state, chattering/Zeno); says why."""


def _integrate(rhs, t0: float, t1: float, y0, options: dict, mode):
    """``solve_ivp`` with dense output from ``(t0, y0)``; ReferenceSolveError on failure or non-finite states."""
    # rejected trial steps of an explicit method on a stiff contact may overflow; accepted states
    # are checked for finiteness below, so the floating-point warnings are noise, not results
    with np.errstate(over="ignore", invalid="ignore"):
        try:
            sol = solve_ivp(rhs, (t0, t1), y0, dense_output=True, **options)
        except NonFiniteEvent as exc:
            raise ReferenceSolveError(f"non-finite state after t = {t0:.9g} s in {mode}: {exc}") from None
    if sol.status < 0:
        raise ReferenceSolveError(f"solve_ivp ({options['method']}) failed at t = {t0:.9g} s in {mode}: "
                                  f"{sol.message}")
    if not np.all(np.isfinite(sol.y)):
        raise ReferenceSolveError(f"non-finite state after t = {t0:.9g} s in {mode}")
    sol.sol = DenseSolution.of(sol.sol)  # the same values, evaluated on many times at once
    return sol


def _hints(sol, funcs, names) -> dict[str, bool]:
    """The events that stopped ``sol`` (at its last time), with the direction of their crossing."""
    if sol.status != 1:
        return {}
    t_end = sol.t[-1]
    return {name: fun.direction > 0 for name, fun, te in zip(names, funcs, sol.t_events[:len(funcs)])
            if len(te) and te[-1] == t_end}


def _refine_last_step(sol, rhs, t1: float, options: dict, mode):
    """``sol`` with its last step (the one in which the event was found) integrated again from its start in
    at least :data:`_SUBSTEPS` steps; the dense output joins the two solutions at that step's start."""
    t_k, y_k = float(sol.t[-2]), sol.y[:, -2]
    h = (sol.t[-1] - t_k) / _SUBSTEPS
    if not h > 0:
        return sol
    again = _integrate(rhs, t_k, t1, y_k, {**options, "max_step": min(options["max_step"], h)}, mode)
    ts = np.concatenate((sol.sol.ts[:-1], again.sol.ts[1:]))
    again.sol = DenseSolution.of(OdeSolution(ts, sol.sol.interpolants[:-1] + again.sol.interpolants))
    again.t = np.concatenate((sol.t[:-1], again.t[1:]))
    again.y = np.concatenate((sol.y[:, :-1], again.y[:, 1:]), axis=1)
    again.nfev_refinement = again.nfev
    again.nfev = sol.nfev
    return again


def segment_end(sol, funcs, names, t: float):
    """``(t_new, y, hints)`` where a segment that started at ``t`` ends: the solver's last state and the events
    that stopped it, or the first crossing inside it that the step-end sign checks missed (then the state there,
    from the dense output)."""
    hints = _hints(sol, funcs, names)
    t_new, y = float(sol.t[-1]), sol.y[:, -1].copy()
    missed = missed_crossing(sol.sol, funcs, names, t, t_new) if funcs and t_new > t else None
    if missed is not None:
        t_new, y = missed[0], sol.sol(missed[0])
        hints = {missed[1]: dict(zip(names, funcs))[missed[1]].direction > 0}
    return t_new, y, hints


def check_segment_count(segments, max_segments: int, t: float, name: str) -> None:
    """ReferenceSolveError once ``max_segments`` segments are reached (chattering / Zeno behaviour)."""
    if len(segments) >= max_segments:
        raise ReferenceSolveError(f"more than {max_segments} smooth segments before t = {t:.9g} s "
                                  f"(chattering / Zeno behaviour?) in scene {name!r}")


def count_stalls(stalls: int, t: float, t_new: float, mode, hints) -> int:
    """The count of consecutive zero-length segments after one from ``t`` to ``t_new``; ReferenceSolveError
    beyond :data:`_MAX_STALLS`."""
    if t_new - t > 1e-14 * max(1.0, t):
        return 0
    if stalls + 1 > _MAX_STALLS:
        raise ReferenceSolveError(f"stuck at t = {t:.12g} s: {_MAX_STALLS} zero-length segments "
                                  f"({mode}, events {sorted(hints)})")
    return stalls + 1


def _check_args(scene, end_time, method, rtol, atol, impact_threshold, max_step, max_segments):
    if not (callable(getattr(scene, "tables", None)) and hasattr(scene, "barrel")):
        raise TypeError(f"scene must be a scene (tables read as data), got {type(scene).__name__}")
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    for name, value in (("end_time", end_time), ("rtol", rtol), ("atol", atol), ("max_step", max_step)):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    if not impact_threshold >= 0:
        raise ValueError(f"impact_threshold must be >= 0 N, got {impact_threshold!r}")
    if int(max_segments) < 1:
        raise ValueError(f"max_segments must be >= 1, got {max_segments!r}")


def solve_reference(scene, end_time: float = 10.0, *, method: str = "DOP853", rtol: float = 1e-10,
                    atol: float = 1e-12, impact_threshold: float = 1000.0, max_step: float = 0.01,
                    max_segments: int = 20000, stop_when_final=(), refine_releases: bool = False) -> ReferenceResult:
    """Integrate the scene's equations over ``[0, end_time]`` s with event-driven ``solve_ivp``.

    Parameters
    ----------
    scene: the mechanism (a ``mbs_models`` Scene, read as data); every body starts at x = 0, the barrel at
        v0 (DESIGN.md), the absorbers at rest.
    end_time: simulated time in s; shots and pulses after it do not happen.
    method: ``"DOP853"`` (default), ``"RK45"``, ``"Radau"`` or ``"LSODA"``.
    rtol, atol: solver tolerances; ``atol`` is in m and m/s for the mechanical states and is scaled by
        the initial energy (J, at least 1) for the dissipated-energy states.
    impact_threshold: contact episodes with a peak force above this (N) are reported as impacts.
    max_step: largest solver step in s (keeps grazing contacts from being stepped over).
    max_segments: cap on the number of smooth segments; more raises :class:`ReferenceSolveError`.
    stop_when_final: metric names among :data:`validation.reference.finality.METRICS`; the integration stops
        once energy bounds (:mod:`validation.reference.finality`) prove that none of them can change before
        ``end_time``: checked at every segment end, and inside a segment by a terminal event (which
        leaves the solver's steps before it unchanged, so the window is the full run's prefix).  The
        result then covers ``[0, result.end_time]``, ``result.stop_reason == "metrics_final"``, and
        metrics not proven final are None.  Scenes that inject energy (``literal_lambda_sign``) or have
        a load that never ends (a constant load) run to ``end_time`` (``stop_reason ==
        "end_time_no_energy_bound"``).  With shots and pulses the bounds apply only from the last external
        input on (:attr:`Model.last_input_time`: the last shot, the end of the last pulse): no stop
        before it.
    refine_releases: integrate the solver step in which a power-law contact releases (``p = 0`` from
        above, where ``k p^n`` is only C^1 and the step's error estimate can miss its error) again from
        its start in at least 16 steps.  Off by default: version 1 did not, and its results are kept
        bit for bit.  Measured: a free Flores impact (e = 0.8, max_step 2.5 ms) rebounds 2.9e-6 off the
        closed form without, 2e-10 with; the late, weak impacts of model (i), m = 500 kg, gap 0 have
        peaks 2.8e-7 off a rtol = 1e-13 run without, 1.5e-8 with.

    A scene with ``[carriage]`` is solved by the planar model (:func:`validation.reference.planar.solve_planar`,
    a :class:`~validation.reference.planar.PlanarResult`).

    Raises
    ------
    ReferenceSolveError: solver failure, non-finite state, or chattering (too many segments).
    ReferenceModelError: a scene table the reference has no term for.
    ValueError: a bad argument (names it).
    """
    if getattr(scene, "carriage", None) is not None:  # the gun on its carriage: the planar model
        from .planar import solve_planar
        return solve_planar(scene, end_time, method=method, rtol=rtol, atol=atol, impact_threshold=impact_threshold,
                            max_step=max_step, max_segments=max_segments, stop_when_final=stop_when_final,
                            refine_releases=refine_releases)
    _check_args(scene, end_time, method, rtol, atol, impact_threshold, max_step, max_segments)
    requested = check_names(stop_when_final)
    model = build_model(scene)
    finality = Finality(model, requested, impact_threshold) if requested else None
    early = finality is not None and finality.enabled
    y = model.initial_state()
    e_scale = max(float(model.mechanical_energy(y)), 1.0)
    atol_vec = atol * np.concatenate((np.ones(2 * model.n_bodies),
                                      np.full(model.n_states - 2 * model.n_bodies, e_scale)))
    #: the solve is split at these (shots, jumps, the loads' breakpoints); the bounds hold after the last input
    time_events = [te for te in model.time_events if te < end_time]
    last_input = model.last_input_time
    start = time.perf_counter()
    t, hints, stalls, nfev, previous = 0.0, {}, 0, 0, None
    segments: list[ReferenceSegment] = []
    while t < end_time:
        check_segment_count(segments, max_segments, t, model.name)
        k = bisect.bisect_right(time_events, t)
        t_bound = time_events[k] if k < len(time_events) else end_time
        restart = Restart(model, t, y, hints, previous)
        mode = previous = restart.mode
        funcs, names = restart.events()
        checking = early and t >= last_input  # no input acts from t on: the energy bounds hold
        stop = [finality.stop_event(mode)] if checking else []
        options = dict(method=method, rtol=rtol, atol=atol_vec, max_step=max_step, events=(funcs + stop) or None)
        sol = _integrate(model.rhs(mode), t, t_bound, y, options, mode)
        nfev += sol.nfev
        hints = _hints(sol, funcs, names)
        if refine_releases and set(hints) & restart.rough and len(sol.t) >= 2:
            sol = _refine_last_step(sol, model.rhs(mode), t_bound, options, mode)
            nfev += sol.nfev_refinement
        t_new, y, hints = segment_end(sol, funcs, names, t)
        if t_new > t:
            segments.append(ReferenceSegment(t, t_new, mode, sol.sol))
        if early and t_new > t:
            finality.observe_segment(mode, sol.sol, t, t_new)
            if checking:
                finality.check(y, mode)
                if finality.done:
                    finality.check(y, mode, METRICS)  # which others are final here too
                    t = t_new
                    break
        stalls = count_stalls(stalls, t, t_new, mode, hints)
        t = t_new
        if t == t_bound and t < end_time:  # a time event: the jumps firing now, then a restart
            y = model.apply_impulses(t, y)
    stopped = early and finality.done and t < end_time
    if stopped:
        reason, final = STOP_METRICS_FINAL, tuple(m for m in METRICS if m in finality.final)
    else:
        reason, final = (STOP_NO_BOUND if requested and not early else STOP_END_TIME), METRICS
    return ReferenceResult(scene=scene, model=model, end_time=float(t) if stopped else float(end_time),
                           segments=segments, method=method, rtol=rtol, atol=atol, impact_threshold=impact_threshold,
                           nfev=nfev, wall_time=time.perf_counter() - start, requested_end_time=float(end_time),
                           stop_reason=reason, final_metrics=final)
