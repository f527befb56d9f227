"""Validation of the engine: an independent reference implementation, and the studies that use it.

* :mod:`validation.reference` -- the scene's equations integrated with scipy, event-driven; imports
  nothing of the engine (checked by a test);
* :mod:`validation.studies` -- what uses both the engine and the reference: comparisons, the guarantee
  tolerances, the replication report, the convention study, the contact-law calibration, the
  work-precision study, and the paper's published numbers.

Importing this package loads neither Exudyn nor the engine.
"""

from .reference import (METHODS, AbsorberMetrics, ContactMetrics, ReferenceImpact, ReferenceModelError, ReferenceResult,
                        ReferenceSegment, ReferenceSolveError, StopMetrics, achieved_restitution,
                        exact_restitution_factor, hunt_crossley_restitution, kelvin_voigt_restitution,
                        restitution_factor, simplified_max_displacement, solve_reference)
from .studies.paper import PublishedValue, QualitativeClaim, published_values, qualitative_claims, table2

__all__ = [
    "solve_reference", "ReferenceResult", "ReferenceImpact", "ReferenceSegment", "ReferenceSolveError",
    "ReferenceModelError", "ContactMetrics", "StopMetrics", "AbsorberMetrics", "METHODS",
    "simplified_max_displacement", "hunt_crossley_restitution", "restitution_factor", "exact_restitution_factor",
    "achieved_restitution", "kelvin_voigt_restitution",
    "PublishedValue", "QualitativeClaim", "published_values", "qualitative_claims", "table2",
]
