"""The initial static equilibrium on the supports against statics by hand (lever rule, moment balance)."""

from __future__ import annotations

import math

import pytest

from planar_scenes import SPADE, WHEELS, carriage_scene
from validation.reference.planar import build_planar_model

G = 9.81
#: the test gun: carriage 2000 kg at x = 2.4 m, barrel 1000 kg at the trunnion's x = 2.5 m (b = 0), wheels at 2.8 m
WEIGHT = 3000.0 * G
CG_X = (2000.0 * 2.4 + 1000.0 * 2.5) / 3000.0


def lever_rule(front_x: float = 2.8) -> tuple[float, float]:
    """(spade, front) loads (N) of a rigid gun level on two supports at x = 0 and x = front_x."""
    front = WEIGHT * CG_X / front_x
    return WEIGHT - front, front


def level_supports(spade_stiffness: float = 5.0e8):
    """Linear supports whose stiffnesses are in the ratio of the lever-rule loads: the gun sinks level."""
    rear, front = lever_rule()
    spade = {**SPADE, "stiffness": spade_stiffness}
    wheels = {"name": "wheels", "position": [2.8, 0.0], "law": "kelvin-voigt",
              "stiffness": spade_stiffness * front / rear, "damping": 1.0e5}
    return [spade, wheels]


def test_a_gun_that_sinks_level_carries_the_lever_rule_loads():
    model, y = build_planar_model(carriage_scene(level_supports()))
    static = model.static
    rear, front = lever_rule()
    assert static["normal"] == pytest.approx([rear, front], rel=1e-10)
    assert abs(static["phi"]) < 1e-12
    assert static["Y"] == pytest.approx(-rear / 5.0e8, rel=1e-9)  # both sink by N / k
    assert y[model.carriage_slot:model.carriage_slot + 6].tolist() == pytest.approx([0.0, static["Y"], static["phi"],
                                                                                     0.0, 0.0, 0.0], abs=1e-15)


def test_a_pitched_equilibrium_balances_force_and_moment_by_hand():
    """The brief's gun (a stiff spade, soft wheels): it pitches nose down; at the pitched positions the weights and
    the loads balance (moment about the spade's point, each CG and support rotated by phi)."""
    model, _ = build_planar_model(carriage_scene([SPADE, WHEELS]))
    static = model.static
    phi, Y = static["phi"], static["Y"]
    assert -1e-3 < phi < -1e-4  # nose down on the soft wheels: the balance below is not the level one
    spade, wheels = static["normal"]
    assert spade + wheels == pytest.approx(WEIGHT, rel=1e-11)

    def x_of(point):
        return math.cos(phi) * point[0] - math.sin(phi) * point[1]
    spade_x = x_of((0.0, 0.0))
    moment = wheels * (x_of((2.8, 0.0)) - spade_x) - G * (2000.0 * (x_of((2.4, 0.8)) - spade_x)
                                                          + 1000.0 * (x_of((2.5, 1.0)) - spade_x))
    assert abs(moment) < 1e-9 * WEIGHT * 2.8
    # each load is the law's force at the point's penetration
    assert spade == pytest.approx(5.0e8 * -Y, rel=1e-12)
    assert wheels == pytest.approx(2.0e7 * -(Y + math.sin(phi) * 2.8), rel=1e-12)
    # the lever rule holds to the order of the pitch (the CGs shift by y phi)
    assert wheels == pytest.approx(lever_rule()[1], rel=2e-4)


def test_a_support_that_carries_nothing_at_rest_is_accepted():
    """A third support held above the ground by the others (its point at y = 0.1 m) carries no load: the
    equilibrium is the two others' (the same Y and pitch as without it), its static load 0 (DESIGN.md: the
    stability margin is over the supports loaded at rest)."""
    high = {**WHEELS, "name": "high", "position": [1.0, 0.1]}
    three, _ = build_planar_model(carriage_scene([SPADE, WHEELS, high]))
    two, _ = build_planar_model(carriage_scene([SPADE, WHEELS]))
    assert three.static["normal"][2] == 0.0
    assert three.static["Y"] == pytest.approx(two.static["Y"], rel=1e-12)
    assert three.static["phi"] == pytest.approx(two.static["phi"], rel=1e-12)
