"""Hard cases of the contact laws in the reference: resting and grazing contacts (onset velocity 0 or
below minimum_impact_velocity) and end stops hit at ten times the paper's firing velocity.  (The
restitution extremes 0.05 and 0.99 are in test_restitution.py.)"""

from __future__ import annotations


import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

from mbs_models.scene import (Absorber, Barrel, BatteryStop, Contact, Conventions, Firing, RecoilDamper, RecoilSpring,
                              RecoilStop, Scene, model_ii)
from validation.reference import solve_reference

LN = dict(law="lankarani-nikravesh", stiffness=1e8, exponent=1.5, restitution=0.5)
CHI = 3 * (1 - 0.5 ** 2) / 4   # Lankarani-Nikravesh's chi for e = 0.5
FLOOR = 1e-3                   # the default minimum_impact_velocity, m/s


def assert_sound(r, end, balance=1e-8):
    """Finite, non-negative contact forces; the energy balance closes."""
    t = np.linspace(0.0, end, 20001)
    for name in r.contacts:
        force = r.connector_force(name, t)
        assert np.all(np.isfinite(force)) and np.all(force >= 0), name
    energy = r.energy_balance(t)
    assert np.all(np.isfinite(energy))
    assert np.max(np.abs(energy - r.initial_energy)) <= balance * max(r.initial_energy, 1.0)


def test_battery_stop_touching_a_barrel_at_rest():
    """p = 0, p' = 0, p'' = 0 at the battery stop: nothing moves, no force, no division by v- = 0."""
    scene = Scene(barrel=Barrel(5600.0, initial_velocity=0.0), recoil_spring=RecoilSpring(27500.0),
                  recoil_damper=RecoilDamper(6239.0, 14050.0), battery_stop=BatteryStop(position=0.0, **LN))
    r = solve_reference(scene, 1.0)
    assert_sound(r, 1.0)
    assert r.initial_energy == 0.0 and r.max_barrel_displacement == 0.0
    assert r.stop_metrics["battery_stop"].peak_force == 0.0 and r.stop_metrics["battery_stop"].episodes == []
    assert r.peak_support_force == 0.0


def _resting_force(gap, k, kr, kc, n):
    """Contact force F (N) of the resting state: barrel -k x_M = F, absorber kr x_m = F, and the penetration
    p = x_M - x_m + gap = (F / kc)^(1/n)."""
    return brentq(lambda F: gap - F / k - F / kr - (F / kc) ** (1 / n), 0.0, gap * min(k, kr))


def test_interference_at_rest_settles_into_a_resting_contact():
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


def test_grazing_return_onto_the_battery_stop():
    """The barrel returns past x = 0 and turns; a battery stop 2e-8 m short of that turning point is met at
    v- ~ 2e-4 m/s, below minimum_impact_velocity: the law damps as Hunt-Crossley with lambda = chi / 1 mm/s,
    the force stays finite and >= 0, and the energy balance closes."""
    base = Scene(barrel=Barrel(5600.0), firing=Firing(6.86, 564.0), recoil_spring=RecoilSpring(27500.0),
                 recoil_damper=RecoilDamper(6239.0, 14050.0))
    free = solve_reference(base, 4.0)
    t = np.linspace(0.0, 4.0, 40001)
    i = int(np.argmin(free.barrel_position(t)))
    turn = minimize_scalar(free.barrel_position, bounds=(t[i - 1], t[i + 1]), method="bounded",
                           options={"xatol": 1e-12})
    x_min, a_turn = float(turn.fun), float(free.acceleration("barrel", turn.x))
    v_target = 2e-4
    position = x_min + v_target ** 2 / (2 * a_turn)
    r = solve_reference(base.with_changes(battery_stop=BatteryStop(position=position, **LN)), 4.0)
    onsets = r.contacts["battery_stop"].onsets
    assert len(onsets) == 1
    t_on, v_minus = onsets[0]
    assert v_minus == pytest.approx(v_target, rel=0.05) and v_minus < FLOOR
    state = next(s.mode["battery_stop"] for s in r.segments if s.t0 == t_on)
    assert state.factor == pytest.approx(CHI / FLOOR, rel=1e-15)
    assert_sound(r, 4.0)
    stop = r.stop_metrics["battery_stop"]
    assert 0 < stop.peak_force < 1000.0 and stop.impacts == []  # a touch, not an impact


SPEED = 10  # times the paper's muzzle velocity: v0 = 6.9 m/s
STOP_LAWS = {
    "hunt-crossley": dict(law="hunt-crossley", stiffness=1e9, exponent=1.5, damping_factor=0.5),
    "flores": dict(law="flores", stiffness=1e9, exponent=1.5, restitution=0.5),
    "exact-restitution": dict(law="exact-restitution", stiffness=1e9, exponent=1.5, restitution=0.2),
    "kelvin-voigt": dict(law="kelvin-voigt", stiffness=1e8, damping=1e6),
    "hertz": dict(law="hertz", stiffness=1e9, exponent=1.5),
}


@pytest.mark.parametrize("law", list(STOP_LAWS))
def test_stops_hit_at_ten_times_the_firing_velocity(law):
    scene = model_ii(1000.0, 0.0).with_changes(
        firing=Firing(6.86, 564.0 * SPEED), recoil_stop=RecoilStop(position=0.15, **STOP_LAWS[law]),
        battery_stop=BatteryStop(position=-0.05, law="kelvin-voigt", stiffness=5e7, damping=2e5))
    end = 3.0
    r = solve_reference(scene, end)
    assert_sound(r, end, balance=1e-7)
    energy = r.initial_energy
    assert energy == pytest.approx(0.5 * 5600.0 * (6.86 * 5640.0 / 5600.0) ** 2, rel=1e-14)
    stop = r.stop_metrics["recoil_stop"]
    assert stop.impacts and stop.impacts[0].peak_force > 1e5
    spec = STOP_LAWS[law]
    n = spec.get("exponent", 1.0)
    own = ((n + 1) * energy / spec["stiffness"]) ** (1 / (n + 1))  # the stop's potential cannot exceed E(0)
    assert 0.15 < r.max_barrel_displacement < 0.15 + own
    if law == "hertz":
        assert stop.dissipated_energy == pytest.approx(0.0, abs=1e-8 * energy)
    else:
        assert stop.dissipated_energy > 0
    t = np.linspace(0.0, end, 20001)
    x = r.barrel_position(t)
    np.testing.assert_array_equal(r.connector_force("recoil_stop", t)[x < 0.15 - 1e-12], 0.0)
    np.testing.assert_array_equal(r.connector_force("battery_stop", t)[x > -0.05 + 1e-12], 0.0)
