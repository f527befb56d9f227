"""The reference's shots: the gas after-effect, the breech-force pulse (an external load), bursts (velocity
jumps or repeated pulses), the per-shot outputs and the early stop after the last input.

Every expected value is written out here from the equations (closed forms for a free mass, Duhamel's
integral for the pulse's convergence to the initial-velocity model), or is another reference run of a
scene the burst must reproduce (its first shot alone).
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from mbs_models.scene import Barrel, Burst, Conventions, Firing, Pulse, Scene, model_i, model_ii, simplified_model
from validation.reference import solve_reference
from validation.reference.assembly import build_model
from validation.reference.codegen import source
from validation.reference.finality import METRICS
from validation.reference.model import ConstantLoad, Mode
from validation.reference.switching import Restart
from validation.reference.terms import TERMS
from validation.reference.terms.contact_laws import ContactMode

M = 5600.0                        # kg, the paper's barrel
K, C_RECOIL = 27500.0, 6239.0     # N/m, N s/m: the simplified model's spring and recoil damping
MOMENTUM = 6.86 * 564.0           # kg m/s
V0 = MOMENTUM / M                 # m/s
#: a pulse that starts late, jumps at both ends and has a kink at every inner point (s, N)
TIMES, FORCES = (0.001, 0.003, 0.007, 0.010), (5.0e5, 2.0e6, 6.0e5, 1.0e5)
#: its impulse, sum (F_i + F_(i+1)) (t_(i+1) - t_i) / 2 (N s)
IMPULSE = 0.5 * (5.0e5 + 2.0e6) * 0.002 + 0.5 * (2.0e6 + 6.0e5) * 0.004 + 0.5 * (6.0e5 + 1.0e5) * 0.003


def pulse_pieces(shift: float = 0.0, scale: float = 1.0) -> list[tuple[float, float, float, float]]:
    """``(a, b, F(a+), F(b-))`` of the pulse on each piece, shifted by ``shift`` s, forces times ``scale``."""
    return [(shift + TIMES[i], shift + TIMES[i + 1], scale * FORCES[i], scale * FORCES[i + 1])
            for i in range(len(TIMES) - 1)]


def free_mass(pieces, mass: float, t, v_start: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """x (m), v (m/s) at ``t`` of a mass starting at x = 0 with ``v_start`` under a force linear on each piece
    ``(a, b, F_a, F_b)`` (sorted, disjoint) and 0 elsewhere.  On a piece, with ``s = (F_b - F_a)/(b - a)`` and
    ``tau = t - a``:  ``v = v_a + (F_a tau + s tau^2/2) / m``,  ``x = x_a + v_a tau + (F_a tau^2/2 + s tau^3/6) / m``;
    between pieces the velocity is constant."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    x, v = v_start * t, np.full_like(t, v_start)
    for a, b, fa, fb in pieces:
        s = (fb - fa) / (b - a)
        tau = np.clip(t - a, 0.0, b - a)          # time spent in the piece so far
        after = np.maximum(t - b, 0.0)            # time since the piece ended
        dv_tau = (fa * tau + s * tau ** 2 / 2) / mass
        dx_tau = (fa * tau ** 2 / 2 + s * tau ** 3 / 6) / mass
        x, v = x + dx_tau + dv_tau * after, v + dv_tau
    return x, v


def free_barrel(**tables) -> Scene:
    """The barrel alone (no spring, no damper, no absorber): a free mass M."""
    return Scene(barrel=Barrel(M), **tables)


def pulse(**fields) -> Pulse:
    return Pulse(times=TIMES, forces=FORCES, **fields)


# ------------------------------------------------------------------ the momentum of a shot
def test_the_gas_after_effect_adds_the_charge_momentum():
    """``v0 = (m_p v_p + m_c v_g) / M``; with v0_includes_absorber over M + m; a free barrel moves at v0."""
    firing = Firing(6.86, 564.0, charge_mass=5.5, gas_velocity=1400.0)
    expected = (6.86 * 564.0 + 5.5 * 1400.0) / M
    assert build_model(free_barrel(firing=firing)).bodies[0].initial_velocity == pytest.approx(expected, rel=1e-15)
    assert expected > 1.5 * V0  # the charge's share is not negligible: the check can tell the two apart
    including = model_i(500.0, 0.0).with_changes(firing=firing, conventions=Conventions(v0_includes_absorber=True))
    assert build_model(including).bodies[0].initial_velocity == pytest.approx(expected * M / (M + 500.0), rel=1e-15)
    r = solve_reference(free_barrel(firing=firing), 1.0)
    t = np.linspace(0.0, 1.0, 11)
    np.testing.assert_allclose(r.barrel_position(t), expected * t, rtol=1e-12, atol=1e-15)
    # a burst's later shots add the same v0, gas included
    burst = solve_reference(free_barrel(firing=firing, burst=Burst(3, 0.2)), 0.5)
    assert burst.barrel_velocity(0.5) == pytest.approx(3 * expected, rel=1e-14)


