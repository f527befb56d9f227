"""Stop at rest (mbs_models.engine.rest, simulate(stop_at_rest=...)).

The held rest state must be within the claimed tolerance of the solution for all later time (checked
against the engine's own integration to the end time and against the independent reference), the run's
samples must stop growing with the end time once it rests, and the rest stop must never trigger while an
input is pending, under a load that never ends, with friction, or in a scene that never comes to rest.
Thresholds are checked against hand calculations from the scene's numbers.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from mbs_models import (Burst, Conventions, RecoilSpring, SceneError, SolverSettings, load_scene, model_i, model_ii,
                        simplified_model, simulate)
from mbs_models.engine import final_metrics as fm
from mbs_models.engine.accuracy import ACCURACY_PRESETS
from mbs_models.engine.energy_bounds import EnergyBounds
from mbs_models.engine.mechanism import Mechanism
from mbs_models.engine.reuse import Simulator
from mbs_models.engine.rest import CHECK_INTERVAL, RIEMANN_PIECES, RestState, RestWatch, well_energy
from mbs_models.scenes import list_scenes, scene_path
from validation.reference import solve_reference

TOLERANCE = ACCURACY_PRESETS["standard"].absolute_tolerance  # m and m/s: what a standard run proves
RECUPERATOR = load_scene(scene_path("recuperator"))
#: a shipped scene whose rest can be proven but whose quadratic damping decays algebraically: never at rest
WEAKLY_DAMPED = "recoil_brake"
#: the shipped scenes that come to rest (the others have gravity on an inclined cradle)
RESTING = sorted(name for name in list_scenes() if name != WEAKLY_DAMPED
                 and RestState.of(Mechanism(load_scene(scene_path(name))), TOLERANCE) is not None)
_RUNS: dict[tuple, object] = {}


def run(name: str, end_time: float, **options):
    """A shipped scene's run (cached: several tests look at the same one)."""
    key = (name, end_time, tuple(sorted(options.items())))
    if key not in _RUNS:
        _RUNS[key] = simulate(load_scene(scene_path(name)), end_time, **options)
    return _RUNS[key]


# ------------------------------------------------------------------ the held state against the solution
@pytest.mark.parametrize("name", RESTING)
def test_the_held_rest_state_is_within_the_tolerance_of_the_full_integration(name):
    """Every position and velocity of the integration to 200 s, from the rest time on, is within the tolerance
    of the held state.  The proof covers the scene's equations from the state at the rest time; the full
    integration adds its own error, a relative 1e-9 (rtol) of a solution this small: 1e-3 of margin."""
    held, full = run(name, 200.0), run(name, 200.0, stop_at_rest=False)
    assert held.stop_reason == fm.STOP_AT_REST and full.stop_reason == fm.STOP_END_TIME
    assert held.end_time == held.requested_end_time == 200.0 and held.time[-1] == 200.0
    assert held.rest_tolerance == TOLERANCE and held.rest_time < CHECK_INTERVAL
    after = full.time >= held.rest_time
    for body in full.positions:
        assert np.all(held.velocities[body][-2:] == 0.0) and np.all(held.accelerations[body][-2:] == 0.0)
        rest = held.positions[body][-1]
        assert np.max(np.abs(full.positions[body][after] - rest)) <= TOLERANCE * 1.001, body
        assert np.max(np.abs(full.velocities[body][after])) <= TOLERANCE * 1.001, body
    # the metrics are the full run's (their maxima come long before the rest)
    for metric in ("max_barrel_displacement", "peak_support_force", "peak_contact_force", "max_absorber_velocity"):
        a, b = getattr(held, metric), getattr(full, metric)
        assert (a is None and b is None) or a == pytest.approx(b, rel=1e-9, abs=1e-12), metric
    assert (held.impacts is None) == (full.impacts is None)
    if held.impacts is not None:
        assert [i.contact for i in held.impacts] == [i.contact for i in full.impacts]
        assert [i.peak_force for i in held.impacts] == pytest.approx([i.peak_force for i in full.impacts], rel=1e-9)


