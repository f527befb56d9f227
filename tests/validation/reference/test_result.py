"""The reference result's outputs (validation.reference.result): names, histories, support force, energies,
per-contact, per-absorber and per-stop metrics, against definitions and conservation laws.  The scenes of
every element are composed by tests/conftest.py (``every_element``); what is particular to one element is in
its test file (tests/elements/)."""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest

from mbs_models.elements.contact_laws import LawFields
from mbs_models.scene import Conventions, load_scene, model_i, model_ii, simplified_model
from validation.reference import solve_reference
from validation.reference.model import GROUND

END = 3.0  # s: the every-element scenes fire a burst (last shot 1.2 s) and return onto the battery stop after it


#: two absorbers (front: ground, hunt-crossley, gap 0; rear: barrel, lankarani-nikravesh, gap 10 mm)
TWO = load_scene(Path(__file__).parent / "data" / "two_absorbers.toml")

SCENES = {
    "simplified": simplified_model(),
    "i": model_i(500.0, 0.0),
    "ii": model_ii(1000.0, 0.04),
    "two-absorbers": TWO,
}
#: scenes of every element: these with every other table of the shipped examples (``every_element``)
EVERY = {"two-absorbers-every-element": TWO, "ii-every-element": model_ii(100.0, 0.0)}
KEYS = [*SCENES, *EVERY]


@pytest.fixture(scope="module")
def scenes(every_element) -> dict:
    return {**SCENES, **{key: every_element(base) for key, base in EVERY.items()}}


@pytest.fixture(scope="module")
def solved(scenes):
    """``solved(key)``: the reference solution of ``scenes[key]`` over END (cached).  The scenes of every element
    refine the power-law releases (``refine_releases``; the default keeps version 1's record): their stops'
    ``k p^n`` is only C^1 at release, and one long step across a recoil-stop release lost 4.5e-7 of the energy
    of ii-every-element once the recoil brake joined the elements (2.6e-10 refined)."""
    return functools.lru_cache(maxsize=None)(lambda key: solve_reference(scenes[key], END,
                                                                         refine_releases=key in EVERY))


def grid(n=4001):
    return np.linspace(0.0, END, n)


def other_contacts(scene) -> set[str]:
    """The connectors of the tables other than the absorbers that carry a contact law: DESIGN.md names each
    like its table; the reference reports them as stops (per-stop metrics)."""
    return {name for name, table in scene.elements() if isinstance(table, LawFields)}


def test_names_follow_design(solved, scenes, design_connectors):
    key = "two-absorbers-every-element"
    r, scene = solved(key), scenes[key]
    assert r.bodies == ("barrel", "front", "rear")
    assert r.connectors == design_connectors(scene)
    assert r.connectors[:6] == ("recoil_spring", "recoil_damper", "front_damper", "front_contact", "rear_damper",
                                "rear_contact")
    others = other_contacts(scene)
    assert others and set(r.contacts) == {"front_contact", "rear_contact"} | others
    assert [m.name for m in r.absorber_metrics] == ["front", "rear"] and set(r.stop_metrics) == others
    # the pure spring only stores energy, the pure damper only dissipates it, every contact law does both;
    # every connector does one or the other
    dissipating, storing = set(r.dissipated_energy), set(r.stored_energy(0.1))
    assert "recoil_spring" in storing - dissipating and "recoil_damper" in dissipating - storing
    assert set(r.contacts) <= dissipating & storing and dissipating | storing == set(r.connectors)
    assert set(r.kinetic_energy(0.1)) == {"barrel", "front", "rear"}
    one = solved("ii")
    assert one.bodies == ("barrel", "absorber") and one.connectors[-2:] == ("absorber_damper", "contact")
    assert solved("simplified").bodies == ("barrel",) and solved("simplified").connectors == ("recoil_spring",
                                                                                              "recoil_damper")


