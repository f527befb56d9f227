"""Hard cases of the contact laws in the reference: a resting contact (an initial interference: onset
velocity 0, below minimum_impact_velocity).  (The restitution extremes 0.05 and 0.99 are in
test_restitution.py; the hard cases of an element's own contacts are in its test file, tests/elements/.)"""

from __future__ import annotations

import pytest
from scipy.optimize import brentq

from mbs_models.scene import Absorber, Barrel, Contact, Conventions, RecoilDamper, RecoilSpring, Scene
from validation.reference import solve_reference

LN = dict(law="lankarani-nikravesh", stiffness=1e8, exponent=1.5, restitution=0.5)
CHI = 3 * (1 - 0.5 ** 2) / 4   # Lankarani-Nikravesh's chi for e = 0.5
FLOOR = 1e-3                   # the default minimum_impact_velocity, m/s


def _resting_force(gap, k, kr, kc, n):
    """Contact force F (N) of the resting state: barrel -k x_M = F, absorber kr x_m = F, and the penetration
    p = x_M - x_m + gap = (F / kc)^(1/n)."""
    return brentq(lambda F: gap - F / k - F / kr - (F / kc) ** (1 / n), 0.0, gap * min(k, kr))


def test_interference_at_rest_settles_into_a_resting_contact(assert_sound):
    """literal_gap_sign makes the gap an interference: p(0) = 5 mm with both bodies at rest, v- = max(p'(0), 0)
    = 0, so the law damps as at minimum_impact_velocity (lambda = chi / 1 mm/s); the bodies are pushed apart
    against their springs and come to rest pressed together: F = -k x_M = k_r x_m."""
    gap, k, kr = 0.005, 27500.0, 13500.0
    scene = Scene(barrel=Barrel(5600.0, initial_velocity=0.0), recoil_spring=RecoilSpring(k),
                  recoil_damper=RecoilDamper(6239.0, 14050.0),
                  absorber=Absorber(1000.0, "ground", kr, 3675.0), contact=Contact(gap=gap, **LN),
                  conventions=Conventions(literal_gap_sign=True))
    r = solve_reference(scene, 40.0)
    assert r.initial_energy == pytest.approx(1e8 * gap ** 2.5 / 2.5, rel=1e-14)  # the interference's energy
    assert r.contacts["contact"].onsets[0] == (0.0, 0.0)
    assert r.segments[0].mode["contact"].factor == pytest.approx(CHI / FLOOR, rel=1e-15)
    assert_sound(r, 40.0)
    F = _resting_force(gap, k, kr, 1e8, 1.5)
    assert r.contact_force(40.0) == pytest.approx(F, rel=1e-4)
    assert r.barrel_position(40.0) == pytest.approx(-F / k, rel=1e-4)
    assert r.absorber_position(40.0) == pytest.approx(F / kr, rel=1e-4)
