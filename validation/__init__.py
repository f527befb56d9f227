"""Independent scipy implementation of the paper's Eqs. (1)-(8), closed-form oracles and published values.

Nothing here imports Exudyn or the engine modules of :mod:`mbs_models`; only the scene description
(:mod:`mbs_models.scene`, :mod:`mbs_models.models`) is shared, so the two implementations can be compared
point by point.  SI units throughout (m, s, kg, N, J).

* :func:`solve_reference` -- event-driven ``solve_ivp`` solution -> :class:`ReferenceResult`;
* :func:`simplified_max_displacement`, :func:`hunt_crossley_restitution` -- closed-form oracles;
* :func:`table2`, :func:`published_values`, :func:`qualitative_claims` -- what the paper publishes.
"""

from .closed_form import hunt_crossley_restitution, simplified_max_displacement
from .paper import PublishedValue, QualitativeClaim, published_values, qualitative_claims, table2
from .reference import METHODS, ReferenceSolveError, solve_reference
from .result import ReferenceImpact, ReferenceResult, ReferenceSegment

__all__ = [
    "solve_reference", "ReferenceResult", "ReferenceImpact", "ReferenceSegment", "ReferenceSolveError",
    "METHODS", "simplified_max_displacement", "hunt_crossley_restitution",
    "PublishedValue", "QualitativeClaim", "published_values", "qualitative_claims", "table2",
]