@pytest.mark.parametrize("name", ["model_i", "model_ii", "simplified", "recuperator", "two_absorbers"])
def test_up_to_the_rest_time_a_run_is_the_run_without_the_stop(name):
    """Without shots or pulses, the first chunk of a long run is the solve of a 100-s run: the samples up to the
    rest time are those of the full integration, bit for bit."""
    held, full = run(name, 200.0), run(name, 200.0, stop_at_rest=False)
    n = len(held.time) - 2  # the integrated samples
    assert held.time[n - 1] == held.rest_time
    assert np.array_equal(held.time[:n], full.time[:n])
    for body in full.positions:
        for histories in ("positions", "velocities", "accelerations"):
            assert np.array_equal(getattr(held, histories)[body][:n], getattr(full, histories)[body][:n])
    for name_, contact in full.contacts.items():
        assert np.array_equal(held.contacts[name_].force[:n], contact.force[:n])


def test_the_energy_balance_still_closes_with_the_held_tail():
    """The held tail drops the kinetic energy left at the rest time (below the threshold) and moves stored
    energy between connectors by at most their force at rest times the tolerance."""
    held = run("recuperator", 200.0)
    scale = held.kinetic_energy_history[0]
    assert np.max(np.abs(held.energy_error())) < 1e-6 * scale
    preload = RECUPERATOR.recuperator.initial_pressure * RECUPERATOR.recuperator.piston_area  # N
    jump = abs(held.energy_error()[-1] - held.energy_error()[-3])
    assert jump <= 4.0 * preload * TOLERANCE  # (the gas spring's and the stop's forces, on both sides)


REFERENCE_CASES = [
    pytest.param("i-gap50mm", model_i(1000.0, 0.05), id="i-gap50mm"),
    pytest.param("simplified", simplified_model(), id="simplified", marks=pytest.mark.slow),
    pytest.param("recuperator", RECUPERATOR, id="recuperator", marks=pytest.mark.slow),
]


@pytest.mark.parametrize("name, scene", REFERENCE_CASES)
def test_the_reference_stays_within_the_claimed_bound_of_the_held_state(name, scene):
    """The independent reference (DOP853, rtol 1e-10, atol 1e-12) from the engine's rest time to 120 s stays
    within the claimed tolerance of the engine's held state: the rest is a property of the equations, not of
    the engine's integration.  (A contact that closes during the recoil and is open at rest: the reference
    would chatter on a gap-0 contact at rest.)"""
    held = simulate(scene, 200.0)
    assert held.stop_reason == fm.STOP_AT_REST
    reference = solve_reference(scene, 120.0)
    times = np.linspace(held.rest_time, reference.end_time, 20001)
    for body in held.positions:
        assert np.max(np.abs(reference.position(body, times) - held.positions[body][-1])) <= held.rest_tolerance
        assert np.max(np.abs(reference.velocity(body, times))) <= held.rest_tolerance


# ------------------------------------------------------------------ memory and time do not grow with the end time
def test_the_samples_do_not_grow_with_the_end_time_once_at_rest():
    short, long = simulate(model_i(1000.0, 0.0), 200.0), simulate(model_i(1000.0, 0.0), 1000.0)
    assert short.stop_reason == long.stop_reason == fm.STOP_AT_REST
    assert len(short.time) == len(long.time) and short.steps == long.steps and short.rest_time == long.rest_time
    assert np.array_equal(short.time[:-1], long.time[:-1]) and long.time[-1] == 1000.0
    assert np.array_equal(short.barrel_position, long.barrel_position)


@pytest.mark.parametrize("scene", [
    simplified_model().with_changes(**{"recoil_damper.recoil": 0.0, "recoil_damper.counter_recoil": 0.0}),
    load_scene(scene_path(WEAKLY_DAMPED))], ids=["undamped", "quadratic-brake"])
def test_a_scene_that_never_rests_keeps_every_sample(scene):
    """No damping at all (the energy never falls), or a quadratic brake alone (``M v' = -K v |v|``: the energy
    decays algebraically, never to 1e-19 J in 300 s): rest is never proven and the histories grow with the end
    time (memory grows with the histories asked for)."""
    assert RestState.of(Mechanism(scene), TOLERANCE) is not None  # it could rest, it just never does
    short, long = simulate(scene, 150.0, "draft"), simulate(scene, 300.0, "draft")
    assert short.stop_reason == long.stop_reason == fm.STOP_END_TIME and short.rest_time is None
    assert len(long.time) > 1.9 * len(short.time)