def test_a_pulse_starts_the_barrel_at_rest():
    scene = free_barrel(firing=Firing(6.86, 564.0, charge_mass=5.5, gas_velocity=1400.0, pulse=pulse()))
    model = build_model(scene)
    assert model.bodies[0].initial_velocity == 0.0
    assert [load.name for load in model.loads] == ["breech_force"]
    assert model.shot_times is None  # one shot: no per-shot outputs without a burst


# ------------------------------------------------------------------ a pulse on a free mass
def test_a_pulse_on_a_free_mass_is_the_double_integral_of_the_force():
    r = solve_reference(free_barrel(firing=Firing(6.86, 564.0, pulse=pulse())), 0.05)
    t = np.unique(np.concatenate((np.linspace(0.0, 0.05, 2001), TIMES)))
    x, v = free_mass(pulse_pieces(), M, t)
    np.testing.assert_allclose(r.barrel_position(t), x, rtol=1e-11, atol=1e-16)
    np.testing.assert_allclose(r.barrel_velocity(t), v, rtol=1e-11, atol=1e-16)
    assert v[-1] == pytest.approx(IMPULSE / M, rel=1e-14)  # the closed form's own consistency
    assert r.pulse_impulse == pytest.approx(IMPULSE, rel=1e-14)
    metrics = r.metrics()
    assert r.shots is None and "shots" not in metrics and metrics["pulse_impulse"] == r.pulse_impulse
    assert metrics["work"] == r.work and set(r.work) == {"breech_force"}
    # the force: 0 before the pulse, jumps onto it, linear between the points, 0 after it
    np.testing.assert_allclose(r.load_force("breech_force", [0.0, 0.0009, 0.001, 0.002, 0.0085, 0.010, 0.02]),
                               [0.0, 0.0, 5.0e5, 1.25e6, 0.5 * (6.0e5 + 1.0e5), 0.0, 0.0], rtol=1e-12, atol=1e-6)
    # every table point is a segment boundary: each segment integrates one piece of the law
    assert set(TIMES) <= {seg.t0 for seg in r.segments}


def test_the_work_of_a_pulse_closes_the_energy_balance():
    """A free mass from rest: the work of the force is its kinetic energy, ``W = M v^2 / 2``, and
    kinetic - work stays at the initial energy 0."""
    r = solve_reference(free_barrel(firing=Firing(6.86, 564.0, pulse=pulse())), 0.05)
    t = np.linspace(0.0, 0.05, 501)
    _, v = free_mass(pulse_pieces(), M, t)
    np.testing.assert_allclose(r.work_history(t)["breech_force"], 0.5 * M * v ** 2, rtol=1e-10, atol=1e-9)
    assert r.initial_energy == 0.0
    assert np.max(np.abs(r.energy_balance(t))) < 1e-10 * 0.5 * M * v[-1] ** 2
    assert r.work["breech_force"] == pytest.approx(0.5 * IMPULSE ** 2 / M, rel=1e-10)


def test_a_pulse_scaled_to_the_momentum_gives_v0():
    firing = Firing(6.86, 564.0, charge_mass=5.5, gas_velocity=1400.0, pulse=pulse(scale_to_momentum=True))
    r = solve_reference(free_barrel(firing=firing), 0.05)
    momentum = 6.86 * 564.0 + 5.5 * 1400.0
    assert r.pulse_impulse == pytest.approx(momentum, rel=1e-14)
    t = np.linspace(0.0, 0.05, 201)
    x, v = free_mass(pulse_pieces(scale=momentum / IMPULSE), M, t)
    np.testing.assert_allclose(r.barrel_position(t), x, rtol=1e-11, atol=1e-16)
    assert r.barrel_velocity(0.05) == pytest.approx(momentum / M, rel=1e-12)


