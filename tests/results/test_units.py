"""Plain-text SI units of metrics and scene keys (mbs_models/results/units.py): the units a user types, no
plot markup, every metric and every numeric field of every shipped scene covered."""

from __future__ import annotations

import pytest

from mbs_models.results.units import metric_si_unit, parameter_si_unit
from mbs_models.scene import load_scene
from mbs_models.scenes import list_scenes, scene_path


@pytest.mark.parametrize("column, unit", [
    ("max_barrel_displacement", "m"), ("time_of_max_barrel_displacement", "s"), ("peak_support_force", "N"),
    ("absorber.1.peak_contact_force", "N"), ("max_absorber_velocity", "m/s"), ("absorber.0.impacts", "count"),
    ("stop_1.dissipated_energy", "J"), ("time_of_peak_contact_force", "s"),
])
def test_metric_units_are_si(column, unit):
    assert metric_si_unit(column) == unit


@pytest.mark.parametrize("key, unit", [
    ("contact.gap", "m"), ("absorber.1.contact.gap", "m"), ("absorber.mass", "kg"), ("barrel.mass", "kg"),
    ("recoil_spring.stiffness", "N/m"), ("absorber.0.contact.stiffness", "N/m^exponent"),
    ("recoil_damper.recoil", "N s/m"), ("recoil_brake.orifice_area", "m^2"), ("recoil_brake.piston_area", "m^2"),
    ("recoil_brake.fluid_density", "kg/m^3"), ("recuperator.initial_pressure", "Pa"),
    ("recuperator.gas_volume", "m^3"), ("contact.restitution", "-"), ("firing.muzzle_velocity", "m/s"),
    ("burst.interval", "s"),
])
def test_parameter_units_are_the_scene_files(key, unit):
    assert parameter_si_unit(key) == unit


def test_every_metric_and_numeric_field_of_the_shipped_scenes_has_a_plain_unit():
    from mbs_models.studies.optimise import optimisable_metrics

    for name in list_scenes():
        scene = load_scene(scene_path(name))
        for metric in optimisable_metrics(scene):
            unit = metric_si_unit(metric)
            assert unit != "SI" and "$" not in unit, (name, metric)
        for key, table in scene.tables():
            for field, value in table.to_mapping().items():
                if isinstance(value, (int, float)) and not isinstance(value, bool):
                    unit = parameter_si_unit(f"{key}.{field}")
                    assert unit != "SI" and "$" not in unit, (name, key, field)