@pytest.mark.parametrize("key", KEYS)
def test_histories_are_derivatives_of_each_other(key, solved):
    r = solved(key)
    t = grid(20001)
    h = t[1] - t[0]
    # a shot of a burst jumps the velocity: the central differences next to it do not see it
    jumps = [s for impulse in r.model.impulses for s in impulse.times]
    away = np.all([np.abs(t - s) > 1.5 * h for s in jumps], axis=0) if jumps else np.ones_like(t, dtype=bool)
    assert away.mean() > 0.99
    for body in r.bodies:
        x, v, a = r.position(body, t), r.velocity(body, t), r.acceleration(body, t)
        scale_v, scale_a = np.max(np.abs(v)) + 1e-9, np.max(np.abs(a)) + 1e-9
        np.testing.assert_allclose(np.gradient(x, h)[1:-1][away[1:-1]], v[1:-1][away[1:-1]], atol=1e-3 * scale_v,
                                   err_msg=body)
        smooth = np.abs(np.gradient(v, h) - a) < 1e-2 * scale_a  # velocity kinks at impacts are excluded
        assert smooth.mean() > 0.97, body


@pytest.mark.parametrize("key", KEYS)
def test_support_force_is_minus_the_rate_of_momentum(key, solved):
    """S = -(M a_M + sum m_i a_i) plus the external loads (which act on a body, not through the mount), to
    round-off of the forces."""
    r = solved(key)
    t = grid()
    momentum_rate = sum(mass * r.acceleration(b, t) for b, mass in zip(r.bodies, [b.mass for b in r.model.bodies]))
    loads = sum((load.force(t) for load in r.model.loads), 0.0 * t)
    scale = max(np.max(np.abs(r.connector_force(c, t))) for c in r.connectors)
    np.testing.assert_allclose(r.support_force(t), loads - momentum_rate, rtol=0, atol=1e-9 * scale)


def test_support_force_of_the_paper_model_is_its_grounded_connectors_forces(solved):
    """Model (ii): S = k x_M + c(v_M) v_M + k_r x_m + c_r v_m, written out."""
    r = solved("ii")
    t = grid()
    x, v, x_m, v_m = r.position("barrel", t), r.velocity("barrel", t), r.position("absorber", t), r.velocity("absorber", t)
    c = np.where(v > 0, 6239.0, 14050.0)
    expected = 27500.0 * x + c * v + 13500.0 * x_m + 3675.0 * v_m
    np.testing.assert_allclose(r.support_force(t), expected, rtol=1e-12, atol=1e-9 * np.max(np.abs(expected)))


@pytest.mark.parametrize("key", KEYS)
def test_support_force_is_the_grounded_connectors_forces(key, solved):
    """DESIGN.md: S = sum of F over the connectors ground -> body, minus those body -> ground (each element's
    own test checks which way its connectors point)."""
    r = solved(key)
    t = grid()
    forces = {c.name: r.connector_force(c.name, t) for c in r.model.connectors}
    expected = sum(forces[c.name] for c in r.model.connectors if c.a == GROUND) \
        - sum(forces[c.name] for c in r.model.connectors if c.b == GROUND)
    np.testing.assert_allclose(r.support_force(t), expected, rtol=1e-12, atol=1e-9 * np.max(np.abs(expected)))


@pytest.mark.parametrize("key", KEYS)
def test_peak_support_force_is_refined(key, solved):
    r = solved(key)
    t = grid(40001)
    s = np.abs(r.support_force(t))
    assert r.peak_support_force >= s.max() and r.peak_support_force >= 0
    assert r.peak_support_force == pytest.approx(s.max(), rel=1e-4)
    assert abs(r.support_force(r.time_of_peak_support_force)) == pytest.approx(r.peak_support_force, rel=1e-12)


@pytest.mark.parametrize("key", KEYS)
def test_energy_balance_closes_part_by_part(key, solved, scenes):
    r = solved(key)
    t = grid()
    total = sum(r.kinetic_energy(t).values()) + sum(r.stored_energy(t).values()) + \
        sum(r.dissipated_energy_history(t).values())
    work = sum(r.work_history(t).values(), 0.0 * t)  # the work of a burst's later shots and of loads (gravity)
    total = total - work
    np.testing.assert_allclose(total, r.energy_balance(t), rtol=1e-13)
    # the barrel alone moves at t = 0; what is stored then (a preload held in battery) is part of the initial energy
    assert r.kinetic_energy(0.0)["barrel"] == pytest.approx(0.5 * scenes[key].barrel.mass
                                                            * scenes[key].initial_velocity ** 2, rel=1e-15)
    assert r.initial_energy == pytest.approx(sum(r.kinetic_energy(0.0).values())
                                             + sum(r.stored_energy(0.0).values()), rel=1e-15)
    # relative to the energy that flows through the mechanism: the initial energy and the largest work done
    assert np.max(np.abs(total - r.initial_energy)) < 1e-7 * (abs(r.initial_energy) + np.max(np.abs(work)))
    for name, history in r.dissipated_energy_history(t).items():
        assert np.all(np.diff(history) >= -1e-9 * r.initial_energy), name  # every connector only dissipates


