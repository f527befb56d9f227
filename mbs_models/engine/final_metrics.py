"""When is a metric final?  The energy bounds and the early stop's tracker, under their former name.

Kept so that ``from mbs_models.engine.final_metrics import ...`` works as before: the energy bounds (the
equations, :class:`EnergyBounds`, :class:`PotentialWell`, :data:`ENERGY_SLACK`) are in
:mod:`mbs_models.engine.energy_bounds`, the finality of the metrics (:class:`FinalityTracker`, the stop reasons,
:func:`check_metric_names`) in :mod:`mbs_models.engine.finality`.
"""

from __future__ import annotations

from .energy_bounds import (ENERGY_SLACK, EnergyBounds, PotentialWell, _QuadraticForm, connector_ends, dissipative,
                            general_potentials, largest_energy_rise, mechanical_energy)
from .finality import (FINAL_METRICS, STOP_AT_REST, STOP_END_TIME, STOP_ENERGY_CHECK, STOP_METRICS_FINAL,
                       STOP_NO_BOUND, FinalityTracker, check_metric_names)

__all__ = ["ENERGY_SLACK", "EnergyBounds", "FINAL_METRICS", "FinalityTracker", "PotentialWell", "STOP_AT_REST",
           "STOP_END_TIME", "STOP_ENERGY_CHECK", "STOP_METRICS_FINAL", "STOP_NO_BOUND", "check_metric_names",
           "connector_ends", "dissipative", "general_potentials", "largest_energy_rise", "mechanical_energy"]
