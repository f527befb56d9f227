"""Absorbers (mbs_models.elements.absorber): one or several, each with its mount, actuator and contact."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mbs_models import Absorber, Contact, SceneError, load_scene, model_i, model_ii, scene_from_dict, simulate
from mbs_models.engine.assembly import assemble
from mbs_models.scenes import scene_path

PAPER_CONTACT = dict(stiffness=2.1e8, exponent=1.3, damping_factor=0.6)


def halves(scene, mount="ground"):
    """Two identical absorbers, each with half the mass, k_r, c_r and k_c of the scene's one."""
    a = scene.absorber
    half = Absorber(a.mass / 2, mount, a.stiffness / 2, a.damping / 2,
                    contact=Contact(gap=a.contact.gap, stiffness=a.contact.stiffness / 2, exponent=a.contact.exponent,
                                    damping_factor=a.contact.damping_factor))
    return scene.with_changes(absorbers=(half, half), name="two halves")


@pytest.mark.parametrize("factory, mount", [(model_ii, "ground"), (model_i, "barrel")])
@pytest.mark.parametrize("accuracy, tolerance", [("standard", 1e-7), ("reference", 1e-9)])
def test_two_halves_move_exactly_as_one_absorber_and_each_carries_half_the_force(factory, mount, accuracy, tolerance):
    """Equations: m/2 x'' = -(k_r/2) x - (c_r/2) x' + (k_c/2) p^n (1 + lambda p') is m x'' = ... halved, so
    both halves move as the one absorber and each carries half its force; only the solver's steps differ."""
    one = simulate(factory(1000.0, 0.02), 3.0, accuracy)
    two = simulate(halves(factory(1000.0, 0.02), mount), 3.0, accuracy)
    np.testing.assert_array_equal(two.positions["absorber_1"], two.positions["absorber_2"])
    np.testing.assert_array_equal(two.contacts["absorber_1_contact"].force, two.contacts["absorber_2_contact"].force)
    assert two.max_barrel_displacement == pytest.approx(one.max_barrel_displacement, rel=tolerance)
    assert two.max_absorber_velocity == pytest.approx(one.max_absorber_velocity, rel=10 * tolerance)
    for name in ("absorber_1_contact", "absorber_2_contact"):
        assert two.contacts[name].peak_force == pytest.approx(one.peak_contact_force / 2, rel=10 * tolerance)
    assert two.peak_contact_force == pytest.approx(one.peak_contact_force / 2, rel=10 * tolerance)
    assert two.peak_support_force == pytest.approx(one.peak_support_force, rel=10 * tolerance)
    assert len(two.impacts) == 2 * len(one.impacts)


@pytest.mark.parametrize("mount, stiffness, damping", [("ground", 5000.0, 1000.0), ("barrel", 0.0, 0.0)],
                         ids=["on-the-ground", "free-on-the-barrel"])
def test_an_absorber_whose_gap_never_closes_changes_nothing(mount, stiffness, damping):
    """A second absorber 0.5 m away (beyond any travel) adds a body that stays at rest and a contact that
    never closes: the barrel and the first absorber move as without it.  (On the barrel with an actuator
    it would not: the actuator carries it with the barrel, adding its inertia.)"""
    scene = model_ii(1000.0, 0.0)
    far = Absorber(300.0, mount, stiffness, damping, contact=Contact(gap=0.5, **PAPER_CONTACT), name="far")
    near = scene.absorber.__class__(**{**scene.absorber.__dict__, "name": "near"})
    alone = simulate(scene, 5.0, "reference")
    both = simulate(scene.with_changes(absorbers=(near, far)), 5.0, "reference")
    assert np.all(both.positions["far"] == 0.0) and both.contacts["far_contact"].peak_force == 0.0
    assert both.max_barrel_displacement == pytest.approx(alone.max_barrel_displacement, rel=1e-9)
    assert both.contacts["near_contact"].peak_force == pytest.approx(alone.peak_contact_force, rel=1e-8)
    assert both.peak_contact_force == pytest.approx(alone.peak_contact_force, rel=1e-8)
    assert both.peak_support_force == pytest.approx(alone.peak_support_force, rel=1e-8)
    assert [i.start for i in both.impacts] == pytest.approx([i.start for i in alone.impacts], abs=1e-6)