def test_absorber_specific_outputs_need_one_absorber(solved):
    r = solved("two-absorbers")
    for call in (lambda: r.absorber_position(0.1), lambda: r.penetration(0.1), lambda: r.contact_force(0.1),
                 lambda: r.accelerations(0.1), lambda: r.contact_episodes, lambda: r.absorber_velocity(0.1)):
        with pytest.raises(ValueError, match="2 absorbers"):
            call()
    simple = solved("simplified")
    assert simple.contact_force(0.3) == 0.0 and simple.accelerations(0.3).shape == (2,)
    assert simple.peak_contact_force is None and simple.max_absorber_velocity is None and simple.impacts == []
    assert simple.absorber_metrics == [] and simple.contacts == {} and simple.stop_metrics == {}


def test_largest_over_absorbers_and_impacts_in_time_order(solved):
    r = solved("two-absorbers-every-element")
    per = {m.name: m for m in r.absorber_metrics}
    assert r.peak_contact_force == max(m.peak_contact_force for m in per.values())
    assert r.max_absorber_velocity == max(m.max_velocity for m in per.values())
    best = max(per.values(), key=lambda m: m.peak_contact_force)
    assert r.time_of_peak_contact_force == best.time_of_peak_contact_force
    assert r.connector_force(f"{best.name}_contact", r.time_of_peak_contact_force) == pytest.approx(
        r.peak_contact_force, rel=1e-12)
    for m in per.values():
        assert r.velocity(m.name, m.time_of_max_velocity) == pytest.approx(m.max_velocity, rel=1e-12)
        assert r.acceleration(m.name, m.time_of_max_velocity) == pytest.approx(0.0, abs=1e-6)
        assert m.impacts == r.contacts[f"{m.name}_contact"].impacts
    starts = [i.start for i in r.impacts]
    assert starts == sorted(starts)
    assert sorted((i.start, i.contact) for i in r.impacts) == sorted(
        (i.start, i.contact) for m in per.values() for i in m.impacts)
    assert {i.contact for i in r.impacts} == {"front_contact", "rear_contact"}  # both absorbers are hit
    assert r.stop_metrics and any(stop.impacts for stop in r.stop_metrics.values())
    for stop in r.stop_metrics.values():  # stops are not absorbers' impacts
        assert all(i.contact == stop.name for i in stop.impacts)
        assert stop.impacts == r.contacts[stop.name].impacts
        # (a stop the barrel never reaches -- gravity keeps an unpreloaded barrel from battery -- dissipates 0)
        assert stop.dissipated_energy == r.dissipated_energy[stop.name] >= 0
        assert (stop.dissipated_energy > 0) == bool(stop.episodes)


def test_contact_episodes_and_onsets(solved):
    r = solved("two-absorbers-every-element")
    t = grid(40001)
    for name, contact in r.contacts.items():
        force = r.connector_force(name, t)
        assert np.all(force >= 0), name
        for e in contact.episodes:
            assert e.start <= e.time_of_peak <= e.end and e.contact == name
            assert r.connector_force(name, e.time_of_peak) == pytest.approx(e.peak_force, rel=1e-12)
            inside = (t > e.start) & (t < e.end)
            assert np.all(force[inside] <= e.peak_force * (1 + 1e-12))
        for a, b in zip(contact.episodes, contact.episodes[1:]):
            assert a.end <= b.start
        # no episode here is going on at t = 0 (the shot clips the preloaded buffer's force at once), so each began
        # from 0 N at rest and an impact is an episode peaking above the threshold
        assert all(e.start > 0.0 for e in contact.episodes)
        assert contact.impacts == [e for e in contact.episodes if e.peak_force > 1000.0]
        c = r.model.connector(name)
        for time, v_minus in contact.onsets:  # onset: p = 0 turning positive at the rate v-
            if time == 0.0 and c.d_of(r.state(0.0)) - c.offset > 0:  # an initial interference (a preload's hold)
                assert v_minus == max(c.rate_of(r.state(0.0)), 0.0)
                continue
            assert abs(c.d_of(r.state(time)) - c.offset) < 1e-12
            assert c.rate_of(r.state(time)) == pytest.approx(v_minus, rel=1e-9, abs=1e-12)
        assert len(contact.onsets) >= len(contact.episodes)
        assert contact.episodes or name in r.stop_metrics, name  # a stop may be out of reach (gravity)
    assert all(r.contacts[f"{m.name}_contact"].episodes for m in r.absorber_metrics)
    assert any(r.contacts[name].episodes for name in r.stop_metrics)


