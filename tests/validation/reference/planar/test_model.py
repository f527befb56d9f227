"""The planar right-hand side's constraint: exact Coulomb friction of the cradle sticking on a carriage."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planar_scenes import carriage_scene
from validation.reference import solve_reference

STIFF = {"law": "kelvin-voigt", "stiffness": 1.0e9, "damping": 1.0e6}
RIGID = [dict(STIFF, name="spade", position=[0.0, 0.0], horizontal_stiffness=1.0e9, horizontal_damping=1.0e6),
         dict(STIFF, name="front", position=[2.8, 0.0])]


def test_the_cradle_friction_holds_the_barrel_with_its_weight_along_the_tilted_axis():
    """At 10 degrees with mu = 0.5 the barrel at rest sticks: the friction is the multiplier that holds it,
    M g sin(theta + phi) (the axis turned by the static pitch), and nothing moves."""
    scene = carriage_scene(RIGID, **{"barrel.initial_velocity": 0.0},
                           cradle={"elevation": 10.0, "friction_coefficient": 0.5})
    result = solve_reference(scene, 0.2)
    assert {seg.mode["cradle"] for seg in result.segments} == {"stick"}
    phi = result.model.static["phi"]
    t = np.linspace(0.0, 0.2, 21)
    held = result.connector_force("cradle", t)
    assert np.allclose(held, 1000.0 * 9.81 * math.sin(math.radians(10.0) + phi), rtol=1e-8)  # pushes it up the cradle
    assert result.max_barrel_displacement < 1e-12


def test_the_barrel_breaks_away_when_the_push_exceeds_mu_n():
    """A breech force rising at 1e5 N/s against mu M g = 0.3 x 9810 N at 0 degrees: the barrel breaks away at
    L = mu M g (t = 0.02943 s) to within what the carriage's motion on its stiff supports changes (1e-4 s)."""
    scene = carriage_scene(RIGID, barrel={"mass": 1000.0},
                           firing={"projectile_mass": 10.0, "muzzle_velocity": 100.0,
                                   "pulse": {"times": [0.0, 0.1], "forces": [0.0, 1.0e4], "scale_to_momentum": False}},
                           cradle={"elevation": 0.0, "friction_coefficient": 0.3})
    result = solve_reference(scene, 0.05)
    slip = next(seg.t0 for seg in result.segments if seg.mode["cradle"] != "stick")
    assert slip == pytest.approx(0.3 * 1000.0 * 9.81 / 1.0e5, abs=1e-4)
    assert result.barrel_position(slip) == pytest.approx(0.0, abs=1e-12)
    assert result.barrel_position(0.05) > 1e-4
