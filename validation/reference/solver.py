"""Event-driven scipy reference solution of the paper's Eqs. (1)-(8).

:func:`solve_reference` integrates the equations of :mod:`validation.reference.equations` with
``scipy.integrate.solve_ivp`` in segments on which the right-hand side is smooth.  A segment stops at
every switch (terminal events, located by root finding on the dense output):

* ``p``  -- contact onset / release, penetration p = 0 (m);
* ``s``  -- Hunt-Crossley force reaching 0 by clipping, ``1 + lambda p' = 0`` while ``p > 0``;
* ``pd`` -- ``p' = 0`` while ``p > 0`` (only with the ``compression_only`` convention);
* ``v``  -- barrel velocity sign change, switch of the recoil damper, Eqs. (2)-(3);
* ``release`` / ``slip`` -- end of a STICK (sliding) phase, see :mod:`validation.reference.equations`.

At each restart the mode is chosen from the state; a quantity sitting on its switching surface is
classified by the direction the state is heading (the crossing direction of the event that stopped the
previous segment, or the sign of its time derivatives).  Metrics are refined on the dense output
(root finding on the derivative), not taken from samples; see :mod:`validation.reference.result`.
"""

from __future__ import annotations

import time
from functools import partial

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from mbs_models.scene import Scene

from . import equations as eq
from .equations import OFF, ON, STICK, Mode, Parameters
from .finality import METRICS, Finality, check_names
from .result import STOP_END_TIME, STOP_METRICS_FINAL, STOP_NO_BOUND, ReferenceImpact, ReferenceResult, ReferenceSegment

__all__ = ["METHODS", "ReferenceSolveError", "solve_reference", "ReferenceResult", "ReferenceImpact",
           "ReferenceSegment"]

#: solve_ivp methods accepted by :func:`solve_reference`.
METHODS = ("DOP853", "RK45", "Radau", "LSODA")
#: |g| below these (m, 1, m/s) counts as "on the switching surface" when no event says so.
_TOL_POS, _TOL_S, _TOL_VEL = 1e-14, 1e-14, 1e-14
#: consecutive zero-length segments tolerated before declaring chattering.
_MAX_STALLS = 50


class ReferenceSolveError(RuntimeError):
    """The reference solve failed (solver error, non-finite state, chattering/Zeno); says why."""


def _heading(g, dg, ddg=0.0, tol=_TOL_POS) -> bool:
    """Is ``g`` (with derivatives ``dg``, ``ddg``) positive or about to become positive?"""
    if abs(g) > tol:
        return g > 0
    if abs(dg) > _TOL_VEL:
        return dg > 0
    return ddg > 0


def _sided(g, t_start: float, positive: bool, window: float = 0.0):
    """Terminal event from ``g(t, y)`` watching the crossing that leaves the ``positive`` side.

    For ``t_start <= t <= t_start + window`` the function reports the classified side (a tiny value of
    that sign if ``g`` says otherwise): a surface the state has just left is re-armed only once ``g`` has
    moved clear of round-off noise, so noise in the dense output right after the restart, or a return
    within the first step, is not mistaken for a crossing at ``t_start``.
    """
    sign = 1.0 if positive else -1.0

    def fun(t, y):
        value = g(t, y)
        if t - t_start <= window and not sign * value > 0:
            return sign * 1e-300
        return value
    fun.terminal = True
    fun.direction = -sign
    fun.raw, fun.sign, fun.t_start, fun.window = g, sign, t_start, window
    return fun


def _rearm_window(value: float, rate: float | None, noise: float, positive: bool) -> float:
    """Time (s) for a function sitting on its surface (``|value| <= noise``) to clear 100 noise levels."""
    if abs(value) > noise or rate is None or not (rate > 0) == positive or rate == 0:
        return 0.0
    return min(100.0 * noise / abs(rate), 1e-8)


