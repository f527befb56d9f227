"""The [carriage] table and its supports (mbs_models/elements/carriage.py): checks naming the key, the support law
over the backends, the static equilibrium against hand statics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mbs_models import SceneError
from mbs_models.elements.carriage import (AxisBody, static_equilibrium, support_normal_force,
                                          support_tangential_force)
from mbs_models.elements.ops import NUMPY_OPS, PYTHON_OPS
from mbs_models.scene.io import scene_from_dict, scene_to_toml, load_scene
from mbs_models.scene.overrides import apply_overrides

from carriage_scenes import BASE, carriage_scene


@pytest.mark.parametrize("changes, key, words", [
    ({"carriage.support": []}, "carriage.support", "at least two"),
    ({"carriage.support.1.position": [0.0, 0.5]}, "carriage.support", "one x"),
    ({"carriage.support.1.name": "spade"}, "carriage.support.1.name", "two supports"),
    ({"carriage.support.0.friction_coefficient": 0.3}, "carriage.support.0.friction_coefficient", "not both"),
    ({"carriage.support.1.position": [1.0]}, "carriage.support.1.position", "two numbers"),
    ({"carriage.mass": 0.0}, "carriage.mass", "> 0"),
    ({"carriage.inertia": -1.0}, "carriage.inertia", "> 0"),
    ({"carriage.trunnion": "high"}, "carriage.trunnion", "point"),
    ({"carriage.support.1.anchor": "touchdown"}, "carriage.support.1.anchor", "spade"),
    ({"carriage.support.0.anchor": "dug"}, "carriage.support.0.anchor", "unknown anchor"),
    ({"carriage.support.0.horizontal_stiffness": -1.0}, "carriage.support.0.horizontal_stiffness", ">= 0"),
])
def test_bad_carriage_tables_name_the_key(changes, key, words):
    with pytest.raises(SceneError) as error:
        carriage_scene(changes)
    assert error.value.key == key and words in str(error.value)


def test_a_carriage_needs_a_version_2_scene():
    data = dict(BASE)
    data.pop("version")
    data.pop("cradle")
    data.pop("recoil_damper")
    with pytest.raises(SceneError, match="version"):
        scene_from_dict(data)


def test_the_scene_round_trips_through_toml_and_overrides(tmp_path):
    scene = carriage_scene()
    path = tmp_path / "gun.toml"
    path.write_text(scene_to_toml(scene))
    assert load_scene(path) == scene
    changed = apply_overrides(scene, {"carriage.support.1.stiffness": 3e8, "carriage.mass": 2500.0})
    assert changed.carriage.supports[1].stiffness == 3e8 and changed.carriage.mass == 2500.0
    with pytest.raises(SceneError) as error:
        apply_overrides(scene, {"carriage.support.2.stiffness": 1.0})
    assert error.value.key == "carriage.support.2.stiffness" and "2 [[carriage.support]]" in str(error.value)
    with pytest.raises(SceneError, match="index and a field"):
        apply_overrides(scene, {"carriage.support.stiffness": 1.0})


def test_the_support_law_is_the_contact_law_and_coulomb():
    """N: Kelvin-Voigt k p + c p' clipped at 0, p = -y; T: -mu N sat(u / v_reg); a spade: -(k_h dx + c_h u) while
    p > 0 (by hand)."""
    scene = carriage_scene({"carriage.support.1.friction_coefficient": 0.3})
    spade, wheels = scene.carriage.supports
    assert support_normal_force(wheels, -1e-4, -0.01, PYTHON_OPS) == pytest.approx(2e8 * 1e-4 + 1e6 * 0.01)
    assert support_normal_force(wheels, -1e-4, 0.1, PYTHON_OPS) == 0.0  # leaving fast: clipped
    assert support_normal_force(wheels, 1e-4, -1.0, PYTHON_OPS) == 0.0  # above the ground
    assert support_tangential_force(wheels, 1000.0, 0.0, 1.0, 0.0, PYTHON_OPS, -1e-4) == pytest.approx(-300.0)
    assert support_tangential_force(wheels, 1000.0, 0.0, 0.5e-4, 0.0, PYTHON_OPS, -1e-4) == pytest.approx(-150.0)
    assert support_tangential_force(spade, 10.0, 0.002, 0.01, 0.0, PYTHON_OPS, -1e-5) == pytest.approx(
        -(2e8 * 0.002 + 1e6 * 0.01))
    assert support_tangential_force(spade, 0.0, 0.002, 0.01, 0.0, PYTHON_OPS, 1e-5) == 0.0  # lifted: no anchor
    heights = np.array([-2e-4, -1e-4, 1e-4])
    assert np.allclose(support_normal_force(wheels, heights, np.zeros(3), NUMPY_OPS), [4e4, 2e4, 0.0])


def test_static_equilibrium_balances_forces_and_moments():
    """Sum of loads = weight; moments about the origin: sum x_i N_i = g sum m x (every abscissa in the pitched
    position); the penetrations are the laws' k p = N (hand check on the result)."""
    scene = carriage_scene({"cradle.elevation": 30.0})
    carriage = scene.carriage
    bodies = [AxisBody("barrel", 1000.0, 0.0, 0.05), AxisBody("buffer", 200.0, 0.0, 0.0)]
    state = static_equilibrium(carriage, math.radians(30.0), 9.81, bodies)
    weight = 9.81 * (2000.0 + 1200.0)
    assert sum(state.loads.values()) == pytest.approx(weight, rel=1e-12)
    c, s = math.cos(state.pitch), math.sin(state.pitch)

    def x_of(point):
        return c * point[0] - s * point[1]

    e = (math.cos(math.radians(30.0)), math.sin(math.radians(30.0)))
    masses = [(2000.0, carriage.center_of_mass), (1000.0, (2.5 - 0.05 * e[0], 1.0 - 0.05 * e[1])), (200.0, (2.5, 1.0))]
    moment = sum(x_of(s_.position) * state.loads[s_.name] for s_ in carriage.supports)
    assert moment == pytest.approx(9.81 * sum(m * x_of(p) for m, p in masses), rel=1e-10)
    for support in carriage.supports:
        y = state.height + s * support.position[0] + c * support.position[1]
        assert state.loads[support.name] == pytest.approx(support.stiffness * -y, rel=1e-12)