def test_the_load_enters_the_right_hand_side_and_a_sliding_contact_sees_it():
    """``M a = -k x - c v + F(t)`` and ``dW/dt = F v`` in the simplified model with a pulse, on floats and
    on numpy rows; in the compression-only sliding mode the contact's constraint holds ``p'' = 0`` with the
    load (the load is added before the constraint force)."""
    scene = simplified_model().with_changes(firing=Firing(6.86, 564.0, pulse=pulse()))
    model = build_model(scene)
    rng = np.random.default_rng(5)
    for a, b, fa, fb in pulse_pieces():
        t = a + (b - a) * rng.uniform(0.05, 0.95, size=6)
        force = fa + (fb - fa) * (t - a) / (b - a)
        y = np.array([rng.normal(0.0, 0.05, 6), rng.uniform(0.01, 1.0, 6), rng.uniform(0, 10, 6), rng.normal(0, 10, 6)])
        mode = Mode(model.names, (None, True), model.load_pieces(float(a)))
        for j in range(6):
            dy = model.rhs(mode)(float(t[j]), y[:, j])
            expected = (-K * y[0, j] - C_RECOIL * y[1, j] + force[j]) / M
            np.testing.assert_allclose(dy, [y[1, j], expected, C_RECOIL * y[1, j] ** 2, force[j] * y[1, j]], rtol=1e-12)
        np.testing.assert_allclose(model.evaluate(mode, y, t=t).accelerations[0],
                                   (-K * y[0] - C_RECOIL * y[1] + force) / M, rtol=1e-12)
    sticky = model_i(500.0, 0.0).with_changes(firing=Firing(6.86, 564.0, pulse=pulse()),
                                             conventions=Conventions(compression_only=True))
    model = build_model(sticky)
    t = 0.005
    mode = Mode(model.names, (None, True, None, ContactMode("stick", True, False, 0.6, 0.3)), model.load_pieces(t))
    y = np.array([0.02, 0.3, 0.01, 0.3, 0.0, 0.0, 0.0, 0.0])[:model.n_states]  # p = 0.01 > 0, p' = 0
    contact = model.connector("contact")
    assert model.relative_acceleration(contact, model.evaluate(mode, y, t=t)) == pytest.approx(0.0, abs=1e-9)
    free = model.evaluate(Mode(model.names, mode.states, ()), y, t=t)  # the whole law at t: the same force
    assert free.forces == pytest.approx(model.evaluate(mode, y, t=t).forces, rel=1e-12)


def test_a_scene_without_inputs_keeps_the_code_of_version_1():
    """No time events, no work states, ``evaluate(y)`` without time: the paper's scenes run as before."""
    for scene in (simplified_model(), model_i(500.0, 0.04), model_ii(1000.0, 0.0)):
        model = build_model(scene)
        assert model.time_events == () and model.work_slot == {} and model.last_input_time == 0.0
        assert model.n_states == 2 * model.n_bodies + len(model.dissipating)
        mode = Restart(model, 0.0, model.initial_state(), {}, None).mode
        assert mode.loads == ()
        assert "def evaluate(y):" in source(model, mode, "array") and "L0" not in source(model, mode, "rhs")


