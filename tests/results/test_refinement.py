"""Refinement of contact episodes and the support peak in lockstep (mbs_models.results.refinement)."""

from __future__ import annotations

import numpy as np
import pytest

from mbs_models import load_scene, model_ii, simulate
from mbs_models.engine import result_builder
from mbs_models.results import refinement
from mbs_models.results.refinement import Episodes, refine
from mbs_models.results.samples import Interpolant
from mbs_models.engine.mechanism import Mechanism
from mbs_models.scenes import list_scenes, scene_path


def solved(scene, end_time):
    """The mechanism and samples ``simulate`` hands to the post-processing."""
    seen = {}
    original = result_builder.analyse

    def spy(mechanism, samples, *args, **kwargs):
        seen.update(mechanism=mechanism, samples=samples)
        return original(mechanism, samples, *args, **kwargs)

    result_builder.analyse = spy
    try:
        simulate(scene, end_time, "standard")
    finally:
        result_builder.analyse = original
    return seen["mechanism"], seen["samples"]


def test_an_episode_lifted_over_the_threshold_by_its_refined_peak_gets_refined_bounds(one_bracket_crossing):
    """Its bounds are searched after the peaks (the second round): the same bits as when its samples
    alone make it an impact, and as the one-bracket search."""
    mechanism, s = solved(model_ii(1000.0, 0.0), 2.0)
    interp = Interpolant(s)
    contact = mechanism.contacts[0]
    force = s.forces[contact.name]
    every = refine(mechanism, s.time, s.forces, interp, [contact], 0.0)[0][contact.name]  # all surely impacts
    lifted = np.flatnonzero((every.peak_force > force[every.k]) & (every.first > 0) & (every.last < len(s.time) - 1))
    assert len(lifted)
    e = int(lifted[0])
    threshold = 0.5 * (force[every.k[e]] + every.peak_force[e])  # above the samples, below the refined peak
    late = refine(mechanism, s.time, s.forces, interp, [contact], threshold)[0][contact.name]
    assert late.peak_force[e] > threshold >= force[late.first[e]:late.last[e] + 1].max()
    assert (late.start[e], late.end[e]) == (every.start[e], every.end[e])
    assert late.start[e] < s.time[late.first[e]] and late.end[e] > s.time[late.last[e]]

    def positive(t):
        d = mechanism.relative(contact, {n: interp.x[n](t) for n in interp.names})
        rate = mechanism.relative(contact, {n: interp.v[n](t) for n in interp.names})
        return contact.force(d, rate, t) > 0.0

    t, i0, i1 = s.time, late.first[e], late.last[e]
    assert late.start[e] == one_bracket_crossing(positive, t[i0 - 1], t[i0])
    assert late.end[e] == one_bracket_crossing(lambda x: ~positive(x), t[i1], t[i1 + 1])


#: The shipped scenes with several contacts (absorbers or end stops).
SEVERAL_CONTACTS = [name for name in list_scenes() if len(Mechanism(load_scene(scene_path(name))).contacts) > 1]


@pytest.mark.parametrize("name", SEVERAL_CONTACTS)
def test_contacts_together_equal_contacts_alone(name):
    """Several contacts and the support peak share the rounds; each gets what it gets alone."""
    mechanism, s = solved(load_scene(scene_path(name)), 3.0)
    interp = Interpolant(s)
    together, support = refine(mechanism, s.time, s.forces, interp, mechanism.contacts, 1000.0, 10)
    assert support == refine(mechanism, s.time, s.forces, interp, [], 1000.0, 10)[1]
    for contact in mechanism.contacts:
        alone = refine(mechanism, s.time, s.forces, interp, [contact], 1000.0)[0][contact.name]
        for field in ("first", "last", "k", "peak_force", "time_of_peak_force", "start", "end"):
            assert np.array_equal(getattr(together[contact.name], field), getattr(alone, field)), (contact.name, field)


def _episodes(first, peaks) -> Episodes:
    """Episodes with these first samples and peak forces (N); the other fields do not decide impacts."""
    first, peaks = np.array(first), np.array(peaks, dtype=float)
    return Episodes(first=first, last=first + 1, k=first, peak_force=peaks, time_of_peak_force=first * 1e-3,
                    start=first * 1e-3, end=first * 1e-3 + 1e-3)


