"""The scipy reference solution (validation.reference.solver) against closed forms, itself and physics."""

import functools
import math

import numpy as np
import pytest

from mbs_models.scene.models import model_i, model_ii, simplified_model
from mbs_models.scene import Absorber, Barrel, Contact, Conventions, RecoilDamper, RecoilSpring, Scene
from validation import (ReferenceSolveError, hunt_crossley_restitution, simplified_max_displacement,
                        solve_reference)

V0 = 6.86 * 564.0 / 5600.0
MODELS = {"i": model_i, "ii": model_ii}


@functools.lru_cache(maxsize=None)
def solve(model: str, mass: float = 1000.0, gap: float = 0.0, end_time: float = 10.0, **kw):
    scene = simplified_model() if model == "simplified" else MODELS[model](mass, gap)
    return solve_reference(scene, end_time, **kw)


# ------------------------------------------------------------------ closed form and convergence
def test_simplified_matches_closed_form():
    r = solve("simplified")
    x_max, t_max = simplified_max_displacement(5600.0, 27500.0, 6239.0, V0)
    assert r.scene.initial_velocity == pytest.approx(V0, rel=1e-15)
    assert r.max_barrel_displacement == pytest.approx(x_max, rel=1e-8)
    assert r.time_of_max_barrel_displacement == pytest.approx(t_max, rel=1e-8)
    assert round(r.max_barrel_displacement, 4) == 0.2215


@pytest.mark.parametrize("c", [2 * math.sqrt(27500.0 * 5600.0), 5e4])
def test_critically_and_over_damped_match_closed_form(c):
    scene = Scene(barrel=Barrel(mass=5600.0, initial_velocity=V0), recoil_spring=RecoilSpring(27500.0),
                  recoil_damper=RecoilDamper(c, c))
    r = solve_reference(scene, 5.0)
    x_max, t_max = simplified_max_displacement(5600.0, 27500.0, c, V0)
    assert r.max_barrel_displacement == pytest.approx(x_max, rel=1e-8)
    assert r.time_of_max_barrel_displacement == pytest.approx(t_max, rel=1e-6)


METRICS = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity")


@pytest.mark.parametrize("model", ["i", "ii"])
@pytest.mark.parametrize("gap", [0.0, 0.04])
@pytest.mark.parametrize("variant", [{"method": "Radau"}, {"rtol": 1e-12, "atol": 1e-14}])
def test_converged(model, gap, variant):
    base = solve(model, 1000.0, gap, 1.0)
    other = solve(model, 1000.0, gap, 1.0, **variant)
    for name in METRICS:
        assert getattr(other, name) == pytest.approx(getattr(base, name), rel=1e-8), name


def test_other_methods_run():
    base = solve("ii", 1000.0, 0.0, 1.0)
    for method in ("RK45", "LSODA"):
        r = solve("ii", 1000.0, 0.0, 1.0, method=method)
        for name in METRICS:
            assert getattr(r, name) == pytest.approx(getattr(base, name), rel=1e-7), (method, name)


# ------------------------------------------------------------------ physics checks
@pytest.mark.parametrize("model", ["i", "ii"])
@pytest.mark.parametrize("gap", [0.0, 0.04])
def test_energy_balance_closes(model, gap):
    r = solve(model, 1000.0, gap)
    t = np.linspace(0.0, r.end_time, 4001)
    energy = r.energy_balance(t)
    assert r.initial_energy == pytest.approx(0.5 * 5600.0 * V0 ** 2, rel=1e-15)
    assert np.max(np.abs(energy - r.initial_energy)) < 1e-8 * r.initial_energy
    d = r.dissipated_energy
    assert d["recoil_damper"] > 0 and d["absorber_damper"] > 0 and d["contact"] > 0
    assert np.all(np.diff(r.dissipated_energy_history(t)["contact"]) > -1e-9)  # Hunt-Crossley only dissipates


