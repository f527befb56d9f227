"""Scene validation through the Python API (mbs_models.scene, mbs_models.scene.io)."""

from __future__ import annotations

import copy
import math
import tomllib

import pytest

from mbs_models import (Absorber, Barrel, Contact, Conventions, SceneError, load_scene, model_i, model_ii,
                        scene_from_dict, scene_to_dict, scene_to_toml, simplified_model)
from mbs_models.scene import CONTACT_LAWS
from mbs_models.scenes import list_scenes, scene_path


def test_bad_scene_raises_scene_error_naming_the_key(bad_scene):
    data, key, text = bad_scene
    with pytest.raises(SceneError) as info:
        scene_from_dict(data)
    assert info.value.key == key
    assert str(info.value).startswith(f"{key}:")
    assert text in str(info.value)


def test_dataclasses_validate_when_built_in_python():
    with pytest.raises(SceneError, match=r"barrel\.mass"):
        Barrel(mass=-1.0, initial_velocity=0.7)
    with pytest.raises(SceneError, match=r"contact\.gap"):
        Contact(gap=math.nan, stiffness=1e8, exponent=1.5, damping_factor=0.1)
    with pytest.raises(SceneError, match=r"absorber\.mount"):
        Absorber(mass=1.0, mount="wall", stiffness=0.0, damping=0.0)
    with pytest.raises(SceneError, match=r"conventions\.compression_only"):
        Conventions(compression_only=1)