def test_a_run_no_longer_than_the_check_interval_is_integrated_in_full():
    result = simulate(model_i(1000.0, 0.0), CHECK_INTERVAL)
    assert result.stop_reason == fm.STOP_END_TIME and result.rest_time is None and result.time[-1] == CHECK_INTERVAL


def test_stop_at_rest_false_integrates_to_the_end():
    result = run("model_i", 200.0, stop_at_rest=False)
    assert result.stop_reason == fm.STOP_END_TIME and result.rest_time is None
    assert "rest_time" not in result.metrics()


def test_a_fixed_step_solver_is_never_stopped_at_rest():
    result = simulate(simplified_model(), 150.0, SolverSettings(solver="RK44", step=1e-2))
    assert result.stop_reason == fm.STOP_END_TIME and result.rest_time is None


# ------------------------------------------------------------------ no rest while an input is pending or never ending
def test_a_late_shot_of_a_burst_is_fired_before_any_rest():
    """Shots at 0 and 120 s: the mechanism is at rest long before the second shot, which must still fire; the
    rest comes after it, and the second shot, fired at rest, recoils as the first."""
    scene = load_scene(scene_path("burst")).with_changes(**{"burst.shots": 2, "burst.interval": 120.0})
    result = simulate(scene, 300.0)
    assert result.stop_reason == fm.STOP_AT_REST and result.rest_time > 120.0
    first, second = result.shots
    assert second["time"] == 120.0
    assert second["max_barrel_displacement"] == pytest.approx(first["max_barrel_displacement"], rel=1e-6)


def test_a_late_pulse_is_applied_before_any_rest():
    """The breech pulse repeated at 150 s: no rest before the end of the second pulse; fired at rest both times,
    the two pulses do the same work."""
    scene = load_scene(scene_path("breech_pulse")).with_changes(burst=Burst(shots=2, interval=150.0))
    result = simulate(scene, 400.0)
    pulse_end = Mechanism(scene).last_input_time
    assert 150.0 < pulse_end < 151.0
    assert result.stop_reason == fm.STOP_AT_REST and result.rest_time > pulse_end
    before_second = result.work_history[np.searchsorted(result.time, 100.0)]
    assert result.work_history[-1] == pytest.approx(2.0 * before_second, rel=1e-6)


def test_a_shot_after_the_end_time_keeps_the_run_going():
    """The bounds hold only after the last input, even one beyond the window: no rest stop then."""
    scene = load_scene(scene_path("burst")).with_changes(**{"burst.shots": 2, "burst.interval": 150.0})
    result = simulate(scene, 140.0, "draft")
    assert result.stop_reason == fm.STOP_END_TIME and result.time[-1] == 140.0


@pytest.mark.parametrize("scene", [load_scene(scene_path("cradle")), load_scene(scene_path("realistic")),
                                   load_scene(scene_path("cradle")).with_changes(**{"cradle.elevation": 0.0}),
                                   model_ii(1000.0, 0.04, Conventions(literal_lambda_sign=True))],
                         ids=["gravity", "realistic", "level-friction", "literal-lambda"])
def test_no_rest_under_a_never_ending_load_friction_or_injected_energy(scene):
    assert RestState.of(Mechanism(scene), TOLERANCE) is None


def test_the_cradle_runs_to_its_end_time():
    result = simulate(load_scene(scene_path("cradle")), 120.0, "draft")
    assert result.stop_reason == fm.STOP_END_TIME and result.time[-1] == 120.0


@pytest.mark.parametrize("scene", [
    model_ii(1000.0, 0.0).with_changes(**{"absorber.stiffness": 0.0}),  # nothing holds the absorber's position
    RECUPERATOR.with_changes(recoil_spring=RecoilSpring(stiffness=27500.0)),  # rest is not the well's minimum
    model_ii(1000.0, 0.001, Conventions(literal_gap_sign=True)),  # the contact closed at x = 0
], ids=["free-absorber", "recuperator-and-spring", "interference"])
def test_no_rest_state_where_the_bounds_cannot_reach_it(scene):
    assert RestState.of(Mechanism(scene), TOLERANCE) is None


