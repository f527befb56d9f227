"""End stops (mbs_models.elements.end_stops): the barrel against the ground, any contact law."""

from __future__ import annotations

import numpy as np
import pytest

from mbs_models import BatteryStop, RecoilStop, load_scene, model_ii, simplified_model, simulate
from mbs_models.elements.contact_laws import CONTACT_LAWS
from mbs_models.engine.assembly import assemble
from mbs_models.scenes import scene_path

LAW_FIELDS = {"hunt-crossley": dict(stiffness=1e9, exponent=1.5, damping_factor=0.5),
              "hertz": dict(stiffness=1e9, exponent=1.5), "kelvin-voigt": dict(stiffness=5e7, damping=2e5)}


def law_fields(law: str) -> dict:
    return LAW_FIELDS.get(law, dict(stiffness=1e9, exponent=1.5, restitution=0.5))


def with_stops(scene, law: str, position=0.12):
    return scene.with_changes(recoil_stop=RecoilStop(position=position, law=law, **law_fields(law)),
                              battery_stop=BatteryStop(position=0.0, law=law, **law_fields(law)))


@pytest.mark.parametrize("law", sorted(CONTACT_LAWS))
def test_stops_of_every_law_stop_the_barrel_and_balance_energy(law):
    result = simulate(with_stops(model_ii(1000.0, 0.0), law), 5.0)
    stop = result.contacts["recoil_stop"]
    assert stop.impacts and stop.peak_force > 1e4
    # the stroke ends at the stop (plus its penetration: (F/k)^(1/n) at the peak force)
    penetration = (stop.peak_force / law_fields(law)["stiffness"]) ** (1 / law_fields(law).get("exponent", 1.0))
    assert 0.12 < result.max_barrel_displacement <= 0.12 + 1.01 * penetration
    assert np.all(result.contacts["battery_stop"].force >= 0.0) and np.all(stop.force >= 0.0)
    assert np.max(np.abs(result.energy_error())) < 5e-6 * result.kinetic_energy_history[0]
    assert {"recoil_stop", "battery_stop"} <= set(result.dissipated_energy) or law == "hertz"


def test_the_stops_push_the_mount_in_opposite_directions():
    """Recoil stop (ground -> barrel): +F on the mount; battery stop (barrel -> ground): -F.  The support
    force is minus the rate of momentum at every sample."""
    result = simulate(load_scene(scene_path("end_stops")), 3.0)
    accelerations = 5600.0 * result.accelerations["barrel"] + 1000.0 * result.accelerations["absorber"]
    np.testing.assert_allclose(result.support_force, -accelerations, rtol=0, atol=1e-9 * np.max(np.abs(accelerations)))
    recoil = result.contacts["recoil_stop"]
    i = int(np.argmax(recoil.force))
    assert result.support_force[i] > 0.9 * recoil.force[i]  # the stop dominates the mount's load there
    battery = result.contacts["battery_stop"]
    j = int(np.argmax(battery.force))
    assert result.support_force[j] < -0.5 * battery.force[j]
    stops = {s["name"]: s for s in result.metrics()["stops"]}
    assert stops["recoil_stop"]["peak_contact_force"] == recoil.peak_force and stops["battery_stop"]["impacts"]


@pytest.mark.parametrize("law", ["hunt-crossley", "kelvin-voigt", "exact-restitution"])
def test_stops_hit_at_ten_times_the_firing_velocity(law):
    """A hard case: the barrel hits the recoil stop at ~7 m/s (muzzle velocity 5640 m/s)."""
    scene = with_stops(simplified_model(), law, 0.1).with_changes(**{"firing.muzzle_velocity": 5640.0})
    for accuracy in ("draft", "standard"):
        result = simulate(scene, 2.0, accuracy)
        assert np.all(np.isfinite(result.support_force))
        assert result.contacts["recoil_stop"].peak_force > 1e5
        assert np.max(np.abs(result.energy_error())) < (1e-3 if accuracy == "draft" else 5e-6) * \
            result.kinetic_energy_history[0]


def test_a_scene_without_stops_adds_no_stop_item():
    with assemble(model_ii()) as assembly:
        assert not {"recoil_stop", "battery_stop"} & set(assembly.connectors)
    with assemble(load_scene(scene_path("end_stops"))) as assembly:
        assert {"recoil_stop", "battery_stop"} <= set(assembly.connectors)
        assert {"recoil_stop_force", "battery_stop_force"} <= set(assembly.sensors)


BAD_STOPS = [
    ("missing-position", "recoil_stop.position", "<delete>", "recoil_stop.position", "missing"),
    ("recoil-stop-behind-the-start", "recoil_stop.position", 0.0, "recoil_stop.position", "> 0 m"),
    ("battery-stop-ahead-of-the-start", "battery_stop.position", 0.01, "battery_stop.position", "<= 0 m"),
    ("position-string", "battery_stop.position", "zero", "battery_stop.position", "must be a number"),
    ("missing-stiffness", "recoil_stop.stiffness", "<delete>", "recoil_stop.stiffness", "missing"),
    ("unknown-law", "battery_stop.law", "kelvin", "battery_stop.law", "did you mean 'kelvin-voigt'"),
    ("missing-damping", "battery_stop.damping", "<delete>", "battery_stop.damping", "missing"),
    ("unknown-key", "recoil_stop.positon", 0.2, "recoil_stop.positon", "did you mean 'position'"),
    ("not-a-table", "recoil_stop", 0.3, "recoil_stop", "must be a table"),
]


STOP_TABLES = {"recoil_stop": {"position": 0.3, "law": "hunt-crossley", "stiffness": 1.0e9, "exponent": 1.5,
                               "damping_factor": 0.5},
               "battery_stop": {"position": 0.0, "law": "kelvin-voigt", "stiffness": 5.0e7, "damping": 2.0e5}}


@pytest.mark.parametrize("path, value, key, text", [c[1:] for c in BAD_STOPS], ids=[c[0] for c in BAD_STOPS])
def test_bad_stop_tables_are_one_line_errors_naming_the_key(bad_input, v2_mapping, changed, path, value, key, text):
    bad_input(changed({**v2_mapping, **STOP_TABLES}, path, value), key, text)


def test_stops_need_a_version_2_scene(bad_input, v1_mapping):
    bad_input(dict(v1_mapping, recoil_stop=STOP_TABLES["recoil_stop"]), "recoil_stop", "version-2 scene")