@pytest.mark.parametrize("model", ["i", "ii"])
def test_contact_force_never_negative_and_metrics_are_refined(model):
    r = solve(model)
    t = np.linspace(0.0, r.end_time, 200001)
    s = r.sample(t)
    assert np.all(s["contact_force"] >= 0.0)
    assert np.all(s["contact_force"][s["penetration"] < -1e-12] == 0.0)
    assert r.max_barrel_displacement >= s["x_M"].max()
    assert r.max_barrel_displacement == pytest.approx(s["x_M"].max(), rel=1e-6)
    assert r.barrel_velocity(r.time_of_max_barrel_displacement) == pytest.approx(0.0, abs=1e-9)
    # peak force and max absorber velocity are refined beyond any sample grid
    tf = np.linspace(0.0, 0.02, 20001)
    assert r.peak_contact_force >= r.contact_force(tf).max()
    assert r.contact_force(r.time_of_peak_contact_force) == pytest.approx(r.peak_contact_force, rel=1e-14)
    assert r.max_absorber_velocity >= r.absorber_velocity(tf).max()
    assert r.accelerations(r.time_of_max_absorber_velocity)[1] == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize("model", ["i", "ii"])
def test_impacts_are_contact_episodes(model):
    r = solve(model)
    impacts, episodes = r.impacts, r.contact_episodes
    assert impacts and impacts[0].start == 0.0  # gap 0: contact from the start
    assert all(i.peak_force > 1000.0 for i in impacts)
    assert all(e in episodes for e in impacts)
    for a, b in zip(episodes, episodes[1:]):
        assert a.end < b.start
        assert r.contact_force(0.5 * (a.end + b.start)) == 0.0
    for i in impacts:
        assert i.start <= i.time_of_peak <= i.end
        assert r.contact_force(0.5 * (i.start + i.time_of_peak)) > 0.0
        assert abs(r.penetration(i.end)) < 1e-12 or abs(r.contact_force(i.end)) < 1e-6
    assert impacts[0].peak_force == r.peak_contact_force


def test_simplified_has_no_absorber_metrics():
    r = solve("simplified")
    assert r.peak_contact_force is None and r.time_of_peak_contact_force is None
    assert r.max_absorber_velocity is None and r.time_of_max_absorber_velocity is None
    assert r.impacts == [] and r.contact_episodes is None
    assert set(r.dissipated_energy) == {"recoil_damper"}  # only connectors that exist
    assert r.dissipated_energy["recoil_damper"] > 0
    t = np.linspace(0, 10, 1001)
    assert np.all(r.contact_force(t) == 0.0)
    assert np.max(np.abs(r.energy_balance(t) - r.initial_energy)) < 1e-9 * r.initial_energy


def test_state_and_sample_shapes():
    r = solve("ii", 1000.0, 0.0, 1.0)
    assert r.state(0.3).shape == (7,)
    assert r.state(np.linspace(0, 1, 5)).shape == (7, 5)
    np.testing.assert_allclose(r.state(0.0)[:4], [0.0, V0, 0.0, 0.0], atol=1e-15)
    s = r.sample(11)
    assert s["t"].shape == (11,) and s["x_M"].shape == (11,) and s["contact_force"].shape == (11,)
    assert r.sample()["t"][0] == 0.0 and r.sample()["t"][-1] == 1.0
    with pytest.raises(ValueError):
        r.state(1.5)


# ------------------------------------------------------------------ conventions
CONVENTION_CASES = {
    "literal_lambda_sign": ("ii", 0.0),
    "compression_only": ("ii", 0.0),
    "v0_includes_absorber": ("i", 0.0),
    "rounded_initial_velocity": ("ii", 0.0),
    "literal_gap_sign": ("ii", 0.04),
}