# ------------------------------------------------------------------ the early-stop paths
def test_stop_when_final_still_stops_first(assert_results_identical):
    """The early stop comes long before any rest, exactly where it comes in a 10-s run."""
    result = simulate(model_i(1000.0, 0.0), 200.0, stop_when_final=fm.FINAL_METRICS)
    ten = simulate(model_i(1000.0, 0.0), 10.0, stop_when_final=fm.FINAL_METRICS)
    assert result.stop_reason == fm.STOP_METRICS_FINAL and result.rest_time is None
    assert result.requested_end_time == 200.0
    assert_results_identical(result, dataclasses.replace(ten, requested_end_time=200.0))


def test_a_metric_never_final_stops_at_rest_with_the_full_runs_values():
    """The recuperator's preload keeps its battery stop's episode going: ``impacts`` is never final, so the
    early stop runs on, until rest; the stop's impacts are then the full run's."""
    held = simulate(RECUPERATOR, 200.0, stop_when_final=("impacts",))
    full = run("recuperator", 200.0, stop_at_rest=False)
    assert held.stop_reason == fm.STOP_AT_REST and held.final_metrics == fm.FINAL_METRICS
    (stop,), (expected,) = held.stops(), full.stops()
    assert [(i["start"], i["peak_force"]) for i in stop["impacts"]] == \
        [(i["start"], i["peak_force"]) for i in expected["impacts"]]
    assert stop["impacts"][-1]["end"] == expected["impacts"][-1]["end"] == 200.0  # still pressed at the end


def test_the_simulator_gives_the_same_result_bit_for_bit(assert_results_identical):
    with Simulator() as simulator:
        kept = [simulator.simulate(model_i(1000.0, gap), 200.0) for gap in (0.0, 0.0)]
    assert kept[0].stop_reason == fm.STOP_AT_REST
    assert_results_identical(kept[1], simulate(model_i(1000.0, 0.0), 200.0))


def test_stop_at_rest_must_be_a_bool():
    with pytest.raises(SceneError, match="stop_at_rest"):
        simulate(model_i(), 1.0, stop_at_rest="yes")


# ------------------------------------------------------------------ the rest state and its threshold
def test_threshold_of_one_body_on_a_spring():
    """|v| <= sqrt(2E/M) and |x| <= sqrt(2E/k): the threshold is min(M, k) tol^2 / 2."""
    state = RestState.of(Mechanism(simplified_model()), 1e-8)
    assert state.positions == (0.0,)
    assert state.threshold == pytest.approx(0.5 * min(5600.0, 27500.0) * 1e-16, rel=1e-12)


def test_threshold_of_an_absorber_on_a_weak_spring():
    """Model (i) with k_r = 10 N/m: ``x^T K x <= 2E`` with K = [[k + k_r, -k_r], [-k_r, k_r]] bounds the absorber by
    ``sqrt(2E (K^-1)_11)``, (K^-1)_11 = (k + k_r) / (k k_r): the threshold is tol^2 k k_r / (2 (k + k_r)), below
    both bodies' velocity thresholds."""
    k, k_r = 27500.0, 10.0
    state = RestState.of(Mechanism(model_i(1000.0, 0.0).with_changes(**{"absorber.stiffness": k_r})), 1e-8)
    assert state.positions == (0.0, 0.0)
    assert state.threshold == pytest.approx(1e-16 * k * k_r / (2.0 * (k + k_r)), rel=1e-9)


def _recuperator_rest():
    """``(x*, kappa, net)``: x* from the static balance written out, ``p0 A (V0 / (V0 - A x))^n = k_s (0 - x)`` (the
    Kelvin-Voigt stop at rest); ``kappa`` (N/m) the well's stiffness there, the stop's plus the gas spring's
    tangent; ``net(s)`` (N) the gas spring's force less the stop's at s, as the residual at x* plus the changes
    from x* (written with expm1/log1p: no cancellation of the 2-kN forces)."""
    rec, stop = RECUPERATOR.recuperator, RECUPERATOR.battery_stop
    p0, area, volume, n = rec.initial_pressure, rec.piston_area, rec.gas_volume, rec.polytropic_exponent

    def gas(x):
        return p0 * area * (volume / (volume - area * x)) ** n

    x_rest = brentq(lambda x: gas(x) - stop.stiffness * (stop.position - x), -1.0, 0.0, xtol=1e-18)
    tangent = n * gas(x_rest) * area / (volume - area * x_rest)
    residual = gas(x_rest) - stop.stiffness * (stop.position - x_rest)

    def net(s):
        return residual + gas(x_rest) * math.expm1(n * math.log1p(area * (s - x_rest) / (volume - area * s))) \
            + stop.stiffness * (s - x_rest)

    return x_rest, stop.stiffness + tangent, net


