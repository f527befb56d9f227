"""The independent reference: the scene's equations integrated with scipy, event-driven, without Exudyn.

Written from the design document's equations; it imports nothing of the engine (``mbs_models``) --
``tests/validation/reference/test_independence.py`` checks what it imports against an allow-list.
SI units throughout (m, s, kg, N, J).

* :func:`solve_reference` -- event-driven ``solve_ivp`` solution -> :class:`ReferenceResult`;
* :func:`simplified_max_displacement`, :func:`hunt_crossley_restitution` -- closed-form oracles.
"""

from .closed_form import hunt_crossley_restitution, simplified_max_displacement
from .result import ReferenceImpact, ReferenceResult, ReferenceSegment
from .solver import METHODS, ReferenceSolveError, solve_reference

__all__ = [
    "solve_reference", "ReferenceResult", "ReferenceImpact", "ReferenceSegment", "ReferenceSolveError",
    "METHODS", "simplified_max_displacement", "hunt_crossley_restitution",
]
