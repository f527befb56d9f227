"""mbs_models.engine.final_metrics: the former module of the early stop, kept importable for users.

Every name it had is still there, and is the same object as in its new home (energy_bounds or finality), so
that code importing from either place shares one class, one constant.
"""

from __future__ import annotations

import pytest

from mbs_models.engine import energy_bounds, final_metrics, finality

FORMER_NAMES = {
    energy_bounds: ("ENERGY_SLACK", "EnergyBounds", "PotentialWell", "connector_ends", "dissipative",
                    "general_potentials", "largest_energy_rise", "mechanical_energy", "_QuadraticForm"),
    finality: ("FINAL_METRICS", "FinalityTracker", "STOP_AT_REST", "STOP_END_TIME", "STOP_ENERGY_CHECK",
               "STOP_METRICS_FINAL", "STOP_NO_BOUND", "check_metric_names"),
}


@pytest.mark.parametrize("module,name", [(m, n) for m, names in FORMER_NAMES.items() for n in names])
def test_every_former_name_is_reexported_from_its_new_module(module, name):
    assert getattr(final_metrics, name) is getattr(module, name)


def test_the_package_exports_come_from_the_new_modules():
    import mbs_models

    assert mbs_models.EnergyBounds is energy_bounds.EnergyBounds
    assert mbs_models.FINAL_METRICS is finality.FINAL_METRICS