def test_malformed_toml_is_a_scene_error(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("[barrel\nmass = 1\n")
    with pytest.raises(SceneError, match="malformed TOML"):
        load_scene(path)


def test_missing_and_directory_paths_are_scene_errors(tmp_path):
    with pytest.raises(SceneError, match="not found"):
        load_scene(tmp_path / "nope.toml")
    with pytest.raises(SceneError, match="directory"):
        load_scene(tmp_path)


@pytest.mark.parametrize("scene", [simplified_model(), model_i(100.0, 0.04), model_ii(500.0, 0.12)],
                         ids=["simplified", "model-i", "model-ii"])
def test_toml_round_trip(tmp_path, scene):
    path = tmp_path / "scene.toml"
    path.write_text(scene_to_toml(scene))
    assert load_scene(path) == scene
    assert scene_from_dict(scene_to_dict(scene)) == scene


def test_shipped_scenes_are_the_paper_models_and_the_examples():
    assert {"model_i", "model_ii", "simplified"} <= set(list_scenes())
    examples = set(list_scenes()) - {"model_i", "model_ii", "simplified"}
    assert "two_absorbers" in examples
    assert {f"contact_{law.replace('-', '_')}" for law in CONTACT_LAWS} <= examples
    for name in examples:
        scene = load_scene(scene_path(name))  # every example is a valid version-2 scene
        assert tomllib.loads(scene_path(name).read_text())["version"] == 2 and scene.name
    assert load_scene(scene_path("simplified")) == simplified_model()
    assert load_scene(scene_path("model_i")) == model_i(1000.0, 0.0)
    assert load_scene(scene_path("model_ii")) == model_ii(1000.0, 0.0)


def test_initial_velocity_from_momentum_and_conventions():
    assert simplified_model().initial_velocity == pytest.approx(6.86 * 564 / 5600, rel=1e-15)
    rounded = simplified_model(Conventions(rounded_initial_velocity=True))
    assert rounded.initial_velocity == 0.7
    with_absorber = model_i(1000.0, 0.0, Conventions(v0_includes_absorber=True))
    assert with_absorber.initial_velocity == pytest.approx(6.86 * 564 / 6600, rel=1e-15)
    # the absorber on the ground does not ride on the barrel: v0 unchanged
    assert model_ii(1000.0, 0.0, Conventions(v0_includes_absorber=True)).initial_velocity == pytest.approx(0.6909)


def test_with_changes_revalidates():
    scene = model_ii(1000.0, 0.0)
    assert scene.with_changes(**{"contact.gap": 0.04}).contact.gap == 0.04
    with pytest.raises(SceneError, match=r"contact\.gap"):
        scene.with_changes(**{"contact.gap": -1.0})
    with pytest.raises(SceneError, match="no \\[absorber\\]"):
        simplified_model().with_changes(**{"absorber.mass": 1.0})


def test_model_labels():
    assert simplified_model().model_label == "simplified"
    assert model_i().model_label == "model (i)"
    assert model_ii().model_label == "model (ii)"


_VERSION_1_HEADERS = {"barrel", "firing", "recoil_spring", "recoil_damper", "absorber", "contact", "conventions"}


def _version_2_headers(text: str) -> list[str]:
    """The table headers of a TOML text that a version-1 file cannot have, as written in it."""
    import re

    headers = re.findall(r"^\s*(\[\[?[A-Za-z_.]+\]\]?)", text, flags=re.MULTILINE)
    return list(dict.fromkeys(h for h in headers if h.startswith("[[") or h.strip("[]") not in _VERSION_1_HEADERS))


@pytest.mark.parametrize("name", list_scenes())
def test_a_version_2_scene_without_its_version_key_says_so(tmp_path, name):
    text = scene_path(name).read_text()
    if "version = 2" not in text:
        pytest.skip("a version-1 scene")
    expected = _version_2_headers(text)
    if not expected:
        pytest.skip("uses no version-2 table (only version-2 values)")
    path = tmp_path / f"{name}.toml"
    path.write_text(text.replace("version = 2", ""))
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = info.value.message
    assert "has no version key" in message and message.endswith("add version = 2 at the top")
    assert "missing required table" not in message
    listed = message.split("(", 1)[1].split(")", 1)[0].split(", ")
    assert listed == expected
    path.write_text(text.replace("version = 2", "version = 1"))
    with pytest.raises(SceneError, match="says version = 1"):
        load_scene(path)


def test_the_version_2_message_names_the_first_table_as_its_key():
    data = {"name": "no version", "barrel": {"mass": 5600.0, "initial_velocity": 0.7},
            "absorber": [{"mass": 500.0, "mount": "ground", "stiffness": 0.0, "damping": 0.0,
                          "contact": {"gap": 0.0, "stiffness": 2.1e8, "exponent": 1.3, "damping_factor": 0.6}}],
            "recoil_brake": {}}
    with pytest.raises(SceneError) as info:
        scene_from_dict(data)
    assert info.value.key == "absorber"
    assert "([[absorber]], [absorber.contact], [recoil_brake])" in info.value.message


@pytest.mark.parametrize("wrong", [[1.0, "a"], {"a": 1.0}, 1.0, True, []], ids=["list", "table", "number", "bool",
                                                                                  "empty"])
def test_every_text_key_of_a_wrong_type_is_one_scene_error(tmp_path, wrong):
    """Every string-valued key of every shipped scene (a law, a mount, a name, a file) given another type, in a
    file and by --set: a SceneError naming it, never another exception (found by tests/test_fuzz.py: an
    unhashable list as a contact's law was looked up in the table of laws)."""
    from fuzz_scenes import _leaves, _toml_text

    from mbs_models import apply_overrides

    for name in list_scenes():
        data = tomllib.loads(scene_path(name).read_text())
        for path, value in _leaves(data):
            if not isinstance(value, str) or path == ("name",):
                continue
            changed = copy.deepcopy(data)
            target = changed
            for part in path[:-1]:
                target = target[part]
            target[path[-1]] = copy.deepcopy(wrong)
            file = tmp_path / "scene.toml"
            file.write_text(_toml_text(changed))
            key = ".".join(str(p) for p in path)
            try:
                load_scene(file)
            except SceneError as error:
                assert "\n" not in str(error), (name, key)
            if isinstance(wrong, (dict, list)) and not wrong:
                continue
            try:
                apply_overrides(load_scene(scene_path(name)), {key: wrong})
            except SceneError as error:
                assert "\n" not in str(error), (name, key)