def _missed_crossing(dense, funcs, names, t0: float, t1: float):
    """Earliest crossing inside ``(t0, t1)`` that solve_ivp's step-end sign checks missed.

    solve_ivp only compares event signs at step ends, so a surface left and re-entered within one step
    (a short separation or a grazing contact) goes unseen.  The dense output is scanned on the steps
    subdivided 8 times; returns ``(t, name)`` of the first such crossing, or None.
    """
    ts = np.asarray(dense.ts, dtype=float)
    ts = np.unique(np.concatenate(([t0], ts[(ts > t0) & (ts < t1)], [t1])))
    tg = np.concatenate(((ts[:-1, None] + np.diff(ts)[:, None] * np.arange(8)[None, :] / 8).ravel(), [t1]))
    yg = dense(tg)
    found = None
    for fun, name in zip(funcs, names):
        g = fun.sign * np.broadcast_to(fun.raw(tg, yg), tg.shape)
        wrong = (g < -1e-12 * np.max(np.abs(g))) & (tg > t0 + fun.window)
        wrong[0] = wrong[-1] = False
        if wrong.any():
            j = int(np.argmax(wrong))
            try:
                tr = brentq(lambda s: fun(s, dense(s)), tg[j - 1], tg[j], xtol=1e-16, maxiter=200)
            except ValueError:  # g at tg[j-1] is within round-off of the surface already
                tr = float(tg[j - 1])
            if found is None or tr < found[0]:
                found = (tr, name)
    return found


class _Flags:
    """Which side of every switching surface the state is on, and the resulting :class:`Mode`."""

    def __init__(self, P: Parameters, y, hints: dict[str, bool]):
        provisional = Mode(OFF, bool(y[1] > 0))
        f_M, f_m = eq.other_forces(P, y, provisional)
        pdd_free = f_M / P.M - (f_m / P.m if P.has_absorber else 0.0)  # p'' with F = 0
        self.p_pos = self.s_pos = False
        contact = OFF
        if P.has_absorber:
            p, pd, s = eq.penetration(P, y), eq.penetration_rate(P, y), eq.damping_term(P, y)
            self.p_pos = hints["p"] if "p" in hints else _heading(p, pd, pdd_free)
            if self.p_pos:
                self.s_pos = hints["s"] if "s" in hints else _heading(s, P.lam * pdd_free, tol=_TOL_S)
            if self.p_pos and self.s_pos:
                contact = ON if not P.compression_only else self._compression_only(P, y, hints, pd, pdd_free)
        recoil = True
        if not P.symmetric_damper:
            recoil = bool(y[1] > 0)
            if "v" in hints or abs(y[1]) <= _TOL_VEL:
                a_M, _ = eq.accelerations(P, y, Mode(contact, recoil, bool(self.p_pos)))
                recoil = bool(a_M > 0) if a_M != 0 else hints.get("v", recoil)
        self.mode = Mode(contact, recoil, bool(self.p_pos))

    @staticmethod
    def _compression_only(P: Parameters, y, hints, pd, pdd_free) -> str:
        """Contact mode under ``compression_only`` at p > 0, s > 0 (three-way rule at p' = 0)."""
        if "release" in hints:
            return OFF
        if "slip" in hints:
            return ON
        if "pd" not in hints and abs(pd) > _TOL_VEL:
            return ON if pd > 0 else OFF
        # On the surface p' = 0: the force is k_c p^n (s = 1) if compressing, 0 otherwise.
        pdd_on = pdd_free - P.kc * max(eq.penetration(P, y), 0.0) ** P.n / P.m_red
        if pdd_on > 0:
            return ON       # even with the force the bodies keep approaching
        if pdd_free <= 0:
            return OFF      # even without the force they separate
        return STICK        # both sides push onto p' = 0: Filippov sliding

    def events(self, P: Parameters, t_start: float, y):
        """Terminal event functions watched in this mode from state ``y`` at ``t_start``, and their names.

        Each item is ``(name, g, positive, rate, noise)``: ``rate`` is dg/dt at the start in the new mode
        (None if not available), ``noise`` the round-off level of ``g``, both used for re-arming.
        """
        mode = self.mode
        dy = eq.rhs(P, mode, t_start, y)
        pos_noise = 1e-15 * max(1.0, abs(y[0]), abs(y[2]), abs(P.gap_offset))
        vel_noise = 1e-15 * max(1.0, abs(y[1]), abs(y[3]))
        items = []
        if P.has_absorber and mode.contact != STICK:
            items.append(("p", lambda t, y: eq.penetration(P, y), self.p_pos, dy[0] - dy[2], pos_noise))
            if self.p_pos:
                items.append(("s", lambda t, y: eq.damping_term(P, y), self.s_pos, P.lam * (dy[1] - dy[3]),
                              vel_noise * max(1.0, abs(P.lam))))
                if P.compression_only and self.s_pos:
                    items.append(("pd", lambda t, y: eq.penetration_rate(P, y), mode.contact == ON,
                                  dy[1] - dy[3], vel_noise))
        if mode.contact == STICK:
            def release(t, y):
                return eq.sticking_force(P, *eq.other_forces(P, y, mode))

            def slip(t, y):
                return release(t, y) - P.kc * np.maximum(eq.penetration(P, y), 0.0) ** P.n
            items += [("release", release, True, None, 0.0), ("slip", slip, False, None, 0.0)]
        if not P.symmetric_damper:
            items.append(("v", lambda t, y: y[1], mode.recoil, dy[1], vel_noise))
        funcs, names = [], []
        for name, g, positive, rate, noise in items:
            window = _rearm_window(float(g(t_start, y)), rate, noise, positive)
            funcs.append(_sided(g, t_start, positive, window))
            names.append(name)
        return funcs, names