def test_an_impact_rises_by_the_threshold_above_the_force_at_rest_it_began_with():
    """DESIGN.md: ``peak - B > threshold``; B = 0 for an episode beginning inside the window, the contact's
    force at rest at t = 0 for the one going on at the first sample.  Hand-made episodes, threshold 1 kN."""
    # a 8.5 kN preload's hold that never rises, an onset at 5 kN, an onset at 1 kN exactly (not above)
    held = _episodes([0, 40, 90], [8500.0, 5000.0, 1000.0])
    assert held.impact_mask(1000.0, 8500.0).tolist() == [False, True, False]
    # the same hold pressed 1.5 kN harder is an impact; 0.5 kN harder is not
    assert _episodes([0], [10000.0]).impact_mask(1000.0, 8500.0).tolist() == [True]
    assert _episodes([0], [9000.0]).impact_mask(1000.0, 8500.0).tolist() == [False]
    # without an initial interference (B = 0) the rule is the peak above the threshold, at t = 0 too
    assert held.impact_mask(1000.0).tolist() == [True, True, False]
    # the force at rest at t = 0 concerns only the episode going on at the first sample
    assert _episodes([3, 50], [8500.0, 8500.0]).impact_mask(1000.0, 8500.0).tolist() == [True, True]


@pytest.mark.parametrize("name", SEVERAL_CONTACTS)
def test_batches_of_episodes_equal_one_batch(name, monkeypatch):
    """Refined in batches of a few episodes (a long chattering run is), every contact gets what it gets in one
    batch, and so does the support peak."""
    mechanism, s = solved(load_scene(scene_path(name)), 3.0)
    interp = Interpolant(s)
    whole, support = refine(mechanism, s.time, s.forces, interp, mechanism.contacts, 1000.0, 10)
    assert sum(len(e.first) for e in whole.values()) > 3  # several batches below
    monkeypatch.setattr(refinement, "EPISODES_PER_BATCH", 2)
    batched, batched_support = refine(mechanism, s.time, s.forces, interp, mechanism.contacts, 1000.0, 10)
    assert batched_support == support
    for contact in mechanism.contacts:
        for field in Episodes.__dataclass_fields__:
            assert np.array_equal(getattr(batched[contact.name], field), getattr(whole[contact.name], field)), \
                (contact.name, field)


def test_a_contact_s_refinement_interpolates_its_own_two_bodies_only(monkeypatch):
    """The O(bodies x contacts) trap: with many absorbers, every round interpolated every body at every
    contact's times.  Each contact's search asks for its own bodies (the barrel and its absorber), and the
    support peak for the bodies on the ground's connectors."""
    mechanism, s = solved(load_scene(scene_path("two_absorbers")), 3.0)
    interp = Interpolant(s)
    asked = []
    original = Interpolant.state

    def spy(self, t, bodies=None):
        asked.append(bodies)
        return original(self, t, bodies)

    monkeypatch.setattr(Interpolant, "state", spy)
    refine(mechanism, s.time, s.forces, interp, mechanism.contacts, 1000.0, 10)
    assert asked and None not in asked
    contact_bodies = {tuple(sorted({c.a, c.b} - {"ground"})) for c in mechanism.contacts}
    ground_ends = {end for c in mechanism.connectors if c.support_sign for end in (c.a, c.b)} - {"ground"}
    assert {tuple(sorted(b)) for b in asked} <= contact_bodies | {tuple(sorted(ground_ends))}
    assert all(len(b) == 2 for b in asked if set(b) != ground_ends)


def test_state_of_some_bodies_is_the_same_floats_as_of_all():
    """Interpolant.state(t, bodies) gives each body's position and velocity bit for bit as state(t)."""
    mechanism, s = solved(load_scene(scene_path("two_absorbers")), 3.0)
    interp = Interpolant(s)
    t = np.linspace(0.0, 3.0, 1001)
    x, v = interp.state(t)
    names = interp.names[::-1][:2]
    some_x, some_v = interp.state(t, names)
    assert list(some_x) == names
    for name in names:
        assert np.array_equal(some_x[name], x[name]) and np.array_equal(some_v[name], v[name])
