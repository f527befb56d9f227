"""The stability chart (mbs_models/studies/stability_chart.py, ``recoil stability``): the closed form by hand, the
simulated points against it where the carriage rests, the command's outputs."""

from __future__ import annotations

import json
import math

import pytest

from mbs_models import load_scene
from mbs_models.cli import main
from mbs_models.scenes import scene_path
from mbs_models.studies.stability_chart import closed_form, stability_chart

from carriage_scenes import carriage_scene

G = 9.81


def test_the_closed_form_by_hand_on_the_towed_howitzer():
    """Spade at the origin, wheels at 5.2 m; 4400 kg at x = 3.6 and the 5600 kg barrel at the trunnion (5.0, 1.6):
    m_tot d = 4400 * 3.6 + 5600 * 5.0; h(0) = 1.6 m; E = I^2 / (2 M) with I = 7369 N s (the scene's shot)."""
    scene = load_scene(scene_path("towed_howitzer"))
    point = closed_form(scene, 0.0, margin=0.8)
    moment = 4400 * 3.6 + 5600 * 5.0
    assert point.arm == pytest.approx(1.6)
    assert point.limit_in_battery == pytest.approx(G * moment / 1.6, rel=1e-12)
    energy = scene.firing.shot_momentum ** 2 / (2 * 5600.0)
    a, b, c = 0.8 * G * 5600.0, -0.8 * G * moment, energy * 1.6
    shortest = (-b - math.sqrt(b * b - 4 * a * c)) / (2 * a)
    assert point.shortest_stable_recoil == pytest.approx(shortest, rel=1e-12)
    assert point.resistance_at_shortest == pytest.approx(energy / shortest, rel=1e-12)
    # above atan(1.6 / 5.0) the pull presses the wheels down: no limit
    steep = closed_form(scene, 45.0)
    assert steep.arm < 0 and math.isinf(steep.limit_in_battery) and math.isinf(steep.shortest_stable_recoil)


def test_no_recoil_length_keeps_a_light_gun_down():
    """A shot whose free-recoil energy exceeds what the weight moment can take at any length: no stable recoil."""
    scene = carriage_scene({"barrel.initial_velocity": 60.0})
    assert closed_form(scene, 0.0, margin=1.0).shortest_stable_recoil is None


def test_simulated_points_agree_with_the_closed_form_while_the_carriage_rests():
    """On stiff, well damped supports (the spade stiff horizontally too: the breech force pushes the gun back),
    fired by a breech force that rises over 20 ms (the resistance rises smoothly:
    no step for the carriage to ring at), the carriage stays at rest during the recoil stroke: the front support's
    least load over its static one, simulated, is the closed form's with the simulated resistance, to 1e-3."""
    stiff = {"carriage.support.0.stiffness": 1e10, "carriage.support.0.damping": 1e7,
             "carriage.support.1.stiffness": 1e10, "carriage.support.1.damping": 1e7,
             "carriage.support.0.horizontal_stiffness": 1e10, "carriage.support.0.horizontal_damping": 1e7}
    firing = {"projectile_mass": 2.0, "muzzle_velocity": 500.0,
              "pulse": {"times": [0.0, 0.02, 0.04], "forces": [0.0, 5.0e4, 0.0], "scale_to_momentum": True}}
    scene = carriage_scene(stiff, barrel={"mass": 1000.0}, firing=firing)
    points = stability_chart(scene, [0.0, 10.0], margin=0.8, end_time=0.6)
    for point in points:
        assert point.error is None and point.lift_off_time is None
        assert point.recoil_margin < 0.999  # the resistance does unload the front
        assert point.recoil_margin == pytest.approx(point.recoil_margin_closed_form, abs=1e-3)


def test_recoil_stability_writes_the_chart(tmp_path, capsys):
    out = tmp_path / "chart"
    assert main(["stability", "towed_howitzer", "--elevations", "0,45", "--end-time", "1", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "stays down" in text and "on counter-recoil" in text
    data = json.loads((out / "stability.json").read_text())
    assert [p["elevation"] for p in data["points"]] == [0.0, 45.0]
    assert (out / "stability.png").read_bytes()[:4] == b"\x89PNG"
    assert (out / "stability.csv").read_text().startswith("elevation,")


@pytest.mark.parametrize("argv, key", [(["stability", "model_ii"], "scene"),
                                       (["stability", "towed_howitzer", "--elevations", "0,95"], "--elevations"),
                                       (["stability", "towed_howitzer", "--margin", "1.5"], "--margin")])
def test_bad_input_is_refused(tmp_path, capsys, argv, key):
    assert main([*argv, "--out", str(tmp_path / "x")]) == 2
    assert key in capsys.readouterr().err