def test_several_absorbers_report_per_absorber_and_overall():
    result = simulate(load_scene(scene_path("two_absorbers")), 3.0)
    assert result.absorber_names == ["front", "rear"]
    assert result.absorber_position is None and result.contact_force is None  # version-1 shortcuts: one absorber
    per = {a["name"]: a for a in result.absorbers()}
    assert result.peak_contact_force == max(a["peak_contact_force"] for a in per.values())
    assert result.max_absorber_velocity == max(a["max_absorber_velocity"] for a in per.values())
    starts = [i.start for i in result.impacts]
    assert starts == sorted(starts) and {i.contact for i in result.impacts} == {"front_contact", "rear_contact"}
    assert len(result.impacts) == sum(len(a["impacts"]) for a in per.values())
    assert set(result.dissipated_energy) == {"recoil_damper", "front_damper", "front_contact", "rear_damper",
                                             "rear_contact"}
    data = json.loads(json.dumps(result.metrics(), allow_nan=False))
    assert [a["name"] for a in data["absorbers"]] == ["front", "rear"] and data["stops"] == []
    energy = data["energy"]
    assert set(energy) == {"barrel", "recoil_spring", "recoil_damper", "front", "rear"}
    total = sum(sum(parts.values()) for parts in energy.values())
    assert total == pytest.approx(result.kinetic_energy_history[0], rel=1e-5)  # element by element, it adds up


def test_the_force_on_the_mount_is_minus_the_rate_of_momentum():
    """No external force: S = -(M a_M + sum m_i a_i) at every output sample (ground-mounted actuators pass
    their force to the mount, barrel-mounted ones through the barrel)."""
    scene = load_scene(scene_path("two_absorbers"))
    scene = scene.with_changes(**{"absorber.1.mount": "barrel"})
    result = simulate(scene, 2.0)
    momentum_rate = sum(body.mass * result.accelerations[name] for name, body in
                        (("barrel", scene.barrel), ("front", scene.absorbers[0]), ("rear", scene.absorbers[1])))
    np.testing.assert_allclose(result.support_force, -momentum_rate, rtol=0, atol=1e-9 * np.max(np.abs(momentum_rate)))


def test_assembly_adds_one_body_and_two_connectors_per_absorber():
    with assemble(load_scene(scene_path("two_absorbers"))) as assembly:
        assert set(assembly.nodes) == {"barrel", "front", "rear"}
        assert set(assembly.connectors) == {"recoil_spring", "recoil_damper", "front_damper", "front_contact",
                                            "rear_damper", "rear_contact"}
        assert sorted(assembly.user_function_connectors) == ["front_contact", "rear_contact", "recoil_damper"]
        assert {"front_contact_force", "rear_contact_force"} <= set(assembly.sensors)
    bare = model_ii(1000.0, 0.0).with_changes(**{"absorber.stiffness": 0.0, "absorber.damping": 0.0})
    with assemble(bare) as assembly:  # no actuator at all: no connector for it
        assert "absorber_damper" not in assembly.connectors


def test_dotted_keys_address_absorbers():
    scene = load_scene(scene_path("two_absorbers"))
    assert scene.with_changes(**{"absorber.1.contact.gap": 0.05}).absorbers[1].contact.gap == 0.05
    assert scene.with_changes(**{"absorber.0.mass": 700.0}).absorbers[0].mass == 700.0
    with pytest.raises(SceneError, match=r"absorber\.N\.mass"):
        scene.with_changes(**{"absorber.mass": 700.0})  # two absorbers: say which
    with pytest.raises(SceneError, match="index 2 does not exist"):
        scene.with_changes(**{"absorber.2.mass": 700.0})
    one = model_ii()
    assert one.with_changes(**{"absorber.0.contact.gap": 0.01}) == one.with_changes(**{"contact.gap": 0.01})


