"""Solver settings: the accuracy presets and explicit settings for experts.

``simulate(scene, accuracy="standard")`` picks one of :data:`ACCURACY_PRESETS`; experts pass a
:class:`SolverSettings` instead (any Exudyn dynamic solver, a fixed step or tolerances).

Contract of the settings
------------------------
* Adaptive solvers (``DOPRI5``, ``ODE23``): ``relative_tolerance`` and ``absolute_tolerance`` control
  the local error; ``max_step`` (s) bounds the step.

The maximum step of a preset
----------------------------
Nothing of a result needs small steps where the motion is slow: the metrics are refined on the cubic
Hermite interpolant of the step-end samples (peaks, impact starts and ends, the support force's peak,
:mod:`mbs_models.results.peaks`), the energies are integrated on it (:mod:`mbs_models.results.energies`),
stepped-over contacts are searched on it (:mod:`mbs_models.engine.stability`), loads limit the step inside
their own windows (:data:`~mbs_models.engine.driver.STEPS_PER_LOAD_WINDOW`), and the early stop and the rest
watch prove their bounds from any state.  What the maximum step still decides is (a) how well the samples'
interpolant follows the histories between samples; (b) how far below the tolerance the position error
stays where the solver would take long steps -- which matters for a contact only grazed, whose peak force
``k p^n`` magnifies the position error by ``n / p``: such a run is re-solved with a maximum step of
:data:`~mbs_models.engine.stability.GRAZING_MAX_STEP` (:func:`~mbs_models.engine.stability.grazed_contacts`);
(c) whether the explicit solver stays stable where the motion is below the absolute tolerance but stiff (a
body resting on a contact): there the error estimate cannot see an unstable step, and a noise at the
tolerance's level can keep the proof of rest (:mod:`mbs_models.engine.rest`) from ever succeeding; (d) how
wild a trial step from a slow phase into a stiff one is (a run that diverges is re-solved with a quarter of
the maximum step, :mod:`mbs_models.engine.driver`).

Rule: each preset's ``max_step`` is the largest of 5 ms x 2^k at which (1) every preset metric of the 19 paper
cases meets the preset's stated bound (:data:`validation.studies.precision.PRESET_ERROR_BOUNDS`) with the same
impacts as the reference, (2) the barrel trajectory's interpolant (Hermite, on the 1 ms grid of the study)
stays within half the stated displacement bound (relative L2 error against the reference), and (3) every hard
case meets :data:`validation.studies.guarantee.TOLERANCES` (``tests/test_hard_cases.py``), and (4) every shipped
scene that proves rest within 200 s at 5 ms still does.  The measurements
that chose them are in DESIGN.md ("The maximum step").
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
#: contact force / max absorber velocity), measured -> stated (tests/test_presets.py):
#:
#: * ``draft``:     9.7e-6 / 1.4e-4 / 5.6e-5 -> 1e-4 / 1e-3 / 1e-3 (plots, exploration; max step 20 ms);
#: * ``standard``:  1.5e-8 / 4.9e-8 / 6.0e-7 -> 1e-7 / 1e-6 / 1e-5 (max step 20 ms; the former rtol 1e-8
#:   cost the same and gave 20x larger force errors);
#: * ``reference``: 3.5e-11 / 2.0e-9 / 1.3e-8 -> 1e-9 / 1e-8 / 1e-7 (max step 5 ms: at 10 ms the barrel
#:   trajectory's interpolant is off by more than half the displacement bound; the former max step 1 ms
#:   cost 2.1x more for no gain).
#:
#: The maximum steps follow the rule of the module docstring (DESIGN.md, "The maximum step").
ACCURACY_PRESETS: dict[str, SolverSettings] = {
    "draft": SolverSettings(relative_tolerance=1e-6, absolute_tolerance=1e-8, max_step=2e-2),
    "standard": SolverSettings(relative_tolerance=1e-9, absolute_tolerance=1e-11, max_step=2e-2),
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
