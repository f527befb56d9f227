"""Solver settings: the accuracy presets and explicit settings for experts.

``simulate(scene, accuracy="standard")`` picks one of :data:`ACCURACY_PRESETS`; experts pass a
:class:`SolverSettings` instead (any Exudyn dynamic solver, a fixed step or tolerances).

Contract of the settings
------------------------
* Adaptive solvers (``DOPRI5``, ``ODE23``): ``relative_tolerance`` and ``absolute_tolerance`` control
  the local error; ``max_step`` (s) bounds the step so that the time histories stay resolved.
* Fixed-step solvers (``RK44``, ``RK67``, ``RK33``, ``ExplicitEuler``, ``ExplicitMidpoint``,
  ``VelocityVerlet``, ``GeneralizedAlpha``, ``TrapezoidalIndex2``): ``step`` (s) is the step size.
* ``user_functions`` is ``"symbolic"`` (C++ evaluation, default) or ``"python"`` (debuggable).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..errors import SceneError

#: Exudyn solvers with automatic step-size control.
ADAPTIVE_SOLVERS = ("DOPRI5", "ODE23")
#: Exudyn solvers with a fixed step.
FIXED_STEP_SOLVERS = ("RK44", "RK67", "RK33", "ExplicitEuler", "ExplicitMidpoint", "VelocityVerlet",
                      "GeneralizedAlpha", "TrapezoidalIndex2")
#: Implicit solvers among them (Newton iterations each step).
IMPLICIT_SOLVERS = ("GeneralizedAlpha", "TrapezoidalIndex2")
SOLVERS = ADAPTIVE_SOLVERS + FIXED_STEP_SOLVERS
#: Tightest tolerances accepted: double precision cannot meet tighter ones and the solver stalls.
MIN_RELATIVE_TOLERANCE = 1e-13
MIN_ABSOLUTE_TOLERANCE = 1e-20
USER_FUNCTION_BACKENDS = ("symbolic", "python")


@dataclass(frozen=True)
class SolverSettings:
    """How to integrate a scene with Exudyn.

    Attributes
    ----------
    solver: Exudyn dynamic solver name, one of :data:`SOLVERS`.
    relative_tolerance, absolute_tolerance: adaptive solvers only (dimensionless, m or m/s).
    max_step: adaptive solvers: the largest step in s.
    step: fixed-step solvers: the step in s.
    user_functions: ``"symbolic"`` or ``"python"``.
    """

    solver: str = "DOPRI5"
    relative_tolerance: float | None = 1e-8
    absolute_tolerance: float | None = 1e-10
    max_step: float | None = 5e-3
    step: float | None = None
    user_functions: str = "symbolic"

    def __post_init__(self):
        if self.solver not in SOLVERS:
            raise SceneError("solver", f"unknown Exudyn solver {self.solver!r}; allowed: {', '.join(SOLVERS)}")
        if self.user_functions not in USER_FUNCTION_BACKENDS:
            raise SceneError("user_functions", f"must be one of {', '.join(USER_FUNCTION_BACKENDS)}, "
                                               f"got {self.user_functions!r}")
        if self.adaptive:
            # below these Exudyn's DOPRI5 stalls at round-off (measured: rtol 1e-14 or atol 1e-60 never end)
            _positive("relative_tolerance", self.relative_tolerance, upper=1.0, lower=MIN_RELATIVE_TOLERANCE)
            _positive("absolute_tolerance", self.absolute_tolerance, upper=1.0, lower=MIN_ABSOLUTE_TOLERANCE)
            _positive("max_step", self.max_step, upper=10.0)
        else:
            _positive("step", self.step, upper=1.0)

    @property
    def adaptive(self) -> bool:
        """True for solvers with automatic step-size control."""
        return self.solver in ADAPTIVE_SOLVERS

    @property
    def implicit(self) -> bool:
        """True for the implicit (Newton-iterating) solvers."""
        return self.solver in IMPLICIT_SOLVERS

    def label(self) -> str:
        """Short human-readable description, e.g. ``DOPRI5 rtol=1e-08``."""
        if self.adaptive:
            return f"{self.solver} rtol={self.relative_tolerance:g} ({self.user_functions})"
        return f"{self.solver} h={self.step:g} s ({self.user_functions})"


def _positive(key: str, value, upper: float, lower: float = 0.0) -> None:
    interval = f"[{lower:g}, {upper:g}]" if lower > 0 else f"(0, {upper:g}]"
    if value is None or isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SceneError(key, f"must be a number in {interval}, got {value!r}")
    if not math.isfinite(value) or value <= 0 or value < lower or value > upper:
        raise SceneError(key, f"must be in {interval}, got {value!r}")


#: Accuracy presets, chosen by the work-precision study (``recoil precision --presets``,
#: :mod:`validation.studies.precision`).  All use adaptive DOPRI5 with symbolic user functions: on these
#: models it reaches any error level cheaper than ODE23, the fixed-step and the implicit solvers, and
#: scipy (see the performance pages).  Worst relative error on the 19 paper cases (max barrel displacement / peak
#: contact force / max absorber velocity), measured -> stated (tests/test_presets.py), and the median
#: time of a 10-s run relative to ``draft``:
#:
#: * ``draft``:     1.8e-5 / 1.0e-4 / 6.5e-5 -> 1e-4 / 1e-3 / 1e-3; 1x (plots, exploration);
#: * ``standard``:  1.8e-8 / 8.4e-8 / 4.8e-7 -> 1e-7 / 1e-6 / 1e-5; ~1.4x (the former rtol 1e-8 cost
#:   the same and gave 20x larger force errors: the run time is dominated by post-processing);
#: * ``reference``: 3.5e-11 / 2.0e-9 / 1.3e-8 -> 1e-9 / 1e-8 / 1e-7; ~1.8x (the former max step 1 ms
#:   cost 2.1x more for no gain: the tolerance, not the max step, limits the error).
ACCURACY_PRESETS: dict[str, SolverSettings] = {
    "draft": SolverSettings(relative_tolerance=1e-6, absolute_tolerance=1e-8, max_step=1e-2),
    "standard": SolverSettings(relative_tolerance=1e-9, absolute_tolerance=1e-11, max_step=5e-3),
    "reference": SolverSettings(relative_tolerance=1e-11, absolute_tolerance=1e-13, max_step=5e-3),
}


def solver_settings_for(accuracy: str | SolverSettings = "standard", user_functions: str | None = None
                        ) -> SolverSettings:
    """Resolve a preset name (or pass through explicit settings), optionally overriding the backend."""
    if isinstance(accuracy, SolverSettings):
        settings = accuracy
    elif isinstance(accuracy, str) and accuracy in ACCURACY_PRESETS:
        settings = ACCURACY_PRESETS[accuracy]
    else:
        raise SceneError("accuracy", f"unknown accuracy {accuracy!r}; allowed: {', '.join(ACCURACY_PRESETS)} "
                                     "or a SolverSettings")
    if user_functions is not None:
        settings = replace(settings, user_functions=user_functions)
    return settings
