"""Implausible magnitudes (mbs_models/scene/plausibility.py): each unit slip is found and names its key; real
guns (the public data of DESIGN.md "Unit slips"), the shipped scenes and the paper's models give none.

Expected values are hand calculations: v = I / M; a piecewise-linear pulse's impulse is the trapezoid sum.
"""

from __future__ import annotations

import pytest

from mbs_models import Barrel, Firing, Scene, load_scene, model_i, model_ii, simplified_model
from mbs_models.elements.firing import Pulse
from mbs_models.scene.plausibility import implausible_magnitudes
from mbs_models.scenes import list_scenes, scene_path

MOMENTUM = 6.86 * 564.0  # kg m/s, the paper's shot
TIMES, FORCES = (0.0, 0.002, 0.006, 0.012), (0.0, 2.0e6, 6.0e5, 0.0)  # s, N: DESIGN.md's example pulse
IMPULSE = 0.5 * 2.0e6 * 0.002 + 0.5 * 2.6e6 * 0.004 + 0.5 * 6.0e5 * 0.006  # N s (9000)
WEIGHT = 5600.0 * 9.80665  # N, the paper's barrel


def keys(scene: Scene) -> list[str]:
    return [finding.key for finding in implausible_magnitudes(scene)]


def pulse_scene(times=TIMES, forces=FORCES, *, projectile=True, scale=False, mass=5600.0) -> Scene:
    shot = dict(projectile_mass=6.86, muzzle_velocity=564.0) if projectile else {}
    firing = Firing(**shot, pulse=Pulse(times=tuple(times), forces=tuple(forces), scale_to_momentum=scale))
    return Scene(barrel=Barrel(mass), firing=firing, name="pulse")


def test_a_barrel_mass_in_tonnes_names_the_mass_and_the_recoil_velocity():
    [finding] = implausible_magnitudes(model_ii().with_changes(**{"barrel.mass": 5.6}))
    assert finding.key == "barrel.mass"
    message = finding.message()
    assert message.startswith("barrel.mass = 5.6 kg gives a recoil velocity of ")
    velocity = float(message.split("recoil velocity of ")[1].split()[0])
    assert velocity == pytest.approx(MOMENTUM / 5.6, rel=1e-3)  # 690.9 m/s
    assert "30 m/s" in message and message.endswith("a mass in tonnes?")


def test_the_recoil_velocity_threshold_is_30_m_s():
    limit_mass = MOMENTUM / 30.0  # kg: v = 30 m/s
    assert keys(simplified_model().with_changes(**{"barrel.mass": 0.99 * limit_mass})) == ["barrel.mass"]
    assert keys(simplified_model().with_changes(**{"barrel.mass": 1.01 * limit_mass})) == []


@pytest.mark.parametrize("velocity, warned", [(0.69, False), (-25.0, False), (690.0, True), (-690.0, True)])
def test_an_initial_velocity_in_mm_per_s_names_the_velocity(velocity, warned):
    scene = Scene(barrel=Barrel(5600.0, initial_velocity=velocity), name="given v0")
    assert keys(scene) == (["barrel.initial_velocity"] if warned else [])


def test_the_velocity_of_a_pulse_is_its_impulse_over_the_mass():
    # a pulse without a projectile: v = impulse / M = 9000 / 200 = 45 m/s
    assert keys(pulse_scene(projectile=False, mass=200.0)) == ["barrel.mass"]
    assert keys(pulse_scene(projectile=False, mass=400.0)) == []  # 22.5 m/s


def test_a_pulse_in_milliseconds_names_its_times_and_its_impulse():
    findings = implausible_magnitudes(pulse_scene(times=[1000.0 * t for t in TIMES]))
    assert [f.key for f in findings] == ["firing.pulse.times", "firing.pulse.forces"]
    assert findings[0].message().startswith("firing.pulse.times span 12 s,") and "0.1 s" in findings[0].message()
    ratio = 1000.0 * IMPULSE / MOMENTUM  # 2326
    assert f"{ratio:.3g} times the shot's momentum" in findings[1].message()
    assert findings[1].message().endswith("times in ms?")


def test_a_pulse_in_kilonewtons_names_its_forces_twice():
    findings = implausible_magnitudes(pulse_scene(forces=[f / 1000.0 for f in FORCES]))
    assert [f.key for f in findings] == ["firing.pulse.forces", "firing.pulse.forces"]
    impulse, peak = findings[0].message(), findings[1].message()
    assert f"impulse of {IMPULSE / 1000.0:.4g} N s" in impulse and impulse.endswith("forces in kN, kgf or lbf?")
    assert peak.startswith("firing.pulse.forces peak at 2000 N, below the barrel's weight of ")
    assert float(peak.split("weight of ")[1].split()[0]) == pytest.approx(WEIGHT, rel=1e-4)


def test_a_pulse_in_milliseconds_and_kilonewtons_keeps_its_impulse_but_not_its_duration_or_peak():
    scene = pulse_scene(times=[1000.0 * t for t in TIMES], forces=[f / 1000.0 for f in FORCES])
    assert scene.firing.pulse.impulse == pytest.approx(IMPULSE)
    assert keys(scene) == ["firing.pulse.times", "firing.pulse.forces"]


