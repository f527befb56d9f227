"""The Scene (``mbs_models/scene/container.py``): every body, connector, load and element of the assembled
mechanism has its own name -- outputs are keyed by these names and ``Result.energy()`` groups them by element."""

from __future__ import annotations

import copy

import pytest

from mbs_models import SceneError, model_ii, scene_from_dict


def refused(build, key: str, name: str) -> None:
    with pytest.raises(SceneError) as info:
        build()
    assert info.value.key == key and f"the name {name!r} is taken twice" in info.value.message, info.value
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("name", ["recoil_spring", "recoil_damper", "firing"])
def test_an_absorber_named_like_another_element_is_refused(name):
    """model (ii) has a [recoil_spring] (its connector recoil_spring), a [recoil_damper], a [firing]."""
    refused(lambda: model_ii(1000.0, 0.0).with_changes(**{"absorber.name": name}), "absorber.name", name)


def test_an_absorber_named_like_another_absorber_s_connector_is_refused(v2_mapping):
    """Absorbers front and front_damper: front's actuator is front_damper.  The later absorber is named."""
    mapping = copy.deepcopy(v2_mapping)
    mapping["absorber"][1]["name"] = "front_damper"
    refused(lambda: scene_from_dict(mapping), "absorber.1.name", "front_damper")
    mapping["absorber"][0]["name"], mapping["absorber"][1]["name"] = "rear_contact", "rear"
    refused(lambda: scene_from_dict(mapping), "absorber.1.name", "rear_contact")


@pytest.mark.parametrize("name", ["contact", "absorber_damper"])
def test_a_lone_absorber_named_like_its_own_connector_is_refused(name):
    """One absorber keeps the version-1 connector names absorber_damper and contact: its body may not take one."""
    refused(lambda: model_ii(1000.0, 0.0).with_changes(**{"absorber.name": name}), "absorber.name", name)


def test_an_absorber_named_like_a_load_is_refused(v2_mapping):
    """A [cradle] at 30 degrees adds the load gravity on the barrel."""
    mapping = dict(copy.deepcopy(v2_mapping), cradle={"elevation": 30.0})
    mapping["absorber"][0]["name"] = "gravity"
    refused(lambda: scene_from_dict(mapping), "absorber.0.name", "gravity")


def test_names_that_collide_with_nothing_are_kept(v2_mapping):
    mapping = copy.deepcopy(v2_mapping)
    mapping["absorber"][0]["name"], mapping["absorber"][1]["name"] = "damper", "contact"
    assert scene_from_dict(mapping).absorber_names() == ["damper", "contact"]


def test_a_colliding_name_in_a_file_is_one_line_on_the_command_line(bad_input, v2_mapping):
    mapping = copy.deepcopy(v2_mapping)
    mapping["absorber"][1]["name"] = "recoil_spring"
    bad_input(mapping, "absorber.1.name", "taken twice")
