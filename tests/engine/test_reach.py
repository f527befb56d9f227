"""mbs_models/engine/reach.py: contacts that can never close are found before any solve, and a contact that
closes is never reported (the bound is a proof, not an estimate)."""

from __future__ import annotations

import math
import warnings

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mbs_models import load_scene, model_i, model_ii, simplified_model, simulate
from mbs_models.engine.energy_bounds import ENERGY_SLACK, EnergyBounds
from mbs_models.engine.mechanism import Mechanism
from mbs_models.engine.reach import contact_reach_bounds, contacts_out_of_reach
from mbs_models.scenes import list_scenes, scene_path

# gaps beyond the free-recoil travel are what these tests probe
pytestmark = pytest.mark.filterwarnings("ignore:absorber.*beyond the barrel's free-recoil travel:mbs_models.errors.UnitWarning")


def _undamped_free_travel(scene) -> float:
    """sqrt(2 E0 / k) from the scene's numbers: the undamped free recoil's amplitude, m."""
    energy = 0.5 * scene.barrel.mass * scene.initial_velocity ** 2
    return math.sqrt(2.0 * energy * (1.0 + ENERGY_SLACK) / scene.recoil_spring.stiffness)


def test_a_gap_in_millimetres_is_reported_with_its_key_and_both_lengths():
    scene = model_ii(1000.0, 40.0)  # meant: 40 mm
    [found] = contacts_out_of_reach(scene)
    assert found.key == "absorber.contact.gap" and found.length == 40.0
    # a ground-mounted absorber at rest: the barrel's own free recoil bounds the closing
    assert found.reach == pytest.approx(_undamped_free_travel(scene), rel=1e-12)
    message = found.message()
    assert "absorber.contact.gap" in message and "40 m" in message and f"{found.reach:.4g} m" in message
    assert "\n" not in message


def test_the_free_travel_bound_is_not_below_the_damped_free_recoil():
    free = simulate(simplified_model(), 3.0, "draft").max_barrel_displacement
    scene = model_ii(1000.0, 1.0)
    [found] = contacts_out_of_reach(scene)
    assert free < found.reach


@pytest.mark.parametrize("make", [model_i, model_ii], ids=["model_i", "model_ii"])
def test_gaps_that_close_are_never_reported_and_reported_ones_never_close(make):
    """Around the bound: every reported gap stays open in the solve; every gap that closes is not reported."""
    free = simulate(simplified_model(), 3.0, "draft").max_barrel_displacement
    undamped = _undamped_free_travel(make(1000.0, 0.0))
    closed = reported_gaps = 0
    for gap in (0.0, 0.04, 0.5 * free, 0.99 * free, 1.2 * free, 0.9 * undamped, 1.01 * undamped, 1.5 * undamped):
        scene = make(1000.0, gap)
        reported = contacts_out_of_reach(scene)
        peak = simulate(scene, 3.0, "draft").peak_contact_force
        if reported:
            reported_gaps += 1
            assert peak == 0.0, gap
        if peak > 0.0:
            closed += 1
            assert reported == [], gap
    assert closed >= 2 and reported_gaps >= 1
    for gap in (1.0, 40.0):  # far beyond: always reported
        assert [r.key for r in contacts_out_of_reach(make(1000.0, gap))] == ["absorber.contact.gap"]


def test_shipped_scenes_have_no_contact_out_of_reach():
    for name in list_scenes():
        assert contacts_out_of_reach(load_scene(scene_path(name))) == [], name


def test_one_of_several_contacts_out_of_reach():
    """The rear absorber 40 m away: only it is reported (the front one closes at gap 0)."""
    scene = load_scene(scene_path("two_absorbers"))
    rear = scene.absorbers[1]
    scene = scene.with_changes(**{"absorber.1.contact.gap": 40.0})
    [found] = contacts_out_of_reach(scene)
    assert found.key == "absorber.1.contact.gap" and found.length == 40.0
    assert 0.0 < found.reach < 40.0 and rear.contact.gap == 0.02


def test_the_bound_is_tight_for_an_undamped_barrel():
    """Without the recoil damper the barrel's free recoil reaches sqrt(2 E0 / k) exactly: a gap 0.1 % short
    of it closes (and is not reported), one beyond the bound (which adds only ENERGY_SLACK) stays open."""
    undamped = model_ii(1000.0, 0.0).with_changes(recoil_damper=None)
    travel = math.sqrt(2.0 * 0.5 * undamped.barrel.mass * undamped.initial_velocity ** 2
                       / undamped.recoil_spring.stiffness)
    short = undamped.with_changes(**{"contact.gap": 0.999 * travel})
    assert contacts_out_of_reach(short) == []
    assert simulate(short, 1.5, "draft").peak_contact_force > 0.0
    beyond = undamped.with_changes(**{"contact.gap": travel * (1.0 + ENERGY_SLACK)})
    [found] = contacts_out_of_reach(beyond)
    assert found.reach <= beyond.absorber.contact.gap
    assert simulate(beyond, 1.5, "standard").peak_contact_force == 0.0


@settings(max_examples=12, deadline=None)
@given(mass=st.floats(100.0, 3000.0), fraction=st.floats(0.3, 2.0), mount=st.sampled_from([model_i, model_ii]),
       damping=st.floats(0.0, 1.0))
def test_a_reported_contact_never_closes(mass, fraction, mount, damping):
    """Random absorbers and gaps around the barrel's undamped free travel, recoil damping scaled down to 0:
    whatever is reported stays open in the solve, whatever closes is not reported."""
    base = mount(mass, 0.0)
    scene = base.with_changes(**{"recoil_damper.recoil": damping * base.recoil_damper.recoil,
                                 "contact.gap": fraction * _undamped_free_travel(base)})
    reported = contacts_out_of_reach(scene)
    peak = simulate(scene, 2.0, "draft").peak_contact_force
    assert not (reported and peak > 0.0), (reported, peak)


def test_a_spring_too_weak_for_double_precision_gives_no_bound_and_no_warning():
    """k = 5e-324 N/m: the stroke bound sqrt(2 E / k) overflows (2 / k is beyond 1.8e308), so the spring bounds
    nothing -- an infinite reach, nothing reported -- without a numpy overflow warning."""
    scene = model_ii(1000.0, 0.0).with_changes(**{"recoil_spring.stiffness": 5e-324})
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert contact_reach_bounds(scene) == [(math.inf, True)]
        assert contacts_out_of_reach(scene) == []
        mechanism = Mechanism(scene)
        bounds = EnergyBounds(mechanism)
        assert bounds.contact_reach(0, bounds.energy(mechanism.initial_positions(),
                                                     mechanism.initial_velocities())) == math.inf