REFERENCE_SCENES = {
    "two-on-the-ground": lambda: load_scene(scene_path("two_absorbers")),
    "ground-and-barrel": lambda: load_scene(scene_path("two_absorbers")).with_changes(**{"absorber.1.mount": "barrel"}),
    "two-halves-on-the-barrel": lambda: halves(model_i(1000.0, 0.02), "barrel"),
}


@pytest.mark.parametrize("name", list(REFERENCE_SCENES))
def test_several_absorbers_agree_with_the_reference(agrees_with_reference, name):
    agrees_with_reference(REFERENCE_SCENES[name](), 3.0, "standard")


@pytest.mark.slow
@pytest.mark.parametrize("accuracy", ["draft", "standard", "reference"])
@pytest.mark.parametrize("name", list(REFERENCE_SCENES))
def test_several_absorbers_agree_with_the_reference_at_every_preset(agrees_with_reference, name, accuracy):
    agrees_with_reference(REFERENCE_SCENES[name](), 10.0, accuracy)


BAD_ABSORBERS = [
    ("missing-mass", "absorber.0.mass", "<delete>", "absorber.0.mass", "missing"),
    ("zero-mass", "absorber.1.mass", 0.0, "absorber.1.mass", "> 0 kg"),
    ("mass-string", "absorber.1.mass", "heavy", "absorber.1.mass", "must be a number"),
    ("unknown-mount", "absorber.0.mount", "roof", "absorber.0.mount", "unknown mount"),
    ("negative-damping", "absorber.1.damping", -1.0, "absorber.1.damping", ">= 0 N s/m"),
    ("missing-contact", "absorber.1.contact", "<delete>", "absorber.1.contact", "missing"),
    ("contact-not-a-table", "absorber.1.contact", 3.0, "absorber.1.contact", "must be a table"),
    ("missing-gap", "absorber.0.contact.gap", "<delete>", "absorber.0.contact.gap", "missing"),
    ("negative-gap", "absorber.0.contact.gap", -0.01, "absorber.0.contact.gap", ">= 0 m"),
    ("duplicate-names", "absorber.1.name", "front", "absorber.1.name", "names two absorbers"),
    ("bad-name", "absorber.1.name", "rear wheel", "absorber.1.name", "identifier"),
    ("unknown-key", "absorber.0.masss", 1.0, "absorber.0.masss", "did you mean 'mass'"),
]


@pytest.mark.parametrize("path, value, key, text", [c[1:] for c in BAD_ABSORBERS], ids=[c[0] for c in BAD_ABSORBERS])
def test_bad_absorber_tables_are_one_line_errors_naming_the_key(bad_input, v2_mapping, changed, path, value, key, text):
    bad_input(changed(v2_mapping, path, value), key, text)


def test_version_1_has_one_absorber_and_a_top_level_contact(bad_input, v1_mapping, v2_mapping, changed):
    several = dict(v1_mapping, absorber=[v1_mapping["absorber"], v1_mapping["absorber"]])
    bad_input(several, "absorber", "version-2 scene")
    nested = changed(v1_mapping, "absorber.contact", dict(v1_mapping["contact"]))
    bad_input(nested, "absorber.contact", "version-2 scene")
    twice = changed(v2_mapping, "contact", dict(v1_mapping["contact"]))
    bad_input(twice, "absorber", "exactly one absorber")
    single = dict(v2_mapping, absorber=[v2_mapping["absorber"][0]])
    single["absorber"][0] = {k: v for k, v in single["absorber"][0].items() if k != "contact"}
    single["contact"] = dict(v1_mapping["contact"])  # a version-1 pair inside a version-2 file: one absorber
    assert scene_from_dict(single).absorber.contact.gap == 0.0


def test_an_initial_interference_beyond_double_precision_is_refused(bad_input, v2_mapping):
    """literal_gap_sign: p(0) = gap.  k gap^n = 2.1e8 x (1e300)^1.3 overflows: refused naming the gap."""
    mapping = dict(v2_mapping, conventions={"literal_gap_sign": True})
    mapping["absorber"][0]["contact"] = dict(mapping["absorber"][0]["contact"], gap=1e300)
    bad_input(mapping, "absorber.0.contact.gap", "initial interference's force")