def test_the_recuperators_rest_is_its_static_balance():
    x_rest, _, _ = _recuperator_rest()
    state = RestState.of(Mechanism(RECUPERATOR), TOLERANCE)
    assert state.positions[0] == pytest.approx(x_rest, rel=1e-12)


def test_the_wells_energy_to_leave_the_tolerance_is_the_lower_riemann_sum():
    """Near x* the well is ``kappa (x - x*)^2 / 2`` (kappa: the stop's stiffness plus the gas spring's tangent); the
    lower Riemann sum of ``kappa s`` over 16 pieces of [0, delta] is ``kappa delta^2 (15 / 32)``, below the true
    ``kappa delta^2 / 2``."""
    x_rest, kappa, _ = _recuperator_rest()
    well = EnergyBounds(Mechanism(RECUPERATOR)).well
    for delta in (1e-11, 1e-8, 1e-6):
        expected = kappa * delta * delta * (RIEMANN_PIECES - 1) / (2.0 * RIEMANN_PIECES)
        assert well_energy(well, well.argmin, delta) == pytest.approx(expected, rel=1e-4)


@pytest.mark.parametrize("offset", [3e-12, -7e-12, 2e-10, -5e-9])
@pytest.mark.parametrize("velocity", [0.0, 4e-12, -1e-10])
def test_the_energy_bound_bounds_the_energy_above_the_rest(offset, velocity):
    """``E_up`` >= the kinetic energy plus ``W(x) - W(x*)``, the latter integrated independently (quad of the
    static forces, the gas spring's less the stop's, written out in _recuperator_rest); and at most twice it
    (``(x - x*) W'(x)`` is twice a quadratic well's energy)."""
    x_rest, _, net = _recuperator_rest()
    state = RestState.of(Mechanism(RECUPERATOR), TOLERANCE)
    x = state.positions[0] + offset
    above, _ = quad(net, x_rest, x, epsabs=0.0, epsrel=1e-12)
    kinetic = 0.5 * RECUPERATOR.barrel.mass * velocity ** 2
    bound = state.energy_bound([x], [velocity])
    assert kinetic + above <= bound <= kinetic + 2.0 * above * (1.0 + 1e-3) + 1e-26
    assert state.reached([x], [velocity]) == (bound * (1.0 + fm.ENERGY_SLACK) < state.threshold)


def test_the_chunks_end_at_every_multiple_of_the_check_interval_after_the_last_input():
    """The breech pulse ends at 0.012 s: its segment is not cut, the one after it is, at 100 and 200 s."""
    watch = RestWatch.of(Mechanism(load_scene(scene_path("breech_pulse"))), TOLERANCE, 250.0)
    plan = [(0.0, 0.012, "a"), (0.012, 250.0, "b")]
    assert watch.split(plan) == [(0.0, 0.012, "a"), (0.012, 100.0, "b"), (100.0, 200.0, "b"), (200.0, 250.0, "b")]
    assert watch.split([(100.0, 200.0, "c")]) == [(100.0, 200.0, "c")]
    late = RestWatch.of(Mechanism(load_scene(scene_path("burst")).with_changes(burst=Burst(shots=2, interval=120.0))),
                        TOLERANCE, 250.0)
    assert late.split([(0.0, 120.0, "a"), (120.0, 250.0, "b")]) == [(0.0, 120.0, "a"), (120.0, 200.0, "b"),
                                                                    (200.0, 250.0, "b")]
    assert RestWatch.of(Mechanism(load_scene(scene_path("model_i"))), TOLERANCE, CHECK_INTERVAL) is None
