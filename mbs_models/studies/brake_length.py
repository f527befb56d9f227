"""The designed brake that gives the asked recoil length in the simulation, not only in the closed form.

:func:`~mbs_models.studies.brake_design.design_brake` is the constant-resistance rule for a design length
``L_d``: it tabulates the orifice over ``[0, 0.95 L_d]`` and holds the last area beyond, where the brake's
``K v^2`` law alone never stops the barrel (the recoil spring or recuperator does), and the pulse and the
preload the rule treats as an impulse and a static force move the barrel too.  The simulated recoil
length ``f(L_d)`` (the maximum barrel displacement, m) therefore differs from ``L_d``: measured on the
paper's simplified model, +10 % at 0.05 m and -0.02 % at 0.2215 m.

:func:`hit_recoil_length` solves ``f(L_d) = L`` for the asked ``L`` to ``|f(L_d) - L| <= tolerance``,
each ``f`` a full simulation of the designed scene at the asked accuracy.  ``f`` grows with ``L_d`` (a
longer design has a smaller R and a larger orifice at every stroke): proportional steps
``L_d <- L_d L / f(L_d)`` until the root is bracketed, then Brent's method inside the bracket
(``scipy.optimize.brentq``), stopped by the first run within tolerance; at most ``max_iterations``
simulations.

Refusals (:class:`~mbs_models.errors.SceneError`, key ``recoil_length``, nothing designed): ``L`` longer
than the recoil of the longest design the rule accepts (:func:`~mbs_models.studies.brake_design.
longest_design_length`: beyond it the other elements alone resist more than R, or the orifice would be as
large as the piston); a design whose barrel has not turned back by ``end_time`` (key ``end_time``: nothing in
the scene stops it within the window).  No convergence within ``max_iterations``:
:class:`~mbs_models.errors.SimulationError`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from scipy.optimize import brentq

from ..errors import SceneError, SimulationError
from ..scene import Scene
from .brake_design import BrakeDesign, check_recoil_length, check_scene, check_stops, design_brake, designable, \
    longest_design_length

#: The default tolerance on the recoil length: this fraction of it ...
RELATIVE_TOLERANCE = 1e-3
#: ... but at least this many m.
ABSOLUTE_TOLERANCE = 1e-4
#: The most simulations :func:`hit_recoil_length` runs by default.
MAX_ITERATIONS = 20


def default_tolerance(recoil_length: float) -> float:
    """``max(1e-3 L, 1e-4 m)`` (m): 0.1 % of the recoil length, at least 0.1 mm.

    0.1 % is ten times the worst relative error of the max barrel displacement at the ``draft`` preset
    (1e-4, :data:`~mbs_models.cli.ACCURACY_HELP`), so the residual is the design's and not the solver's
    at every preset, and finer than a recoil length is drawn to (0.3 mm at 0.3 m); the 0.1 mm floor keeps
    short strokes (0.05 m) to a machining tolerance rather than to microns."""
    return max(RELATIVE_TOLERANCE * recoil_length, ABSOLUTE_TOLERANCE)


def check_tolerance(tolerance: float, recoil_length: float) -> float:
    """The tolerance (m) if in ``(0, 0.1 L]``; SceneError naming ``tolerance`` otherwise."""
    if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) or not math.isfinite(tolerance) \
            or not 0.0 < tolerance <= 0.1 * recoil_length:
        raise SceneError("tolerance", f"must be a length in (0, {0.1 * recoil_length:g}] m (at most 10 % of the "
                                      f"recoil length), got {tolerance!r}")
    return float(tolerance)


@dataclass
class LengthDesign:
    """The brake designed for ``design_length`` L_d (m) whose simulation (``result``) recoils
    ``recoil_length`` (m) = the asked ``asked`` (m) within ``tolerance`` (m); ``iterations``: every
    simulation run, ``(L_d m, simulated recoil length m)`` in order (the last is ``design``'s)."""

    design: BrakeDesign
    result: object
    asked: float
    tolerance: float
    iterations: list[tuple[float, float]] = field(default_factory=list)

    @property
    def recoil_length(self) -> float:
        """The simulated recoil length (m): the maximum barrel displacement of :attr:`result`."""
        return self.result.max_barrel_displacement

    @property
    def design_length(self) -> float:
        """L_d (m): the length the constant-resistance table is designed for."""
        return self.design.recoil_length

    def to_dict(self) -> dict:
        return {"recoil_length_asked": self.asked, "recoil_length_achieved": self.recoil_length,
                "tolerance": self.tolerance, "design_length": self.design_length,
                "iterations": [{"design_length": d, "recoil_length": x} for d, x in self.iterations]}


class _Hit(Exception):
    """A run within tolerance: ends the iteration with its design and result."""

    def __init__(self, design, result):
        super().__init__()
        self.design, self.result = design, result


class _OutOfRuns(Exception):
    """``max_iterations`` simulations run without one within tolerance."""


def hit_recoil_length(scene: Scene, recoil_length: float, tolerance: float | None = None,
                      accuracy: str = "standard", end_time: float = 3.0, points: int = 41, fraction: float = 0.95,
                      max_iterations: int | None = None) -> LengthDesign:
    """The constant-resistance brake whose simulated recoil is ``recoil_length`` (m) within ``tolerance``
    (m, default :func:`default_tolerance`); see the module docstring.  Each iterate simulates the designed
    scene to ``end_time`` (s) at ``accuracy``, at most ``max_iterations`` of them (default :data:`MAX_ITERATIONS`)."""
    from ..engine.simulation import simulate

    check_recoil_length(recoil_length)
    check_scene(scene)
    check_stops(scene, recoil_length)
    asked = float(recoil_length)
    tolerance = check_tolerance(default_tolerance(asked) if tolerance is None else tolerance, asked)
    max_iterations = MAX_ITERATIONS if max_iterations is None else max_iterations
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, int) or max_iterations < 2:
        raise SceneError("max_iterations", f"must be a whole number >= 2, got {max_iterations!r}")
    iterations: list[tuple[float, float]] = []
    longest: list[float | None] = []  # computed once, when a step would leave the designable lengths
    design_length = asked
    if not designable(scene, asked, points, fraction):  # a shorter design recoils further: it may reach L
        design_length = _shorter_designable(scene, asked, points, fraction)
        longest.append(design_length)

    def run(design_length: float):
        design = design_brake(scene, design_length, points, fraction)
        result = simulate(design.scene, end_time, accuracy)
        if result.max_at_end_of_window:
            raise SceneError("end_time", f"the barrel has not turned back by t = {end_time:g} s (x = "
                                         f"{result.max_barrel_displacement:.4g} m, still moving out at "
                                         f"{result.barrel_velocity[-1]:.2g} m/s) with the brake designed for "
                                         f"{design_length:.6g} m: simulate longer, or add what returns it (a brake "
                                         f"alone only slows the barrel; a recoil spring or recuperator returns it)")
        iterations.append((float(design_length), result.max_barrel_displacement))
        return design, result

    runs: dict[float, tuple] = {}  # L_d -> (design, result, f - L): brentq asks again for the bracket's ends

    def residual(design_length: float) -> float:
        if design_length not in runs:
            if len(iterations) >= max_iterations:
                raise _OutOfRuns
            design, result = run(design_length)
            runs[design_length] = (design, result, result.max_barrel_displacement - asked)
            if abs(runs[design_length][2]) <= tolerance:
                raise _Hit(design, result)
        return runs[design_length][2]

    try:
        low = high = None  # L_d with f - L < 0 and > 0: the bracket once both are known
        while low is None or high is None:  # proportional steps L_d L / f until the root is bracketed
            r = residual(design_length)
            if r < 0:
                low = design_length
            else:
                high = design_length
            if low is not None and high is not None:
                break
            step = design_length * asked / (r + asked)
            if r < 0:  # longer: stay within the lengths the rule designs
                if not longest:
                    longest.append(longest_design_length(scene, design_length, points, fraction))
                limit = longest[0]
                if limit is not None and step >= limit:
                    if design_length >= limit:  # the longest design is short of L: no design reaches it
                        reason = _limit_reason(scene, limit, points, fraction)
                        raise SceneError("recoil_length", f"{asked:g} m is too long: the longest recoil a constant-"
                                                          f"resistance brake gives on this scene is "
                                                          f"{asked + r:.6g} m (designed for {limit:.6g} m; {reason})")
                    step = limit
            design_length = step
        # f is monotonic in L_d: Brent's method inside the bracket, stopped by the first run within tolerance
        brentq(residual, low, high, xtol=1e-12 * asked, maxiter=max_iterations, disp=False)
    except _Hit as hit:
        return LengthDesign(hit.design, hit.result, asked, tolerance, iterations)
    except _OutOfRuns:
        pass
    best = min(iterations, key=lambda pair: abs(pair[1] - asked))
    raise SimulationError(f"the brake design did not converge to the recoil length {asked:g} m within "
                          f"{tolerance:.3g} m in {max_iterations} simulations: the closest, designed for "
                          f"{best[0]:.6g} m, recoils {best[1]:.6g} m")


def _shorter_designable(scene: Scene, length: float, points: int, fraction: float) -> float:
    """The longest designable length (m), bisected from a designable one found by halving ``length`` (which
    is not designable; the closed form's reason if no length down to 1e-9 of it is)."""
    shorter = 0.5 * length
    while not designable(scene, shorter, points, fraction):
        shorter *= 0.5
        if shorter < 1e-9 * length:
            design_brake(scene, length, points, fraction)  # raises the closed form's reason
    return longest_design_length(scene, shorter, points, fraction)


def _limit_reason(scene: Scene, limit: float, points: int, fraction: float) -> str:
    """Why a design just longer than ``limit`` (m) is refused: the closed form's message."""
    try:
        design_brake(scene, limit * (1.0 + 1e-6), points, fraction)
    except SceneError as exc:
        reason = exc.message
        return reason.split(": ", 1)[1] if "too long: " in reason else reason
    return "the closed form's limit"
