"""Event-driven scipy solution of the planar model (the gun on its carriage).

As the 1-D solve (:mod:`validation.reference.solver`): ``solve_ivp`` in segments on which the right-hand side
is smooth, every axis connector's and every support's discrete state fixed for a segment
(:class:`.model.PlanarMode`), a segment ending at the first switching surface crossed (the axis connectors',
and the supports': touching or leaving the ground, N reaching 0, the friction's branches), the mode chosen
again there (:class:`.switching.PlanarRestart`); the loads' breakpoints and the shots are time events (a
shot: ``x_b' += I / m_b``, :meth:`.model.PlanarModel.apply_impulses`).  Where a spade leaves the ground or
enters it again, its spring's energy ``k_h (x_s - x_s0)^2 / 2`` leaves or enters the balance: it is added
to (taken from) the support's dissipated energy there (a spade anchored where it touches down enters with none).

The initial state: the axis model's (x_i0, v0 of the barrel, the absorbers at rest), the carriage at rest in the
static equilibrium (:mod:`.statics`).
"""

from __future__ import annotations

import bisect
import time

import numpy as np

from ..assembly import build_model
from ..solver import _check_args, _integrate, check_segment_count, count_stalls, segment_end
from ..result import ReferenceSegment
from .kinematics import Geometry
from .model import PlanarModel
from .result import PlanarResult
from .statics import static_equilibrium
from .supports import Support
from .switching import PlanarRestart


def build_planar_model(scene) -> tuple[PlanarModel, np.ndarray]:
    """The planar model of a scene with ``[carriage]`` and its initial state (module docstring)."""
    axis = build_model(scene)
    geometry = Geometry.of(scene, axis.masses)
    supports = [Support(table) for table in scene.carriage.supports]
    y_axis = axis.initial_state()
    xs = [y_axis[2 * i] for i in range(axis.n_bodies)]
    static = static_equilibrium(geometry, supports, xs)
    for support, x in zip(supports, static["x"]):
        support.anchor = x
    model = PlanarModel(axis, geometry, supports)
    model.static = static
    y = np.concatenate((y_axis, [0.0, static["Y"], static["phi"], 0.0, 0.0, 0.0], np.zeros(len(supports))))
    return model, y


def _anchor_jumps(model: PlanarModel, previous, mode, y: np.ndarray) -> np.ndarray:
    """``y`` with the spades' spring energy moved into (out of) their dissipated energy where one leaves (enters)
    the ground between ``previous`` and ``mode``."""
    if previous is None:
        return y
    y = y.copy()
    for k, s in enumerate(model.supports):
        before, after = previous.supports[k], mode.supports[k]
        if s.anchored and before.spring_stored != after.spring_stored:
            x_s = model.support_motion(s)(y)[0]
            if before.spring_stored:
                y[model.support_slot + k] += float(s.anchor_energy(before.anchor, x_s))
            else:
                y[model.support_slot + k] -= float(s.anchor_energy(after.anchor, x_s))
    return y


def solve_planar(scene, end_time: float = 1.0, *, method: str = "DOP853", rtol: float = 1e-10,
                 atol: float = 1e-12, impact_threshold: float = 1000.0, max_step: float = 0.01,
                 max_segments: int = 20000, stop_when_final=(), refine_releases: bool = False) -> PlanarResult:
    """Integrate the planar model of ``scene`` (it has ``[carriage]``) over ``[0, end_time]`` s.

    Parameters as :func:`validation.reference.solve_reference` (``atol`` in m, m/s, rad, rad/s; scaled by the
    initial energy for the energy states).  ``stop_when_final`` is not supported on a carriage (no energy
    bounds for the supports): the solve runs to ``end_time`` (``stop_reason == "end_time_no_energy_bound"``
    when metrics were named).  ``refine_releases`` is accepted and ignored.

    Raises ReferenceSolveError (solver failure, chattering), ReferenceModelError (no static equilibrium, a
    table without a term), ValueError (a bad argument).
    """
    _check_args(scene, end_time, method, rtol, atol, impact_threshold, max_step, max_segments)
    model, y = build_planar_model(scene)
    axis = model.axis
    e_scale = max(float(sum(model.kinetic_energies(y).values())), 1.0)
    atol_vec = np.full(model.n_states, float(atol))
    energy_slots = list(range(2 * axis.n_bodies, model.n1)) + list(range(model.support_slot, model.n_states))
    atol_vec[energy_slots] *= e_scale
    time_events = [te for te in axis.time_events if te < end_time]
    start = time.perf_counter()
    t, hints, stalls, nfev, previous = 0.0, {}, 0, 0, None
    segments: list[ReferenceSegment] = []
    while t < end_time:
        check_segment_count(segments, max_segments, t, axis.name)
        k = bisect.bisect_right(time_events, t)
        t_bound = time_events[k] if k < len(time_events) else end_time
        restart = PlanarRestart(model, t, y, hints, previous)
        mode = restart.mode
        y = _anchor_jumps(model, previous, mode, y)
        restart.y = y
        previous = mode
        funcs, names = restart.events()
        options = dict(method=method, rtol=rtol, atol=atol_vec, max_step=max_step, events=funcs or None)
        rhs = model.rhs(mode)
        sol = _integrate(rhs, t, t_bound, y, options, mode)
        nfev += sol.nfev
        t_new, y, hints = segment_end(sol, funcs, names, t)
        if t_new > t:
            segments.append(ReferenceSegment(t, t_new, mode, sol.sol))
        stalls = count_stalls(stalls, t, t_new, mode, hints)
        t = t_new
        if t == t_bound and t < end_time:
            y = model.apply_impulses(t, y)
    reason = "end_time_no_energy_bound" if tuple(stop_when_final) else "end_time"
    return PlanarResult(scene=scene, model=model, end_time=float(end_time), segments=segments, method=method,
                        rtol=rtol, atol=atol, impact_threshold=impact_threshold, nfev=nfev,
                        wall_time=time.perf_counter() - start, requested_end_time=float(end_time),
                        stop_reason=reason)