@pytest.mark.parametrize("flag", sorted(CONVENTION_CASES))
def test_each_convention_changes_the_result(flag):
    model, gap = CONVENTION_CASES[flag]
    default = solve(model, 1000.0, gap, 1.0)
    r = solve_reference(MODELS[model](1000.0, gap, Conventions(**{flag: True})), 1.0)
    a = np.array([default.max_barrel_displacement, default.peak_contact_force])
    b = np.array([r.max_barrel_displacement, r.peak_contact_force])
    assert np.max(np.abs(b / a - 1)) > 1e-3, flag
    t = np.linspace(0, 1, 20001)
    assert np.all(r.contact_force(t) >= 0)
    assert np.max(np.abs(r.energy_balance(t) - r.initial_energy)) < 1e-8 * r.initial_energy


def test_conventions_without_effect_leave_results_unchanged():
    base = solve("ii", 1000.0, 0.0, 1.0)
    for conv in (Conventions(v0_includes_absorber=True), Conventions(literal_gap_sign=True)):
        r = solve_reference(model_ii(1000.0, 0.0, conv), 1.0)
        assert r.max_barrel_displacement == base.max_barrel_displacement
        assert r.peak_contact_force == base.peak_contact_force


def test_compression_only_has_no_restitution_force():
    r = solve_reference(model_ii(1000.0, 0.0, Conventions(compression_only=True)), 2.0)
    modes = {s.mode["contact"].phase for s in r.segments}
    assert "stick" in modes  # the bodies ride together at constant penetration after max compression
    t = np.linspace(0, 2, 40001)
    s = r.sample(t)
    rate = s["v_M"] - s["v_m"]
    assert np.all(s["contact_force"][rate < -1e-9] == 0.0)
    for seg in r.segments:
        if seg.mode["contact"].phase == "stick":
            ts = np.linspace(seg.t0, seg.t1, 50)
            y = r.state(ts)
            assert np.max(np.abs(y[1] - y[3])) < 1e-12
            p = r.penetration(ts)
            assert np.all(r.contact_force(ts) <= 2.1e8 * p ** 1.3 * (1 + 1e-9))


def test_clipped_force_region():
    # a very lossy contact (lambda = 5 s/m) and a strong barrel damper: the bodies separate faster than
    # 1/lambda while still penetrated, so the Hunt-Crossley force clips to 0 before p returns to 0
    scene = Scene(barrel=Barrel(mass=5600.0, initial_velocity=0.69), recoil_spring=RecoilSpring(27500.0),
                  recoil_damper=RecoilDamper(1e5, 1e5),
                  absorber=Absorber(mass=1000.0, mount="ground", stiffness=13500.0, damping=3675.0),
                  contact=Contact(gap=0.0, stiffness=2.1e8, exponent=1.3, damping_factor=5.0))
    r = solve_reference(scene, 1.0)
    clipped = [s for s in r.segments if s.mode["contact"].phase == "off" and s.mode["contact"].penetrated]
    assert len(clipped) == 1
    seg = clipped[0]
    assert seg.mode["contact"].clipped
    ts = np.linspace(seg.t0, seg.t1, 101)
    assert np.all(r.penetration(ts[:-1]) > 0) and np.all(r.contact_force(ts) == 0.0)
    rate = r.barrel_velocity(seg.t0) - r.absorber_velocity(seg.t0)
    assert 1 + 5.0 * rate == pytest.approx(0.0, abs=1e-12)
    t = np.linspace(0, 1, 10001)
    assert np.max(np.abs(r.energy_balance(t) - r.initial_energy)) < 1e-8 * r.initial_energy


# ------------------------------------------------------------------ restitution oracle
def free_impact(lam, n, kc, conventions=None, v0=0.69, M=5600.0, m=1000.0):
    """Barrel hits a free absorber (no springs, no dampers): one Hunt-Crossley impact."""
    return Scene(barrel=Barrel(mass=M, initial_velocity=v0), recoil_spring=RecoilSpring(0.0),
                 recoil_damper=RecoilDamper(0.0, 0.0),
                 absorber=Absorber(mass=m, mount="ground", stiffness=0.0, damping=0.0),
                 contact=Contact(gap=0.0, stiffness=kc, exponent=n, damping_factor=lam),
                 conventions=conventions or Conventions())


