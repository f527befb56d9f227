"""Early stop of the reference (solve_reference(stop_when_final=...), validation.reference.finality).

Same contract as the engine's: the metrics of an early-stopped reference are the full run's (to
round-off: the solver's steps before the stop are the same), unproven ones are None, and the bounds
really bound the future of the dense solution.  The two independent bound implementations agree.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from mbs_models.scene import Contact, Conventions, load_scene, model_i, model_ii, simplified_model
from validation.reference import finality
from validation.reference import solve_reference
from validation.reference.assembly import build_model

ALL = finality.METRICS
STUDIED = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity")
TIMES = {"max_barrel_displacement": "time_of_max_barrel_displacement",
         "peak_contact_force": "time_of_peak_contact_force",
         "max_absorber_velocity": "time_of_max_absorber_velocity",
         "peak_support_force": "time_of_peak_support_force"}
END = 8.0  # s: long enough for every stop below (model (i) proves its impacts final at 6.8 s)

FAST = {
    "simplified": simplified_model(),
    "i-m1000-gap0": model_i(1000.0, 0.0),
    "ii-m1000-gap0": model_ii(1000.0, 0.0),
    "ii-m100-gap120mm": model_ii(100.0, 0.12),
    "ii-literal_gap_sign": model_ii(1000.0, 0.04, Conventions(literal_gap_sign=True)),
    "ii-compression_only": model_ii(1000.0, 0.0, Conventions(compression_only=True)),
}

#: two absorbers (front: ground, hunt-crossley, gap 0; rear: barrel, lankarani-nikravesh, gap 10 mm)
TWO = load_scene(Path(__file__).parent / "data" / "two_absorbers.toml")
II_EXACT = model_ii(500.0, 0.0).with_changes(contact=Contact(gap=0.0, law="exact-restitution", stiffness=2.1e8,
                                                             exponent=1.3, restitution=0.3))
#: the effects of version 2: several absorbers, every element, every law
NEW = {
    "two-absorbers": TWO,
    "ii-gonthier": model_ii(1000.0, 0.04).with_changes(contact=Contact(gap=0.04, law="gonthier", stiffness=2.1e8,
                                                                       exponent=1.3, restitution=0.4)),
    "i-kelvin-voigt": model_i(500.0, 0.0).with_changes(contact=Contact(gap=0.0, law="kelvin-voigt", stiffness=2e7,
                                                                       damping=2e4)),
}
#: (base, law): the base with every other element (tests/conftest.py's every_element), their contacts of that law
EVERY = {
    "ii-every-element": (model_ii(100.0, 0.0), {}),
    "two-absorbers-every-element": (TWO, {}),
    "ii-exact-every-element-hertz": (II_EXACT, dict(law="hertz", stiffness=1e9, exponent=1.5)),
}


@pytest.fixture(scope="module")
def new_scenes(every_element) -> dict:
    """The scenes of NEW and EVERY by key."""
    return {**NEW, **{key: every_element(base, **law) for key, (base, law) in EVERY.items()}}
SLOW = {
    **{f"{name}-m{mass:g}-gap{gap * 1e3:g}mm": factory(mass, gap)
       for name, factory in (("i", model_i), ("ii", model_ii)) for mass in (100.0, 500.0, 1000.0)
       for gap in (0.0, 0.04, 0.08, 0.12)},
    "ii-soft": model_ii(1000.0, 0.0).with_changes(**{"contact.stiffness": 1e6, "contact.exponent": 1.0}),
    "i-stiff": model_i(100.0, 0.0).with_changes(**{"contact.stiffness": 1e10}),
    **{f"i-{flag}": model_i(500.0, 0.02, Conventions(**{flag: True}))
       for flag in ("compression_only", "v0_includes_absorber", "rounded_initial_velocity", "literal_gap_sign")},
}


def _assert_same_as_full(early, full):
    for name in early.final_metrics:
        if name == "impacts":
            assert [(i.start, i.end) for i in early.impacts] == [(i.start, i.end) for i in full.impacts]
            np.testing.assert_allclose([i.peak_force for i in early.impacts], [i.peak_force for i in full.impacts],
                                       rtol=1e-12)
            continue
        ours, theirs = getattr(early, name), getattr(full, name)
        if theirs is None:  # no absorber
            assert ours is None
            continue
        assert ours == pytest.approx(theirs, rel=1e-12, abs=1e-300), name
        assert getattr(early, TIMES[name]) == pytest.approx(getattr(full, TIMES[name]), rel=1e-12, abs=1e-15)
    for name in set(ALL) - set(early.final_metrics):
        assert getattr(early, name) is None, name
    # per absorber and per stop: what the final metrics cover is the full run's too, the rest None
    peaks, impacts = "peak_contact_force" in early.final_metrics, "impacts" in early.final_metrics
    for ours, theirs in zip(early.absorber_metrics, full.absorber_metrics):
        assert (ours.peak_contact_force, ours.time_of_peak_contact_force) == (
            (theirs.peak_contact_force, theirs.time_of_peak_contact_force) if peaks else (None, None))
        assert (ours.impacts is None) != impacts
        if "max_absorber_velocity" in early.final_metrics:
            assert ours.max_velocity == pytest.approx(theirs.max_velocity, rel=1e-12)
        else:
            assert ours.max_velocity is None
    for name, ours in early.stop_metrics.items():
        theirs = full.stop_metrics[name]
        assert ours.peak_force == (theirs.peak_force if peaks else None)
        if impacts:
            assert [(i.start, i.end) for i in ours.impacts] == [(i.start, i.end) for i in theirs.impacts]
        else:
            assert ours.impacts is None


_FULL: dict = {}


def _full(scene):
    """The run to END without early stop (cached: three requests compare against it)."""
    if scene not in _FULL:
        _FULL[scene] = solve_reference(scene, END)
    return _FULL[scene]


def _check(scene, requested):
    full = _full(scene)
    early = solve_reference(scene, END, stop_when_final=requested)
    assert early.requested_end_time == END
    if early.stop_reason == "metrics_final":
        assert set(requested) <= set(early.final_metrics) and early.end_time < END
        assert len(early.segments) <= len(full.segments)
        for a, b in zip(early.segments[:-1], full.segments):  # the same segments before the stop
            assert (a.t0, a.t1, a.mode) == (b.t0, b.t1, b.mode)
    else:  # a load acting for ever (gravity along a cradle) leaves the scene without a bound
        forever = not math.isfinite(full.model.last_input_time)
        assert early.stop_reason == ("end_time_no_energy_bound" if forever else "end_time")
        assert early.end_time == END
    _assert_same_as_full(early, full)
    return early


@pytest.mark.parametrize("requested", [("max_barrel_displacement",), STUDIED, ALL], ids=["x", "x-F-v", "all"])
@pytest.mark.parametrize("key", list(FAST))
def test_early_stopped_reference_gives_the_full_runs_metrics(key, requested):
    early = _check(FAST[key], requested)
    if key != "ii-literal_gap_sign" or requested != ALL:  # an interference keeps a contact force for ever
        assert early.stop_reason == "metrics_final"


@pytest.mark.parametrize("requested", [ALL, pytest.param(("max_barrel_displacement",), marks=pytest.mark.slow),
                                       pytest.param(("peak_support_force",), marks=pytest.mark.slow)],
                         ids=["all", "x", "S"])
@pytest.mark.parametrize("key", [*NEW, *EVERY])
def test_early_stop_with_several_absorbers_every_element_and_every_law(key, requested, new_scenes):
    scene = new_scenes[key]
    early = _check(scene, requested)
    forever = not math.isfinite(early.model.last_input_time)  # a load acting for ever: no bound
    if forever:
        assert early.stop_reason == "end_time_no_energy_bound", (key, requested)
        return
    if early.stop_reason != "metrics_final" and "impacts" in requested:
        # a contact loaded above the impact threshold at rest (a preload held on its stop) keeps an episode
        # going for ever: the impacts cannot be final, the other metrics must be
        full = _full(scene)
        assert any(full.connector_force(name, END) > full.impact_threshold for name in full.contacts), key
        early = _check(scene, tuple(name for name in requested if name != "impacts"))
    assert early.stop_reason == "metrics_final", (key, requested)


@pytest.mark.parametrize("key", ["two-absorbers-every-element", "ii-gonthier", "i-kelvin-voigt",
                                 "ii-exact-every-element-hertz"])
def test_the_bounds_bound_the_future_with_several_absorbers_every_element_and_every_law(key, new_scenes):
    result = _full(new_scenes[key])
    if not math.isfinite(result.model.last_input_time):  # a load for ever may add energy: no bound claimed, none used
        assert not finality.Finality(result.model, ALL, 1000.0).enabled
        return
    assert_bounds_hold(result, END)


@pytest.mark.slow
@pytest.mark.parametrize("requested", [("max_barrel_displacement",), STUDIED, ALL], ids=["x", "x-F-v", "all"])
@pytest.mark.parametrize("key", list(SLOW))
def test_early_stopped_reference_gives_the_full_runs_metrics_grid(key, requested):
    _check(SLOW[key], requested)


def test_literal_lambda_sign_runs_to_the_end():
    scene = model_ii(1000.0, 0.0, Conventions(literal_lambda_sign=True))
    early = solve_reference(scene, 2.0, stop_when_final=ALL)
    assert early.stop_reason == "end_time_no_energy_bound" and early.end_time == 2.0
    assert early.final_metrics == ALL and early.impacts is not None


def test_unproven_metrics_are_none():
    early = solve_reference(model_ii(1000.0, 0.0), END, stop_when_final=("max_barrel_displacement",))
    assert early.stop_reason == "metrics_final"
    assert early.impacts is None and early.peak_contact_force is None and early.time_of_peak_contact_force is None
    metrics = early.metrics()
    assert metrics["impacts"] is None and metrics["end_time"] < metrics["requested_end_time"]


@pytest.mark.parametrize("bad", ["impacts", ["max_displacement"]])
def test_bad_metric_names(bad):
    with pytest.raises(ValueError, match="stop_when_final.*allowed: max_barrel_displacement"):
        solve_reference(model_ii(), 1.0, stop_when_final=bad)


def assert_bounds_hold(result, end):
    """Every bound computed from the energy at t bounds the dense solution at every later time, from the last
    external input on (a burst's last shot: before it the shots add energy)."""
    model = result.model
    bounds = finality.EnergyBounds(model)
    t = np.linspace(model.last_input_time, end, 6001)
    y = result.state(t)
    energy = model.mechanical_energy(y)
    floor = bounds.floor  # 0, or the minimum of a preload's potential well: the energy's lower bound
    rise = np.maximum.accumulate(energy[::-1])[::-1] - energy
    assert np.all(rise <= 1e-9 * (energy - floor) + 1e-12), "the reference's energy must never increase"

    def later(values):
        return np.maximum.accumulate(np.asarray(values)[::-1])[::-1]

    slack = [floor + (float(e) - floor) * (1 + 1e-9) for e in energy]
    computed = [bounds.bounds(e, y[:, k]) for k, e in enumerate(slack)]
    per_connector = [bounds.connector_bounds(e) for e in slack]
    checks = {"x_barrel": (y[0], [b["x"][0] for b in computed]),
              "support": (np.abs(result.support_force(t)), [b["support"] for b in computed])}
    for i, body in enumerate(result.bodies):
        checks[f"v_{body}"] = (np.abs(y[2 * i + 1]), [b["v"][i] for b in computed])
    for c in model.connectors:
        j = c.index
        checks[f"d_{c.name}"] = (np.abs(c.d_of(y)), [b[j][0] for b in per_connector])
        checks[f"rate_{c.name}"] = (np.abs(c.rate_of(y)), [b[j][1] for b in per_connector])
        checks[f"F_{c.name}"] = (np.abs(result.connector_force(c.name, t)), [b["force"][j] for b in computed])
        if c.is_contact:
            checks[f"p_{c.name}"] = (np.maximum(c.d_of(y) - c.offset, 0.0), [b["penetration"][j] for b in computed])
    for name, (values, bound) in checks.items():
        assert np.all(later(values) <= np.asarray(bound) * (1 + 1e-12) + 1e-12), name


@pytest.mark.parametrize("key", ["i-m1000-gap0", "ii-m1000-gap0", "ii-m100-gap120mm", "ii-literal_gap_sign",
                                 "ii-compression_only"])
def test_the_bounds_bound_the_future_of_the_dense_solution(key):
    assert_bounds_hold(_full(FAST[key]), END)


AGREE = {"i": model_i(100.0, 0.0), "ii": model_ii(500.0, 0.04),
         "ii-literal-gap": model_ii(1000.0, 0.02, Conventions(literal_gap_sign=True)),
         "i-linear": model_i(1000.0, 0.08).with_changes(**{"contact.exponent": 1.0}),
         "simplified": simplified_model()}


@pytest.mark.parametrize("key", [*AGREE, "two-absorbers-every-element"])
def test_the_two_independent_implementations_agree(key, new_scenes):
    """The engine's bounds (mbs_models.engine.final_metrics) and the reference's, written separately,
    give the same numbers on random states."""
    from mbs_models.engine.energy_bounds import EnergyBounds

    scene = AGREE.get(key) or new_scenes[key]

    engine = EnergyBounds(scene)
    model = build_model(scene)
    ours_bounds = finality.EnergyBounds(model)
    bodies = [b.name for b in engine.mechanism.bodies]
    assert bodies == [b.name for b in model.bodies]
    rng = np.random.default_rng(4)
    for _ in range(200):
        x = rng.normal(0.0, 0.1, len(bodies))
        v = rng.normal(0.0, 0.5, len(bodies))
        y = np.zeros(model.n_states)
        y[0:2 * len(bodies):2], y[1:2 * len(bodies):2] = x, v
        energy = float(model.mechanical_energy(y))
        assert engine.energy(x, v) == pytest.approx(energy, rel=1e-12)
        ours = ours_bounds.bounds(energy)
        assert engine.barrel_displacement(energy) == pytest.approx(ours["x"][0], rel=1e-12)
        assert engine.support_force_bound(energy) == pytest.approx(ours["support"], rel=1e-12)
        for i in range(1, len(bodies)):
            assert engine.body_velocity(i, energy) == pytest.approx(ours["v"][i], rel=1e-12)
        per_connector = ours_bounds.connector_bounds(energy)
        for j, contact in enumerate(engine.contacts):
            index = model.connector(contact.name).index
            d, rate, p = per_connector[index]
            assert engine.contact_coordinate(j, energy) == pytest.approx(d, rel=1e-12)
            assert engine.contact_reachable(j, energy) == ours["reachable"][index]
            assert engine.penetration(j, energy) == pytest.approx(p, rel=1e-12, abs=1e-300)
            assert engine.penetration_rate(j, energy) == pytest.approx(rate, rel=1e-12)
            assert engine.contact_force_bound(j, energy) == pytest.approx(ours["force"][index], rel=1e-12, abs=1e-300)


def test_zero_stiffness_means_no_bound():
    model = build_model(simplified_model().with_changes(**{"recoil_spring.stiffness": 0.0}))
    assert finality.EnergyBounds(model).bounds(1.0)["x"][0] == math.inf


def test_stop_event_root_on_the_wrong_side_of_the_bound_still_stops():
    """Regression: model (ii), m = 500 kg, gap 120 mm, all metrics: the stop event's root left the
    force bound 1.005e-12 (relative) short of the impact threshold, the check refused it, and the
    solve restarted at the same instant until it failed as 'stuck'."""
    early = solve_reference(model_ii(500.0, 0.12), END, stop_when_final=ALL)
    assert early.stop_reason == "metrics_final" and early.final_metrics == ALL
    assert early.end_time == pytest.approx(1.5532, abs=1e-3)