def _check_args(scene, end_time, method, rtol, atol, impact_threshold, max_step, max_segments):
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a mbs_models Scene, got {type(scene).__name__}")
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    for name, value in (("end_time", end_time), ("rtol", rtol), ("atol", atol), ("max_step", max_step)):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    if not impact_threshold >= 0:
        raise ValueError(f"impact_threshold must be >= 0 N, got {impact_threshold!r}")
    if int(max_segments) < 1:
        raise ValueError(f"max_segments must be >= 1, got {max_segments!r}")


def solve_reference(scene: Scene, end_time: float = 10.0, *, method: str = "DOP853", rtol: float = 1e-10,
                    atol: float = 1e-12, impact_threshold: float = 1000.0, max_step: float = 0.01,
                    max_segments: int = 20000, stop_when_final=()) -> ReferenceResult:
    """Integrate Eqs. (1)-(8) for ``scene`` over ``[0, end_time]`` s with event-driven ``solve_ivp``.

    Parameters
    ----------
    scene: the mechanism; v0 is ``scene.initial_velocity`` (m/s), both bodies start at 0.
    end_time: simulated time in s.
    method: ``"DOP853"`` (default), ``"RK45"``, ``"Radau"`` or ``"LSODA"``.
    rtol, atol: solver tolerances; ``atol`` is in m and m/s for the mechanical states and is scaled by
        the initial energy (J) for the three dissipated-energy states.
    impact_threshold: contact episodes with a peak force above this (N) are reported as impacts.
    max_step: largest solver step in s (keeps grazing contacts from being stepped over).
    max_segments: cap on the number of smooth segments; more raises :class:`ReferenceSolveError`.
    stop_when_final: metric names among :data:`validation.reference.finality.METRICS`; the integration stops
        once energy bounds (:mod:`validation.reference.finality`) prove that none of them can change before
        ``end_time``: checked at every segment end, and inside a segment by a terminal event (which
        leaves the solver's steps before it unchanged, so the window is the full run's prefix).  The
        result then covers ``[0, result.end_time]``, ``result.stop_reason == "metrics_final"``, and
        metrics not proven final are None.  Scenes that inject energy (``literal_lambda_sign``) run
        to ``end_time`` (``stop_reason == "end_time_no_energy_bound"``).

    Raises
    ------
    ReferenceSolveError: solver failure, non-finite state, or chattering (too many segments).
    ValueError: a bad argument (names it).
    """
    _check_args(scene, end_time, method, rtol, atol, impact_threshold, max_step, max_segments)
    requested = check_names(stop_when_final)
    P = Parameters.from_scene(scene)
    finality = Finality(P, requested, impact_threshold) if requested else None
    early = finality is not None and finality.enabled
    y = np.array([0.0, P.v0, 0.0, 0.0, 0.0, 0.0, 0.0])
    energy0 = sum(eq.energy_components(P, y).values())
    e_scale = max(float(energy0), 1.0)
    atol_vec = atol * np.array([1.0, 1.0, 1.0, 1.0, e_scale, e_scale, e_scale])
    start = time.perf_counter()
    t, hints, stalls, nfev = 0.0, {}, 0, 0
    segments: list[ReferenceSegment] = []
    while t < end_time:
        if len(segments) >= max_segments:
            raise ReferenceSolveError(f"more than {max_segments} smooth segments before t = {t:.9g} s "
                                      f"(chattering / Zeno behaviour?) in scene {scene.name!r}")
        flags = _Flags(P, y, hints)
        funcs, names = flags.events(P, t, y)
        contact_off = flags.mode.contact == OFF
        stop = [finality.stop_event(contact_off)] if early else []
        # rejected trial steps of an explicit method on a stiff contact may overflow; accepted states
        # are checked for finiteness below, so the floating-point warnings are noise, not results
        with np.errstate(over="ignore", invalid="ignore"):
            sol = solve_ivp(partial(eq.rhs, P, flags.mode), (t, end_time), y, method=method, rtol=rtol,
                            atol=atol_vec, dense_output=True, events=(funcs + stop) or None, max_step=max_step)
        nfev += sol.nfev
        if sol.status < 0:
            raise ReferenceSolveError(f"solve_ivp ({method}) failed at t = {t:.9g} s in mode {flags.mode}: "
                                      f"{sol.message}")
        if not np.all(np.isfinite(sol.y)):
            raise ReferenceSolveError(f"non-finite state after t = {t:.9g} s in mode {flags.mode}")
        t_new, y = float(sol.t[-1]), sol.y[:, -1].copy()
        hints = {}
        if sol.status == 1:
            hints = {name: fun.direction > 0 for name, fun, te in zip(names, funcs, sol.t_events)
                     if len(te) and te[-1] == t_new}
        missed = _missed_crossing(sol.sol, funcs, names, t, t_new) if funcs and t_new > t else None
        if missed is not None:
            t_new, y = missed[0], sol.sol(missed[0])
            hints = {missed[1]: dict(zip(names, funcs))[missed[1]].direction > 0}
        if t_new > t:
            segments.append(ReferenceSegment(t, t_new, flags.mode, sol.sol))
        if early and t_new > t:
            finality.observe_segment(flags.mode, sol.sol, t, t_new)
            finality.check(y, contact_off)
            if finality.done:
                finality.check(y, contact_off, METRICS)  # which others are final here too
                t = t_new
                break
        if t_new - t <= 1e-14 * max(1.0, t):
            stalls += 1
            if stalls > _MAX_STALLS:
                raise ReferenceSolveError(f"stuck at t = {t:.12g} s: {_MAX_STALLS} zero-length segments "
                                          f"(mode {flags.mode}, events {sorted(hints)})")
        else:
            stalls = 0
        t = t_new
    stopped = early and finality.done and t < end_time
    if stopped:
        reason, final = STOP_METRICS_FINAL, tuple(m for m in METRICS if m in finality.final)
    else:
        reason, final = (STOP_NO_BOUND if requested and not early else STOP_END_TIME), METRICS
    return ReferenceResult(scene=scene, end_time=float(t) if stopped else float(end_time), segments=segments,
                           parameters=P, method=method, rtol=rtol, atol=atol, impact_threshold=impact_threshold,
                           nfev=nfev, wall_time=time.perf_counter() - start, requested_end_time=float(end_time),
                           stop_reason=reason, final_metrics=final)