def _restitution(scene, lam_signed, v0=0.69):
    P_red = scene.barrel.mass * scene.absorber.mass / (scene.barrel.mass + scene.absorber.mass)
    n, kc = scene.contact.exponent, scene.contact.stiffness
    p_max = ((n + 1) * P_red * v0 ** 2 / (2 * kc)) ** (1 / (n + 1))  # elastic estimate
    e_min = hunt_crossley_restitution(v0, lam_signed, n)
    end = 6 * p_max / v0 / min(e_min, 1.0)
    r = solve_reference(scene, end, max_step=end / 20)
    y = r.state(end)
    assert scene.barrel.mass * y[1] + scene.absorber.mass * y[3] == pytest.approx(scene.barrel.mass * v0, rel=1e-12)
    assert len(r.contact_episodes) == 1 and r.contact_episodes[0].end < end
    return -(y[1] - y[3]) / v0


@pytest.mark.parametrize("lam", [0.0, 0.3, 0.6, 2.0])
@pytest.mark.parametrize("n", [1.0, 1.3, 1.5, 2.0])
@pytest.mark.parametrize("kc", [1e6, 2.1e8, 1e10])
def test_restitution_matches_hunt_crossley(lam, n, kc):
    e = _restitution(free_impact(lam, n, kc), lam)
    assert e == pytest.approx(hunt_crossley_restitution(0.69, lam, n), rel=1e-6, abs=1e-6)


@pytest.mark.parametrize("m", [10.0, 5600.0, 1e5])
def test_restitution_independent_of_masses(m):
    e = _restitution(free_impact(0.6, 1.3, 2.1e8, m=m), 0.6)
    assert e == pytest.approx(hunt_crossley_restitution(0.69, 0.6, 1.3), rel=1e-6)


def test_literal_lambda_sign_restitution_exceeds_one():
    scene = free_impact(0.6, 1.3, 2.1e8, Conventions(literal_lambda_sign=True))
    e = _restitution(scene, -0.6)
    assert e > 1
    assert e == pytest.approx(hunt_crossley_restitution(0.69, -0.6, 1.3), rel=1e-6)


# ------------------------------------------------------------------ robustness and isolation
def test_segment_cap_raises():
    with pytest.raises(ReferenceSolveError, match="segments"):
        solve_reference(model_ii(1000.0, 0.0), 10.0, max_segments=3)


def test_bad_arguments():
    with pytest.raises(ValueError):
        solve_reference(model_ii(), 1.0, method="Euler")
    with pytest.raises(ValueError):
        solve_reference(model_ii(), -1.0)
    with pytest.raises(TypeError):
        solve_reference("model_ii.toml", 1.0)


# ------------------------------------------------------------------ the paper's m = 1000 kg case
@pytest.mark.parametrize("model", ["i", "ii"])
def test_paper_case_m1000_gap0(model):
    r = solve(model)
    first = r.impacts[0]
    print(f"\nmodel ({model}) m=1000 gap 0, 10 s: max x_M = {r.max_barrel_displacement:.6f} m at "
          f"{r.time_of_max_barrel_displacement:.5f} s; peak F = {r.peak_contact_force / 1e3:.3f} kN at "
          f"{r.time_of_peak_contact_force:.6f} s; max v_m = {r.max_absorber_velocity:.5f} m/s at "
          f"{r.time_of_max_absorber_velocity:.6f} s; first impact {first.start:.5f}-{first.end:.6f} s; "
          f"impacts at {[round(i.start, 4) for i in r.impacts]}; {len(r.segments)} segments, "
          f"{r.wall_time:.2f} s")
    if model == "ii":
        assert r.max_barrel_displacement == pytest.approx(0.1508, abs=5e-4)
    else:
        assert r.max_barrel_displacement == pytest.approx(0.2066, abs=5e-4)
    assert 115e3 < r.peak_contact_force < 130e3
    assert first.start == 0.0 and 0.012 < first.end < 0.018
