"""Early stop of the engine (simulate(stop_when_final=...), mbs_models.engine.finality).

The early-stopped metrics must be those of the full run (the window contains the maximum, the
solver's steps are the same), unproven metrics must be None, and the energy bounds must really
bound the future of a simulated run.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mbs_models import Conventions, SceneError, model_i, model_ii, simplified_model, simulate
from mbs_models.engine import energy_bounds as eb
from mbs_models.engine import finality as fm
from mbs_models.studies.sweep import run_scenes

ALL = fm.FINAL_METRICS
TIMES = {"max_barrel_displacement": "time_of_max_barrel_displacement",
         "peak_contact_force": "time_of_peak_contact_force",
         "max_absorber_velocity": "time_of_max_absorber_velocity",
         "peak_support_force": "time_of_peak_support_force"}


def _soft(scene):
    return scene.with_changes(**{"contact.stiffness": 1e6, "contact.exponent": 1.0})


SCENES = {
    "simplified": simplified_model(),
    **{f"{name}-m{mass:g}-gap{gap * 1e3:g}mm": factory(mass, gap)
       for name, factory in (("i", model_i), ("ii", model_ii)) for mass in (100.0, 500.0, 1000.0)
       for gap in (0.0, 0.04, 0.12)},
    "ii-soft-contact": _soft(model_ii(1000.0, 0.0)),
    "i-soft-contact": _soft(model_i(500.0, 0.02)),
    "ii-stiff-contact": model_ii(100.0, 0.0).with_changes(**{"contact.stiffness": 1e10}),
    **{f"ii-{flag}": model_ii(1000.0, 0.04, Conventions(**{flag: True}))
       for flag in ("compression_only", "rounded_initial_velocity", "literal_gap_sign")},
    "i-v0_includes_absorber": model_i(500.0, 0.0, Conventions(v0_includes_absorber=True)),
    "i-literal_gap_sign": model_i(1000.0, 0.02, Conventions(literal_gap_sign=True)),
}
_FULL: dict[str, object] = {}


def _full(key):
    """The 10 s run without early stop (cached: several tests compare against it)."""
    if key not in _FULL:
        try:
            _FULL[key] = simulate(SCENES[key], 10.0)
        except Exception as exc:  # noqa: BLE001 - a scene the engine cannot integrate (sticking contact)
            _FULL[key] = exc
    return _FULL[key]


def _assert_same_as_full(early, full):
    for name in early.final_metrics:
        if name == "impacts":
            assert early.impacts == full.impacts
            continue
        assert getattr(early, name) == getattr(full, name), name
        assert getattr(early, TIMES[name]) == getattr(full, TIMES[name]), TIMES[name]
    for name in set(ALL) - set(early.final_metrics):
        if name == "impacts":
            assert early.impacts is None
        else:
            assert getattr(early, name) is None and getattr(early, TIMES[name]) is None, name


@pytest.mark.parametrize("requested", [("max_barrel_displacement",), ("max_barrel_displacement",
                                                                        "peak_contact_force",
                                                                        "max_absorber_velocity"), ALL],
                         ids=["x", "x-F-v", "all"])
@pytest.mark.parametrize("key", list(SCENES))
def test_early_stop_gives_the_full_runs_metrics(key, requested):
    full = _full(key)
    if isinstance(full, Exception):
        with pytest.raises(type(full)):
            simulate(SCENES[key], 10.0, stop_when_final=requested)
        return
    early = simulate(SCENES[key], 10.0, stop_when_final=requested)
    assert early.requested_end_time == 10.0
    if early.stop_reason == fm.STOP_METRICS_FINAL:
        assert set(requested) <= set(early.final_metrics)
        assert early.end_time < 10.0 and early.time[-1] == pytest.approx(early.end_time)
        assert len(early.time) < len(full.time)
        np.testing.assert_array_equal(early.barrel_position, full.barrel_position[:len(early.time)])
        assert len(early.kinetic_energy_history) == len(early.time)  # histories cover the window
    else:
        assert early.stop_reason == fm.STOP_END_TIME and early.end_time == 10.0
        assert early.final_metrics == ALL
    _assert_same_as_full(early, full)


@pytest.mark.parametrize("key", [k for k in SCENES if "literal_gap" not in k and "compression" not in k])
def test_the_maximum_displacement_is_proven_final_within_the_first_seconds(key):
    early = simulate(SCENES[key], 10.0, stop_when_final=("max_barrel_displacement",))
    assert early.stop_reason == fm.STOP_METRICS_FINAL
    assert early.time_of_max_barrel_displacement < early.end_time < 2.0


def test_literal_lambda_sign_never_stops_early():
    scene = model_ii(1000.0, 0.0, Conventions(literal_lambda_sign=True))
    early = simulate(scene, 3.0, stop_when_final=ALL)
    full = simulate(scene, 3.0)
    assert early.stop_reason == fm.STOP_NO_BOUND and early.end_time == 3.0
    assert early.final_metrics == ALL
    _assert_same_as_full(early, full)
    # ... because its energy really grows: during compression the contact pushes
    assert eb.largest_energy_rise(full.kinetic_energy_history + full.stored_energy_history) > 1e-3


def test_unproven_metrics_are_none_and_summaries_still_work():
    early = simulate(model_ii(1000.0, 0.0), 10.0, stop_when_final=("max_barrel_displacement",))
    assert early.stop_reason == fm.STOP_METRICS_FINAL
    assert "impacts" not in early.final_metrics and early.impacts is None
    assert early.peak_contact_force is None and early.time_of_peak_contact_force is None
    metrics = early.metrics()
    assert metrics["impacts"] is None and metrics["end_time"] < metrics["requested_end_time"] == 10.0
    assert metrics["stop_reason"] == "metrics_final"
    assert "not proven final" in early.summary() and "10 s requested" in early.summary()
    assert "10 s requested: every metric asked for is final (proven by energy bounds)," in early.summary()  # StopReason.METRICS_FINAL's message


def test_zero_recoil_stiffness_has_no_displacement_bound():
    scene = simplified_model().with_changes(**{"recoil_spring.stiffness": 0.0})
    assert eb.EnergyBounds(scene).barrel_displacement(1.0) == math.inf
    result = simulate(scene, 2.0, stop_when_final=("max_barrel_displacement",))
    assert result.stop_reason == fm.STOP_END_TIME and result.end_time == 2.0


def test_an_energy_rise_beyond_the_slack_makes_the_run_go_to_the_end(monkeypatch):
    import mbs_models.engine.run_policy as run_policy

    monkeypatch.setattr(run_policy, "ENERGY_SLACK", -1.0)  # any history "rises" more than this
    result = simulate(model_ii(1000.0, 0.0), 3.0, stop_when_final=("max_barrel_displacement",))
    assert result.stop_reason == fm.STOP_ENERGY_CHECK
    assert result.end_time == 3.0 and result.final_metrics == ALL and result.impacts is not None


@pytest.mark.parametrize("bad", ["max_barrel_displacement", ["max_displacement"], [3], 5])
def test_bad_metric_names_raise_scene_error_naming_the_argument(bad):
    with pytest.raises(SceneError) as info:
        simulate(model_ii(), 1.0, stop_when_final=bad)
    assert info.value.key == "stop_when_final"
    assert "max_barrel_displacement, peak_contact_force" in info.value.message
    with pytest.raises(SceneError, match="stop_when_final"):
        run_scenes([model_ii()], 1.0, stop_when_final=bad)


# --------------------------------------------------------------------------- the bounds along the full runs
# (here, not in test_energy_bounds.py: they reuse this module's cached full runs)
# (compression_only at gap 40 mm sticks, which the engine cannot integrate: its bounds are checked on the
# reference, tests/test_validation_finality.py)
BOUND_SCENES = ["simplified", "i-m100-gap0mm", "ii-m1000-gap0mm", "ii-m100-gap120mm", "i-m500-gap40mm",
                "ii-soft-contact", "ii-literal_gap_sign", "i-literal_gap_sign", "i-v0_includes_absorber"]


@pytest.mark.parametrize("key", BOUND_SCENES)
def test_the_bounds_bound_everything_later_in_a_simulated_run(key):
    """Along a full run: max over [t_i, 10 s] of each quantity <= its bound from E(t_i) (no slack)."""
    scene, result = SCENES[key], _full(key)
    b = eb.EnergyBounds(scene)
    bodies = [body.name for body in b.mechanism.bodies]
    x = np.array([result.positions[name] for name in bodies]).T
    v = np.array([result.velocities[name] for name in bodies]).T
    energy = np.array([b.energy(xi, vi) for xi, vi in zip(x, v)])
    np.testing.assert_allclose(energy, result.kinetic_energy_history + result.stored_energy_history,
                               rtol=1e-9, atol=1e-9 * energy[0])

    def future_max(values):
        return np.maximum.accumulate(np.asarray(values)[::-1])[::-1]

    tolerance = 1e-7  # the solution's own energy error (it is not exactly dissipative)
    margin = 1.0 + tolerance
    x_M = result.barrel_position
    bound_x = np.sqrt(2 * energy * margin / scene.recoil_spring.stiffness)
    assert np.all(future_max(x_M) <= np.array([b.barrel_displacement(e * margin) for e in energy]) + 1e-15)
    assert np.allclose([b.barrel_displacement(e) for e in energy], bound_x / math.sqrt(margin))
    support = np.abs(result.support_force)
    assert np.all(future_max(support) <= np.array([b.support_force_bound(e * margin) for e in energy]) * (1 + 1e-12))
    if scene.absorber is None:  # all the energy is the barrel's: the bound is reached at the maximum
        assert np.min(bound_x / np.maximum(future_max(x_M), 1e-300)) < 1.0 + 1e-6
        return
    x_m, v_M, v_m = result.absorber_position, result.barrel_velocity, result.absorber_velocity
    contact = b.contacts[0]
    checks = {
        "absorber_velocity": (np.abs(v_m), lambda e: b.body_velocity(1, e)),
        "relative_displacement": (x_M - x_m, lambda e: b.contact_coordinate(0, e)),
        "penetration": (np.maximum(x_M - x_m - contact.offset, 0.0), lambda e: b.penetration(0, e)),
        "penetration_rate": (np.abs(v_M - v_m), lambda e: b.penetration_rate(0, e)),
        "contact_force": (result.contact_force, lambda e: b.contact_force_bound(0, e)),
    }
    for name, (values, bound) in checks.items():
        bounds = np.array([bound(e * margin) for e in energy])
        later = future_max(values)
        assert np.all(later <= bounds * (1 + 1e-12) + 1e-12), name
        assert np.all(np.isfinite(bounds)), name


def test_tracker_proves_nothing_for_a_scene_that_injects_energy():
    tracker = fm.FinalityTracker(model_ii(1000.0, 0.0, Conventions(literal_lambda_sign=True)), ALL, 1000.0)
    tracker.observe(0.0, [0.2, 0.0], [0.0, 0.0])
    tracker.observe_last(1.0, [0.0, 0.0], [0.0, 0.0])  # zero energy: every bound would be 0
    assert not tracker.done and not tracker.final


def test_tracker_on_a_simple_state():
    scene = simplified_model()
    tracker = fm.FinalityTracker(scene, ("max_barrel_displacement",), 1000.0)
    tracker.observe(0.1, [0.1], [0.0])                # E = k 0.1^2 / 2: the bound equals the maximum seen ...
    assert not tracker.done                            # ... and the slack keeps it from counting
    x = 0.1 / math.sqrt(2.0)                           # E halves: bound 0.0707 m < 0.1 m seen
    tracker.observe(0.2, [x], [0.0])
    assert tracker.done and tracker.final_at["max_barrel_displacement"] == 0.2


def test_sweep_with_early_stop_gives_the_same_displacements():
    scenes = [model_i(500.0, 0.0), model_ii(100.0, 0.05), model_ii(1000.0, 0.0, Conventions(literal_lambda_sign=True))]
    early = run_scenes(scenes, 4.0, workers=1, stop_when_final=("max_barrel_displacement",))
    full = run_scenes(scenes, 4.0, workers=1)
    for a, b in zip(early, full):
        assert a.error is None and a.max_barrel_displacement == b.max_barrel_displacement
        assert a.time_of_max_barrel_displacement == b.time_of_max_barrel_displacement
    assert [p.stop_reason for p in early] == ["metrics_final", "metrics_final", "end_time_no_energy_bound"]
    assert early[0].end_time < 2.0 and early[0].impacts is None and early[0].peak_contact_force is None
    assert early[2].end_time == 4.0 and early[2].impacts == full[2].impacts


def test_skipping_the_barrels_bound_while_it_rises_stops_where_evaluating_it_does(monkeypatch):
    """While the barrel is at its largest x_M and moving on, the tracker does not evaluate the barrel's bound (it
    cannot prove the maximum there): the early stops of the Figs 4/5 points, and of a run asking for every metric,
    are those of a tracker that evaluates it at every observed state (same end, steps, final metrics, values)."""
    from mbs_models import model_i, model_ii, simulate
    from mbs_models.engine.finality import FINAL_METRICS, FinalityTracker

    runs = [(model(mass, gap), ("max_barrel_displacement",)) for model in (model_i, model_ii)
            for mass in (100.0, 1000.0) for gap in (0.0, 0.08)] + [(model_ii(500.0, 0.04), FINAL_METRICS)]

    def outcomes():
        out = []
        for scene, metrics in runs:
            result = simulate(scene, 10.0, "standard", stop_when_final=metrics)
            out.append((result.end_time, result.steps, result.stop_reason, result.final_metrics,
                        result.max_barrel_displacement, result.peak_contact_force))
        return out

    skipping = outcomes()
    evaluate = FinalityTracker.check
    monkeypatch.setattr(FinalityTracker, "check", lambda self, *args, rising=False, **kwargs: evaluate(self, *args, **kwargs))
    every_state = outcomes()
    assert skipping == every_state
    assert all(result[2] == "metrics_final" for result in skipping)
