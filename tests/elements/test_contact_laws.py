"""The analytic impact oracle against the engine: a free two-body Hunt-Crossley impact.

Measured worst error of e over the grid below: 2.8e-6 at `standard`, 1e-9 at `reference`.

For two free bodies (no springs, no dampers) the coefficient of restitution depends only on
lambda * v_in (``validation.reference.closed_form.hunt_crossley_restitution`` derives it from the energy-like
integral over one impact), whatever the stiffness, exponent or masses.  The reference is checked
against the same oracle in test_validation_reference.py.
"""

from __future__ import annotations

import pytest

from mbs_models import (Absorber, Barrel, Contact, Conventions, RecoilDamper, RecoilSpring, Scene, SolverSettings,
                        simulate)
from validation.reference.closed_form import hunt_crossley_restitution

IMPACT_VELOCITY = 0.69  # m/s


def free_impact(damping_factor, exponent, stiffness, absorber_mass=1000.0, conventions=None) -> Scene:
    return Scene(barrel=Barrel(mass=5600.0, initial_velocity=IMPACT_VELOCITY), recoil_spring=RecoilSpring(0.0),
                 recoil_damper=RecoilDamper(0.0, 0.0),
                 absorber=Absorber(mass=absorber_mass, mount="ground", stiffness=0.0, damping=0.0),
                 contact=Contact(gap=0.0, stiffness=stiffness, exponent=exponent, damping_factor=damping_factor),
                 conventions=conventions or Conventions(), name="free impact")


def engine_restitution(scene: Scene, accuracy="standard") -> float:
    result = simulate(scene, 1.5, accuracy)
    assert len(result.impacts) == 1 and result.impacts[0].end < 1.4, "one impact, over before the end"
    return (result.absorber_velocity[-1] - result.barrel_velocity[-1]) / IMPACT_VELOCITY


@pytest.mark.parametrize("damping_factor", [0.0, 0.3, 0.6, 2.0])
@pytest.mark.parametrize("exponent", [1.0, 1.3, 1.5, 2.0])
@pytest.mark.parametrize("stiffness", [1e6, 2.1e8, 1e10])
def test_engine_restitution_matches_oracle(damping_factor, exponent, stiffness):
    e = engine_restitution(free_impact(damping_factor, exponent, stiffness))
    assert e == pytest.approx(hunt_crossley_restitution(IMPACT_VELOCITY, damping_factor, exponent), abs=1e-5)


@pytest.mark.parametrize("absorber_mass", [10.0, 5600.0, 1e5])
def test_engine_restitution_does_not_depend_on_masses(absorber_mass):
    e = engine_restitution(free_impact(0.6, 1.3, 2.1e8, absorber_mass))
    assert e == pytest.approx(hunt_crossley_restitution(IMPACT_VELOCITY, 0.6, 1.3), abs=1e-5)


def test_reference_preset_meets_the_oracle_tighter():
    e = engine_restitution(free_impact(0.6, 1.3, 2.1e8), "reference")
    assert e == pytest.approx(hunt_crossley_restitution(IMPACT_VELOCITY, 0.6, 1.3), abs=1e-8)


def test_literal_lambda_sign_gains_energy_as_the_oracle_predicts():
    e = engine_restitution(free_impact(0.6, 1.3, 2.1e8, conventions=Conventions(literal_lambda_sign=True)))
    assert e > 1.0
    assert e == pytest.approx(hunt_crossley_restitution(IMPACT_VELOCITY, -0.6, 1.3), abs=1e-5)