def test_restitution_laws_use_the_onset_rate_of_their_episode(solved):
    """Lankarani-Nikravesh: F = k p^n (1 + chi p'/v^), chi = 3 (1 - e^2)/4, v^ = max(v-, 1 mm/s)."""
    r = solved("two-absorbers")
    chi = 3 * (1 - 0.5 ** 2) / 4
    onsets = r.contacts["rear_contact"].onsets
    assert onsets
    c = r.model.connector("rear_contact")
    for start, v_minus in onsets:
        episode = next(e for e in r.contacts["rear_contact"].episodes if e.start == start)
        t = np.linspace(episode.start, episode.end, 50)[1:-1]
        y = r.state(t)
        p, rate = c.d_of(y) - c.offset, c.rate_of(y)
        expected = np.maximum(1e8 * np.maximum(p, 0) ** 1.5 * (1 + chi * rate / max(v_minus, 1e-3)), 0)
        np.testing.assert_allclose(r.connector_force("rear_contact", t), expected, rtol=1e-12,
                                   atol=1e-12 * episode.peak_force)


def test_metrics_dictionary(solved):
    r = solved("two-absorbers-every-element")
    m = r.metrics()
    for key in ("max_barrel_displacement", "time_of_max_barrel_displacement", "peak_contact_force",
                "time_of_peak_contact_force", "max_absorber_velocity", "time_of_max_absorber_velocity", "impacts",
                "peak_support_force", "time_of_peak_support_force", "absorbers", "stops", "end_time",
                "requested_end_time", "stop_reason", "final_metrics", "dissipated_energy", "wall_time"):
        assert key in m, key
    assert [a["name"] for a in m["absorbers"]] == ["front", "rear"]
    assert m["stops"] and set(m["stops"]) == set(r.stop_metrics)
    assert set(m["impacts"][0]) == {"start", "end", "peak_force", "time_of_peak", "contact"}
    for name, stop in m["stops"].items():
        assert stop["dissipated_energy"] == m["dissipated_energy"][name] >= 0
    assert any(stop["dissipated_energy"] > 0 for stop in m["stops"].values())
    import json
    json.dumps(m)  # plain values


def test_sample_keys(solved):
    s = solved("ii").sample(11)
    for key in ("t", "x_M", "v_M", "x_m", "v_m", "contact_force", "penetration", "support_force", "x:absorber",
                "F:contact", "E_recoil_damper", "E_absorber_damper", "E_contact"):
        assert s[key].shape == (11,), key
    several = solved("two-absorbers").sample(5)
    assert "x_m" not in several and several["x:rear"].shape == (5,)


# ------------------------------------------------------------------ which episodes are impacts (DESIGN.md)
def test_an_initial_interference_approached_at_t0_is_an_impact():
    """The paper's literal gap sign makes a 1 mm gap an interference that the barrel approaches at v0: at t = 0
    Hunt-Crossley's ``k p^n (1 + lambda v0)`` exceeds the static ``k p^n`` by ``k p^n lambda v0`` (10.9 kN)."""
    scene = model_ii(1000.0, 0.001, Conventions(literal_gap_sign=True))
    r = solve_reference(scene, 0.5)
    static = 2.1e8 * 0.001 ** 1.3
    first = r.contacts["contact"].episodes[0]
    assert first.start == 0.0 and first.peak_force - static > 10000.0
    assert r.impacts[0] == first


def test_a_single_shot_returns_to_battery_as_the_closed_form_says():
    """``time_to_battery`` against the simplified model's closed form (tests/battery_return.py); the reference's
    tolerances (rtol 1e-10) leave its error near 1e-9, 1e-7 is a margin for any machine."""
    from battery_return import simplified_return

    scene = simplified_model()
    _, x_max, t_back = simplified_return(scene)
    reference = solve_reference(scene, 5.0)
    assert reference.max_barrel_displacement == pytest.approx(x_max, rel=1e-7)
    assert reference.time_to_battery == pytest.approx(t_back, rel=1e-7)
    assert solve_reference(scene, 1.5).time_to_battery is None     # not back yet
