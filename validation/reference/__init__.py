"""The independent reference: the scene's equations integrated with scipy, event-driven, without Exudyn.

Written from the design document's equations (DESIGN.md); it imports nothing of the engine
(``mbs_models``) and reads the scene as data -- ``tests/validation/reference/test_independence.py``
checks what it imports against an allow-list.  SI units throughout (m, s, kg, N, J).

* :func:`solve_reference` -- event-driven ``solve_ivp`` solution -> :class:`ReferenceResult`;
* :mod:`.terms` -- one module per physical effect (bodies, forces, energies, switching surfaces, bounds);
  :mod:`.model`, :mod:`.assembly`, :mod:`.switching`, :mod:`.solver`, :mod:`.result` and
  :mod:`.finality` (the early stop) run them without naming any effect;
* external inputs (:mod:`.model`): a :class:`~.model.Load` ``L(t)`` on one body (``builder.add_load``:
  :class:`~.model.ConstantLoad`, :class:`~.model.PiecewiseLinearLoad` -- the breech force of ``[firing.pulse]``)
  and :class:`~.model.Impulse` velocity jumps (the later shots of a ``[burst]``); their breakpoints and
  times split the solve, their work is in the energy balance (``ReferenceResult.work_history``); the
  result's ``shots`` gives the per-shot outputs, ``pulse_impulse`` the pulse's impulse;
* :mod:`.planar` -- the gun on its carriage (a scene with ``[carriage]``): the same axis model moved by a carriage
  on its supports (Lagrange's equations by hand); :func:`solve_reference` dispatches to it and returns a
  :class:`~.planar.PlanarResult` (the carriage's histories and metrics besides the axis');
* :mod:`.closed_form` -- oracles: :func:`simplified_max_displacement`, :func:`hunt_crossley_restitution`,
  :func:`restitution_factor`, :func:`exact_restitution_factor`, :func:`achieved_restitution`,
  :func:`kelvin_voigt_restitution`.
"""

from .closed_form import (achieved_restitution, exact_restitution_factor, hunt_crossley_restitution,
                          kelvin_voigt_restitution, restitution_factor, simplified_max_displacement)
from .model import ReferenceModelError
from .result import (AbsorberMetrics, ContactMetrics, ReferenceImpact, ReferenceResult, ReferenceSegment,
                     StopMetrics)
from .solver import METHODS, ReferenceSolveError, solve_reference

__all__ = [
    "solve_reference", "ReferenceResult", "ReferenceImpact", "ReferenceSegment", "ReferenceSolveError",
    "ReferenceModelError", "ContactMetrics", "StopMetrics", "AbsorberMetrics", "METHODS",
    "simplified_max_displacement", "hunt_crossley_restitution", "restitution_factor", "exact_restitution_factor",
    "achieved_restitution", "kelvin_voigt_restitution",
]