def test_a_pulse_scaled_to_the_momentum_is_judged_as_applied():
    # in kN but scaled: the applied peak is 2e6 N x momentum / impulse, far above the weight
    assert keys(pulse_scene(forces=[f / 1000.0 for f in FORCES], scale=True)) == []
    assert keys(pulse_scene(scale=True)) == keys(pulse_scene()) == []


@pytest.mark.parametrize("factor, warned", [(0.34, False), (2.9, False), (0.32, True), (3.1, True),
                                            (1.0 / 9.80665, True), (1.0 / 4.448222, True)])
def test_the_impulse_may_differ_from_the_momentum_by_a_factor_of_3(factor, warned):
    forces = [f * factor * MOMENTUM / IMPULSE for f in FORCES]  # impulse = factor x momentum
    assert keys(pulse_scene(forces=forces)) == (["firing.pulse.forces"] if warned else [])


def test_a_pulse_from_a_file_names_the_file(tmp_path):
    path = tmp_path / "breech.csv"
    path.write_text("time_ms,force_kN\n" + "".join(f"{1000 * t},{f / 1000}\n" for t, f in zip(TIMES, FORCES)))
    firing = Firing(projectile_mass=6.86, muzzle_velocity=564.0, pulse=Pulse(file=str(path)))
    findings = implausible_magnitudes(Scene(barrel=Barrel(5600.0), firing=firing, name="file"))
    assert [f.key for f in findings] == ["firing.pulse.file", "firing.pulse.file"]
    assert findings[0].message().startswith(f"firing.pulse.file = {str(path)!r}: its times span 12 s")


@pytest.mark.parametrize("name, projectile_mass, muzzle_velocity, charge_mass, gas_velocity, recoiling_mass", [
    # recoil-data.md 1.2: M109 redesign data furnished by ARRADCOM (gas at SAAMI's 1.75 x muzzle velocity)
    ("155 mm M109", 44.45, 990.6, 18.14, 1.75 * 990.6, 4354.5),
    # 1.3: 75 mm M1897, 12 lb shell at about 1750 ft/s, gun about 460 kg (derived)
    ("75 mm M1897", 12 * 0.45359237, 1750 * 0.3048, 0.0, None, 460.0),
    # the paper (Table 1)
    ("paper", 6.86, 564.0, 0.0, None, 5600.0),
])
def test_real_guns_are_plausible(name, projectile_mass, muzzle_velocity, charge_mass, gas_velocity, recoiling_mass):
    firing = Firing(projectile_mass=projectile_mass, muzzle_velocity=muzzle_velocity, charge_mass=charge_mass,
                    gas_velocity=gas_velocity)
    assert keys(Scene(barrel=Barrel(recoiling_mass), firing=firing, name=name)) == []


def test_a_real_breech_force_is_plausible():
    # recoil-data.md 1.6: D-20, 252.8 MPa on 0.01875 m^2 (4.74 MN), 43.56 kg at 655 m/s; a 12 ms pulse of that
    # peak scaled to the momentum, on a recoiling mass of 2000 kg (assumed: v = 14 m/s)
    peak = 252.8e6 * 0.01875
    firing = Firing(projectile_mass=43.56, muzzle_velocity=655.0,
                    pulse=Pulse(times=(0.0, 0.002, 0.012), forces=(0.0, peak, 0.0), scale_to_momentum=True))
    assert keys(Scene(barrel=Barrel(2000.0), firing=firing, name="D-20")) == []


def test_the_shipped_scenes_and_the_papers_models_are_plausible():
    for name in list_scenes():
        assert implausible_magnitudes(load_scene(scene_path(name))) == [], name
    for mass in (100.0, 500.0, 1000.0):
        for gap in (0.0, 0.04, 0.08, 0.12):
            assert implausible_magnitudes(model_i(mass, gap)) == implausible_magnitudes(model_ii(mass, gap)) == []
    assert implausible_magnitudes(simplified_model()) == []


# ------------------------------------------------------------------ the carriage (issue #22)
@pytest.mark.parametrize("changes, key, words", [
    ({"carriage.mass": 2.0}, "carriage.mass", "tonnes"),                      # 2 t typed as 2
    ({"carriage.support.1.position": [2800.0, 0.0]}, "carriage.support", "mm"),  # 2.8 m typed in mm
    ({"carriage.support.1.stiffness": 2e3}, "carriage.support.1.stiffness", "N/mm"),  # sinks 15 m
])
def test_a_carriage_unit_slip_names_its_key(changes, key, words):
    from carriage_scenes import carriage_scene

    found = implausible_magnitudes(carriage_scene(changes))
    assert [f.key for f in found] == [key] and words in found[0].text


def test_the_shipped_carriage_scenes_are_plausible():
    from mbs_models import load_scene
    from mbs_models.scenes import scene_path

    for name in ("towed_howitzer", "towed_howitzer_45"):
        assert implausible_magnitudes(load_scene(scene_path(name))) == []