# ------------------------------------------------------------------ bursts on a free mass
def test_a_burst_of_impulses_on_a_free_mass_is_piecewise_linear():
    """Shots every 0.3 s: ``v = n(t) v0`` (n shots fired by t), ``x = v0 sum_{t_j <= t} (t - t_j)``; the jumps'
    work ``M v0^2 (n^2 - 1) / 2``; each shot's window rises to its end; never back in battery."""
    interval, shots, end = 0.3, 4, 1.2
    r = solve_reference(free_barrel(firing=Firing(6.86, 564.0), burst=Burst(shots, interval)), end)
    shot_times = [k * interval for k in range(shots)]
    t = np.unique(np.concatenate((np.linspace(0.0, end, 1201), shot_times)))
    fired = sum((t >= s).astype(float) for s in shot_times)
    x = V0 * sum(np.maximum(t - s, 0.0) for s in shot_times)
    np.testing.assert_allclose(r.barrel_position(t), x, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(r.barrel_velocity(t), V0 * fired, rtol=1e-12)  # after the jump at a shot time
    np.testing.assert_allclose(r.work_history(t)["burst"], 0.5 * M * V0 ** 2 * (fired ** 2 - 1), rtol=1e-11,
                               atol=1e-9)
    assert np.max(np.abs(r.energy_balance(t) - r.initial_energy)) < 1e-11 * 0.5 * M * (shots * V0) ** 2
    assert [s["time"] for s in r.shots] == pytest.approx(shot_times)
    assert [s["shot"] for s in r.shots] == [1, 2, 3, 4]
    for k, shot in enumerate(r.shots):
        last = k == shots - 1
        t_next = end if last else shot_times[k + 1]
        x_next = V0 * sum(t_next - s for s in shot_times[:k + 1])
        assert shot["max_barrel_displacement"] == pytest.approx(x_next, rel=1e-12)
        assert shot["time_of_max_barrel_displacement"] == pytest.approx(t_next, abs=1e-15)
        assert shot["time_to_battery"] is None
        if last:
            assert shot["position_at_next_shot"] is None and shot["in_battery_at_next_shot"] is None
        else:
            assert shot["position_at_next_shot"] == pytest.approx(x_next, rel=1e-12)
            assert shot["velocity_at_next_shot"] == pytest.approx((k + 1) * V0, rel=1e-12)  # before the jump
            assert shot["in_battery_at_next_shot"] is False


def test_shots_after_the_end_time_do_not_fire():
    r = solve_reference(free_barrel(firing=Firing(6.86, 564.0), burst=Burst(4, 0.3)), 0.5)
    assert [s["time"] for s in r.shots] == [0.0, 0.3]
    assert r.barrel_velocity(0.5) == pytest.approx(2 * V0, rel=1e-14)


def test_a_burst_of_pulses_on_a_free_mass_superposes_the_shifted_pulses():
    interval, shots, end = 0.02, 3, 0.08
    scene = free_barrel(firing=Firing(6.86, 564.0, pulse=pulse()), burst=Burst(shots, interval))
    r = solve_reference(scene, end)
    pieces = [p for k in range(shots) for p in pulse_pieces(shift=k * interval)]
    t = np.linspace(0.0, end, 1601)
    x, v = free_mass(pieces, M, t)
    np.testing.assert_allclose(r.barrel_position(t), x, rtol=1e-11, atol=1e-16)
    np.testing.assert_allclose(r.barrel_velocity(t), v, rtol=1e-11, atol=1e-16)
    np.testing.assert_allclose(r.work_history(t)["breech_force"], 0.5 * M * v ** 2, rtol=1e-10, atol=1e-9)
    assert r.pulse_impulse == pytest.approx(IMPULSE, rel=1e-13)
    assert r.metrics()["pulse_impulse"] == r.pulse_impulse and len(r.metrics()["shots"]) == shots
    breakpoints = {k * interval + s for k in range(shots) for s in TIMES} | {k * interval for k in range(1, shots)}
    assert breakpoints <= {seg.t0 for seg in r.segments}
    assert "burst" not in r.work  # the pulse repeats: no velocity jumps


# ------------------------------------------------------------------ a burst on the paper's simplified model
INTERVAL = 2.5


@pytest.fixture(scope="module")
def single():
    """The simplified model's one shot, to the first later shot's time."""
    return solve_reference(simplified_model(), INTERVAL)


@pytest.fixture(scope="module")
def burst():
    return solve_reference(simplified_model().with_changes(burst=Burst(3, INTERVAL)), 8.0)


def first_return(result, t_from: float, t_to: float, level: float = 1e-3) -> float:
    """First time after ``t_from`` at which x_M falls to ``level``, from samples every 10 us, interpolated."""
    t = np.arange(t_from, t_to, 1e-5)
    x = result.barrel_position(t)
    i = int(np.argmax(x <= level))
    assert x[i] <= level < x[i - 1]
    return t[i - 1] + (x[i - 1] - level) / (x[i - 1] - x[i]) * (t[i] - t[i - 1])


def test_the_first_shot_of_a_burst_is_the_single_shot(single, burst):
    first = burst.shots[0]
    assert first["max_barrel_displacement"] == pytest.approx(single.max_barrel_displacement, rel=1e-10)
    assert first["time_of_max_barrel_displacement"] == pytest.approx(single.time_of_max_barrel_displacement, abs=1e-9)
    assert first["position_at_next_shot"] == pytest.approx(float(single.barrel_position(INTERVAL)), rel=1e-8)
    assert first["velocity_at_next_shot"] == pytest.approx(float(single.barrel_velocity(INTERVAL)), rel=1e-8)
    assert first["in_battery_at_next_shot"] == (abs(float(single.barrel_position(INTERVAL))) <= 1e-3)
    back = first_return(single, single.time_of_max_barrel_displacement, INTERVAL)
    assert first["time_to_battery"] == pytest.approx(back, abs=1e-8)


def test_each_later_shot_adds_v0_and_recoils_alike(burst):
    for k, shot in enumerate(burst.shots):
        assert shot["time"] == k * INTERVAL and shot["shot"] == k + 1
        assert INTERVAL * k < shot["time_of_max_barrel_displacement"] < INTERVAL * k + 1.0
        # a shot fired near battery (a residual of a few cm and cm/s) recoils about as far as the first
        assert shot["max_barrel_displacement"] == pytest.approx(burst.shots[0]["max_barrel_displacement"], rel=0.05)
        assert 0.0 < shot["time_to_battery"] < INTERVAL
        if k:
            before = burst.shots[k - 1]
            after = float(burst.barrel_velocity(shot["time"]))  # the state after the jump
            assert after - before["velocity_at_next_shot"] == pytest.approx(V0, rel=1e-12)
            assert float(burst.barrel_position(shot["time"])) == pytest.approx(before["position_at_next_shot"], rel=1e-12)
    assert burst.max_barrel_displacement == max(s["max_barrel_displacement"] for s in burst.shots)
    t = np.linspace(0.0, 8.0, 8001)
    work = burst.work_history(t)["burst"]
    assert np.max(np.abs(burst.energy_balance(t) - burst.initial_energy)) < 1e-8 * (burst.initial_energy + work[-1])


def test_a_shot_fired_out_of_battery_recoils_further():
    """Shots 0.5 s apart: the barrel is still recoiling (max of the first shot at ~0.61 s) when the second
    fires, so it is out of battery, the first window's maximum is its end and the second shot goes further."""
    single = solve_reference(simplified_model(), 2.0)
    r = solve_reference(simplified_model().with_changes(burst=Burst(2, 0.5)), 2.0)
    first, second = r.shots
    assert first["in_battery_at_next_shot"] is False and first["position_at_next_shot"] > 0.1
    assert first["time_of_max_barrel_displacement"] == 0.5 and first["time_to_battery"] is None
    assert second["max_barrel_displacement"] > 1.5 * single.max_barrel_displacement


# ------------------------------------------------------------------ a short pulse tends to the initial velocity
def triangle(duration: float) -> Pulse:
    """A triangular pulse 0 -> peak at duration/3 -> 0 at ``duration``, scaled to the shot's momentum."""
    return Pulse(times=(0.0, duration / 3, duration), forces=(0.0, 1.0e6, 0.0), scale_to_momentum=True)


def test_a_short_pulse_converges_to_the_initial_velocity_with_order_two():
    """Duhamel: up to the maximum the simplified model is linear (recoil damping, v > 0), so the pulse's
    response is the initial-velocity response X averaged over the pulse's time distribution w = F / I
    (mean t_c, variance s^2):  ``x_p(t) = E_w[X(t - sigma)] = X(t - t_c) + X''(t - t_c) s^2 / 2 + O(tau^3)``.

    * the maximum moves by ``X''(t*) s^2 / 2 = -(k x_max / M) s^2 / 2``: second order in the duration tau
      (the first-order effect, the delay t_c, does not change the maximum);
    * its time by ``t_c + (c / M) s^2 / 2`` (``V'' = -(c/M) V'`` at v = 0);
    * the position at a fixed time by ``-V(t) t_c``: first order.

    Triangle (0, tau/3, tau): ``t_c = 4 tau / 9``, ``s^2 = 7 tau^2 / 162``.
    """
    reference = solve_reference(simplified_model(), 1.5)
    x_max, t_star = reference.max_barrel_displacement, reference.time_of_max_barrel_displacement
    taus = np.array([0.008, 0.004, 0.002, 0.001])
    dx, dt, dp = [], [], []
    for tau in taus:
        r = solve_reference(simplified_model().with_changes(firing=Firing(6.86, 564.0, pulse=triangle(tau))), 1.5)
        dx.append(r.max_barrel_displacement - x_max)
        dt.append(r.time_of_max_barrel_displacement - t_star)
        dp.append(float(r.barrel_position(0.3) - reference.barrel_position(0.3)))
    dx, dt, dp = map(np.array, (dx, dt, dp))
    variance, centroid = 7 * taus ** 2 / 162, 4 * taus / 9
    order_max = np.log2(np.abs(dx[:-1] / dx[1:]))
    order_position = np.log2(np.abs(dp[:-1] / dp[1:]))
    assert np.all(np.abs(order_max - 2.0) < 0.01), order_max
    assert np.all(np.abs(order_position - 1.0) < 0.02), order_position
    np.testing.assert_allclose(dx, -(K * x_max / M) * variance / 2, rtol=2e-3)
    np.testing.assert_allclose(dt - centroid, (C_RECOIL / M) * variance / 2, rtol=2e-3)
    np.testing.assert_allclose(dp, -float(reference.barrel_velocity(0.3)) * centroid, rtol=2e-2)


# ------------------------------------------------------------------ early stop
@pytest.mark.parametrize("firing, interval", [(Firing(6.86, 564.0), 8.0), (Firing(6.86, 564.0, pulse=triangle(0.01)), 3.0)],
                         ids=["impulses", "pulses"])
def test_an_early_stop_equals_the_full_run_and_waits_for_the_last_shot(firing, interval):
    """After one shot the energy bounds prove the maximum final at once (at the maximum all the energy is in
    the spring), so a stop that ignored the later shots would end long before them."""
    scene = simplified_model().with_changes(firing=firing, burst=Burst(2, interval))
    full = solve_reference(scene, 3 * interval)
    stopped = solve_reference(scene, 3 * interval, stop_when_final=METRICS)
    last_input = interval + (0.01 if firing.pulse is not None else 0.0)
    assert stopped.stop_reason == "metrics_final" and last_input < stopped.end_time < 3 * interval
    for name in ("max_barrel_displacement", "time_of_max_barrel_displacement", "peak_support_force",
                 "time_of_peak_support_force"):
        assert getattr(stopped, name) == pytest.approx(getattr(full, name), rel=1e-12, abs=1e-15), name
    for key, value in full.shots[0].items():
        assert stopped.shots[0][key] == (value if value is None or isinstance(value, bool) else
                                         pytest.approx(value, rel=1e-12)), key
    single = solve_reference(simplified_model().with_changes(firing=firing), 3 * interval, stop_when_final=METRICS)
    assert single.end_time < interval  # the stop the later shot must prevent


def with_load(scene, value: float):
    """``scene`` with an extra table whose test term adds a constant load ``value`` (N) on the barrel."""
    return SimpleNamespace(name="loaded", conventions=scene.conventions, absorbers=scene.absorbers,
                           absorber_names=scene.absorber_names, barrel=scene.barrel, firing=scene.firing, burst=None,
                           tables=lambda: scene.tables() + [("constant_load", SimpleNamespace(value=value))])


@pytest.fixture
def constant_load_term(monkeypatch):
    def build(builder, key, table):
        builder.add_load(ConstantLoad("gravity", "barrel", table.value))
    monkeypatch.setitem(TERMS, "constant_load", SimpleNamespace(TABLES=("constant_load",), build=build))


def test_a_constant_load_on_a_free_mass(constant_load_term):
    """``x = v0 t + F t^2 / (2M)``, the work ``F x``; a load that never ends leaves no energy bound."""
    force = -3000.0
    r = solve_reference(with_load(free_barrel(firing=Firing(6.86, 564.0)), force), 1.0, stop_when_final=METRICS)
    assert r.stop_reason == "end_time_no_energy_bound" and r.end_time == 1.0
    t = np.linspace(0.0, 1.0, 101)
    x = V0 * t + force * t ** 2 / (2 * M)
    np.testing.assert_allclose(r.barrel_position(t), x, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(r.work_history(t)["gravity"], force * x, rtol=1e-10, atol=1e-10)
    assert np.max(np.abs(r.energy_balance(t) - r.initial_energy)) < 1e-10 * r.initial_energy
    assert r.support_force(0.5) == 0.0  # not transmitted to the mount


def test_a_constant_load_leaves_the_paper_model_without_a_bound(constant_load_term):
    r = solve_reference(with_load(simplified_model(), -0.5 * M * 9.81 * math.sin(0.3)), 3.0,
                        stop_when_final=("max_barrel_displacement",))
    assert r.stop_reason == "end_time_no_energy_bound" and r.end_time == 3.0
    assert r.max_barrel_displacement < solve_reference(simplified_model(), 3.0).max_barrel_displacement
