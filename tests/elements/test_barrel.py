"""The barrel (``mbs_models/elements/barrel.py``): its shot's recoil velocity and energy must be representable
(DESIGN.md, "Bad input beyond the ranges").  The boundaries are derived by hand: the model computes ``v0 = I / M``,
``v0^2`` and ``M v0^2 / 2`` (each per shot of a burst), so ``v0`` may not exceed ``sqrt(1.8e308) = 1.34e154`` m/s."""

from __future__ import annotations

import math
import sys

import pytest

from mbs_models import Barrel, Conventions, Firing, Scene, SceneError
from mbs_models.elements.firing import Burst, Pulse

MOMENTUM = 6.86 * 564.0                       # I, kg m/s
FASTEST = math.sqrt(sys.float_info.max)       # m/s: the largest v0 whose square is finite


def shot(mass: float, **changes) -> Scene:
    return Scene(barrel=Barrel(mass), firing=Firing(projectile_mass=6.86, muzzle_velocity=564.0), **changes)


def refused(key: str, quantity: str, build) -> None:
    with pytest.raises(SceneError) as info:
        build()
    assert info.value.key == key and quantity in info.value.message and "\n" not in str(info.value), info.value


def test_a_barrel_so_light_that_v0_squared_overflows_is_refused_naming_its_mass():
    boundary = MOMENTUM / FASTEST  # 2.9e-151 kg
    shot(1.1 * boundary)
    refused("barrel.mass", "(shots v0)^2", lambda: shot(0.9 * boundary))


def test_a_burst_multiplies_the_speed_the_barrel_may_reach():
    boundary = 3 * MOMENTUM / FASTEST
    shot(1.1 * boundary, burst=Burst(shots=3, interval=1.0))
    refused("barrel.mass", "(shots v0)^2", lambda: shot(0.9 * boundary, burst=Burst(shots=3, interval=1.0)))


def test_a_recoil_velocity_that_underflows_to_zero_is_refused():
    """I = 6.86 x 5e-324 = 3.5e-323 kg m/s, I / 5600 kg rounds to 0: the shot would not move the barrel."""
    Scene(barrel=Barrel(5600.0), firing=Firing(projectile_mass=6.86, muzzle_velocity=1e-300))
    refused("firing.muzzle_velocity", "recoil velocity v0 = I / M = 0",
            lambda: Scene(barrel=Barrel(5600.0), firing=Firing(projectile_mass=6.86, muzzle_velocity=5e-324)))


def test_an_initial_velocity_beyond_the_square_root_of_the_largest_double_is_refused():
    Scene(barrel=Barrel(1.0, initial_velocity=0.99 * FASTEST))
    Scene(barrel=Barrel(1.0, initial_velocity=0.0))  # a barrel at rest is a valid scene
    refused("barrel.initial_velocity", "(shots v0)^2", lambda: Scene(barrel=Barrel(1.0, initial_velocity=1.01 * FASTEST)))


def test_a_kinetic_energy_that_overflows_is_refused_naming_the_mass():
    """v0 = 1e5 m/s (v0^2 = 1e10 finite) on M = 1e300 kg: M v0^2 / 2 = 5e309 J."""
    Scene(barrel=Barrel(1e298, initial_velocity=1e5))
    refused("barrel.mass", "kinetic energy M (shots v0)^2 / 2", lambda: Scene(barrel=Barrel(1e300, initial_velocity=1e5)))


def test_a_pulse_whose_impulse_over_the_mass_overflows_is_refused():
    """impulse = 1e300 N x 1 s / 2 = 5e299 N s on M = 1e-10 kg: v = 5e309 m/s."""
    pulse = Pulse(times=(0.0, 0.5, 1.0), forces=(0.0, 1e300, 0.0))
    refused("firing.pulse.forces", "recoil velocity", lambda: Scene(barrel=Barrel(1e-10), firing=Firing(pulse=pulse)))


def test_a_v0_the_paper_s_rounding_takes_to_zero_is_no_precision_error():
    """rounded_initial_velocity: I / M = 3869 / 1e6 = 0.0039 m/s prints as 0.0 m/s -- a reading, not an underflow."""
    scene = Scene(barrel=Barrel(1e6), firing=Firing(projectile_mass=6.86, muzzle_velocity=564.0),
                  conventions=Conventions(rounded_initial_velocity=True))
    assert scene.initial_velocity == 0.0
