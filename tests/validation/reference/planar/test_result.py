"""The planar result's histories and metrics against its own dense samples (the refined extremes are at least
every sample and within a sample step of them) and their definitions (DESIGN.md)."""

from __future__ import annotations

import numpy as np
import pytest

from planar_scenes import carriage_scene
from validation.reference import solve_reference


@pytest.fixture(scope="module")
def jumping():
    """The brief's gun at 0 degrees: the wheels leave the ground ~0.02 s after the shot and land again."""
    return solve_reference(carriage_scene(), 0.3, method="LSODA")


def test_the_metrics_are_the_refined_extremes_of_the_histories(jumping):
    r = jumping
    t = np.linspace(0.0, 0.3, 30001)
    static = r.model.static
    pitch = np.abs(r.carriage_pitch(t) - static["phi"])
    assert pitch.max() <= r.max_carriage_pitch <= pitch.max() * (1 + 1e-6)
    heights = np.max([r.support_height(s, t) for s in ("spade", "wheels")], axis=0)
    assert heights.max() <= r.max_lift <= heights.max() * (1 + 1e-6) and r.max_lift > 1e-3
    x0 = r.carriage_position(0.0)[0]
    shift = np.abs(r.carriage_position(t)[0] - x0)
    assert shift.max() <= r.max_carriage_displacement <= shift.max() * (1 + 1e-6)
    for support in r.supports():
        normal = r.support_normal_force(support["name"], t)
        assert support["min_normal_force"] <= normal.min() + 1e-9 * support["static_normal_force"]
        assert normal.max() <= support["max_normal_force"] <= normal.max() * (1 + 1e-6)
        assert support["static_normal_force"] == pytest.approx(normal[0], rel=1e-12)
    assert r.stability_margin == min(s["min_normal_force"] / s["static_normal_force"] for s in r.supports()) == 0.0


def test_lift_off_is_the_first_time_a_normal_force_reaches_zero(jumping):
    r = jumping
    t_lift = r.lift_off_time
    assert 0.0 < t_lift < 0.1
    before = np.linspace(0.0, t_lift, 2001)[:-1]
    assert r.support_normal_force("wheels", before).min() > 0.0
    assert r.support_normal_force("spade", before).min() > 0.0
    assert r.support_normal_force("wheels", t_lift + 1e-6) == 0.0


def test_metrics_keys_and_samples(jumping):
    r = jumping
    m = r.metrics()
    for key in ("max_carriage_pitch", "max_lift", "lift_off_time", "max_carriage_displacement", "stability_margin",
                "max_barrel_displacement", "peak_support_force"):
        assert key in m
    assert m["supports"] == r.supports() and [s["name"] for s in m["supports"]] == ["spade", "wheels"]
    assert set(m["supports"][0]) == {"name", "static_normal_force", "min_normal_force", "max_normal_force"}
    sample = r.sample(50)
    for key in ("carriage_x", "carriage_y", "carriage_pitch", "N:wheels", "T:spade", "y:wheels", "x_M"):
        assert sample[key].shape == (50,)
    assert r.carriage_position(np.linspace(0, 0.3, 7)).shape == (2, 7)
    with pytest.raises(KeyError, match="spade, wheels"):
        r.support_normal_force("trail", 0.1)
