"""Dotted scene keys (mbs_models.scene.overrides): the same scene as one built with the values, one-line errors
naming the key as given, and the sweep specs."""

from __future__ import annotations

import pytest

from mbs_models import Conventions, SceneError, load_scene, model_i, model_ii
from mbs_models.elements.contact_laws import Contact
from mbs_models.scene.overrides import (apply_overrides, check_keys, parse_assignment, parse_spec, parse_value,
                                        resolve_key, spec_size)
from mbs_models.scenes import scene_path


def _named(scene, like):
    """``scene`` with the name of ``like`` (the overrides keep the scene's name)."""
    return scene.with_changes(name=like.name)


def test_one_absorber_keys_give_the_scene_built_with_those_values():
    changed = apply_overrides(model_i(500.0, 0.0), {"absorber.mass": 1000.0, "contact.gap": 0.04})
    assert changed == _named(model_i(1000.0, 0.04), changed)
    assert changed.name == model_i(500.0, 0.0).name
    for key in ("absorber.0.contact.gap", "absorber.contact.gap", "contact.gap"):
        changed = apply_overrides(model_ii(500.0, 0.0), {key: 0.08})
        assert changed == _named(model_ii(500.0, 0.08), changed)


def test_integers_and_conventions_and_name():
    changed = apply_overrides(model_ii(500.0, 0.0), {"absorber.mass": 1000, "conventions.literal_gap_sign": True,
                                                     "name": "x"})
    assert changed == _named(model_ii(1000.0, 0.0, Conventions(literal_gap_sign=True)), changed)
    assert changed.name == "x"
    assert isinstance(changed.absorber.mass, float)


def test_no_overrides_is_the_scene_itself():
    scene = model_i()
    assert apply_overrides(scene, {}) is scene


def test_indexed_absorbers_of_a_scene_with_several():
    scene = load_scene(scene_path("two_absorbers"))
    changed = apply_overrides(scene, {"absorber.1.contact.gap": 0.03, "absorber.0.mass": 700.0})
    assert changed.absorbers[1].contact.gap == 0.03 and changed.absorbers[0].mass == 700.0
    assert changed.absorbers[0].contact == scene.absorbers[0].contact
    assert changed.absorbers[1].mass == scene.absorbers[1].mass


def test_a_table_field_of_a_version_2_scene():
    scene = load_scene(scene_path("recoil_brake"))
    changed = apply_overrides(scene, {"recoil_brake.orifice_area": [[0.0, 3e-4], [0.3, 1e-4]],
                                      "recoil_spring.stiffness": 1000.0})
    assert changed.recoil_brake.orifice_area == ((0.0, 3e-4), (0.3, 1e-4))
    assert changed.recoil_spring.stiffness == 1000.0


def test_a_contact_law_changes_with_its_fields():
    changed = apply_overrides(model_i(), {"contact.law": "flores", "contact.restitution": 0.5})
    contact = model_i().contact
    assert changed.contact == Contact(gap=contact.gap, stiffness=contact.stiffness, exponent=contact.exponent,
                                      law="flores", restitution=0.5)
    assert apply_overrides(model_i(), {"contact.law": "hertz"}).contact.damping_factor is None
    with pytest.raises(SceneError) as info:
        apply_overrides(model_i(), {"contact.law": "flores"})
    assert info.value.key == "contact.restitution" and "flores" in info.value.message


@pytest.mark.parametrize("scene, overrides, key, needle", [
    (model_i(), {"contact.gapp": 0.1}, "contact.gapp", "did you mean 'gap'"),
    (model_i(), {"absorber.mas": 1.0}, "absorber.mas", "did you mean 'mass'"),
    (model_i(), {"recoil_sprin.stiffness": 1.0}, "recoil_sprin.stiffness", "did you mean 'recoil_spring'"),
    (model_i(), {"contact.gap": -0.01}, "contact.gap", ">= 0 m, got -0.01"),
    (model_i(), {"absorber.0.contact.gap": -0.01}, "absorber.0.contact.gap", ">= 0 m"),
    (model_i(), {"absorber.contact.gap": -0.01}, "absorber.contact.gap", ">= 0 m"),
    (model_i(), {"absorber.mass": "heavy"}, "absorber.mass", "must be a number"),
    (model_i(), {"absorber.mass": 0.0}, "absorber.mass", "> 0 kg"),
    (model_i(), {"contact.law": "flors"}, "contact.law", "did you mean 'flores'"),
    (model_i(), {"absorber.1.mass": 1.0}, "absorber.1.mass", "index 1 does not exist"),
    (model_i(), {"recoil_brake.orifice_area": 1e-4}, "recoil_brake.orifice_area", "no [recoil_brake] table"),
    (model_i(), {"contact": 1.0}, "contact", "names the table"),
    (model_i(), {"recoil_spring": 1.0}, "recoil_spring", "names a table"),
    (model_i(), {"recoil_spring.stiffness.x": 1.0}, "recoil_spring.stiffness.x", "is a value, not a table"),
    (model_i(), {"conventions.literal": True}, "conventions.literal", "did you mean"),
    (model_i(), {"conventions.literal_gap_sign": 1}, "conventions.literal_gap_sign", "true or false"),
    (model_i(), {"contact.gap": 0.1, "absorber.contact.gap": 0.2}, "absorber.contact.gap", "give it once"),
    (model_i(), {"": 1.0}, "", "not a dotted scene key"),
    (model_i(), {"contact..gap": 1.0}, "contact..gap", "not a dotted scene key"),
    (load_scene(scene_path("two_absorbers")), {"absorber.mass": 1.0}, "absorber.mass", "absorber.N.mass"),
    (load_scene(scene_path("two_absorbers")), {"contact.gap": 1.0}, "contact.gap", "absorber.N.contact.gap"),
    (load_scene(scene_path("simplified")), {"contact.gap": 1.0}, "contact.gap", "no absorber"),
])
def test_errors_are_one_line_and_name_the_key_as_given(scene, overrides, key, needle):
    with pytest.raises(SceneError) as info:
        apply_overrides(scene, overrides)
    assert info.value.key == key
    assert needle in info.value.message
    assert "\n" not in str(info.value)


def test_resolve_and_check_keys():
    assert resolve_key(model_i(), "contact.gap") == ("absorbers", 0, ("contact", "gap"))
    assert resolve_key(model_i(), "absorber.0.contact.gap") == ("absorbers", 0, ("contact", "gap"))
    assert resolve_key(model_i(), "recoil_damper.recoil") == ("recoil_damper", None, ("recoil",))
    assert check_keys(model_i(), ["contact.gap", "absorber.mass"]) == ["contact.gap", "absorber.mass"]
    with pytest.raises(SceneError, match="give it once"):
        check_keys(model_i(), ["contact.gap", "absorber.0.contact.gap"])


@pytest.mark.parametrize("text, value", [
    ("500", 500), ("1e-3", 1e-3), ("0.5", 0.5), ("true", True), ('"flores"', "flores"), ("flores", "flores"),
    ("hunt-crossley", "hunt-crossley"), ("[[0.0, 3e-4], [0.3, 1e-4]]", [[0.0, 3e-4], [0.3, 1e-4]]),
])
def test_values_read_as_toml(text, value):
    parsed = parse_value(text)
    assert parsed == value and type(parsed) is type(value)


@pytest.mark.parametrize("text, needle", [("", "no value"), ("nan", "finite"), ("[1, ", "not a TOML value"),
                                          ("{a = 1}", "table")])
def test_bad_values(text, needle):
    with pytest.raises(SceneError, match=needle) as info:
        parse_value(text, "contact.gap")
    assert info.value.key == "contact.gap"


def test_assignments():
    assert parse_assignment(" contact.gap = 0.01 ") == ("contact.gap", "0.01")
    for bad in ("contact.gap", "=1", "contact.gap="):
        with pytest.raises(SceneError):
            parse_assignment(bad)


def test_specs():
    assert parse_spec("100,500,1000") == [100, 500, 1000]
    assert parse_spec("hunt-crossley, hertz") == ["hunt-crossley", "hertz"]
    assert parse_spec("0.5") == [0.5]
    assert parse_spec("[[[0.0, 3e-4]], 2e-4]") == [[[0.0, 3e-4]], 2e-4]
    gaps = parse_spec("0:0.12:13")
    assert len(gaps) == 13 and gaps[0] == 0.0 and gaps[-1] == 0.12      # both ends exactly
    assert all(abs(g - 0.01 * i) < 1e-15 for i, g in enumerate(gaps))
    assert parse_spec("1:-1:3") == [1.0, 0.0, -1.0]
    # the points carry no round-off of their computation: the decimals one would type
    assert parse_spec("1e-4:3e-4:5") == [1e-4, 1.5e-4, 2e-4, 2.5e-4, 3e-4]
    assert parse_spec("0:0.12:25")[7] == 0.035
    thirds = parse_spec("0:1:4")
    assert thirds[1] == pytest.approx(1 / 3, rel=1e-15, abs=0) and thirds[2] == pytest.approx(2 / 3, rel=1e-15)
    masses = parse_spec("100:20000:40")
    assert all(m == pytest.approx(100 + i * 19900 / 39, rel=1e-15, abs=0) for i, m in enumerate(masses))


@pytest.mark.parametrize("spec, needle", [
    ("", "no values"), ("1:2", "START:STOP:COUNT"), ("1:2:3:4", "START:STOP:COUNT"), ("a:1:3", "must be numbers"),
    ("0:1:x", "whole number >= 2"), ("0:1:1", "whole number >= 2"), ("0:1:2.5", "whole number"),
    ("0:inf:3", "finite"), ("1,,2", "empty item"), ("[]", "non-empty"),
])
def test_bad_specs_name_the_key(spec, needle):
    with pytest.raises(SceneError, match=needle) as info:
        parse_spec(spec, "absorber.mass")
    assert info.value.key == "absorber.mass" and "\n" not in str(info.value)
    with pytest.raises(SceneError, match=needle):
        spec_size(spec, "absorber.mass")


@pytest.mark.parametrize("spec", ["100,500,1000", "0.5", "[[[0.0, 3e-4]], 2e-4]", "0:0.12:13", "1:-1:3"])
def test_spec_size_is_the_number_of_values(spec):
    assert spec_size(spec) == len(parse_spec(spec))


def test_spec_size_of_a_range_makes_no_values():
    assert spec_size("0:1:1000000000000") == 10**12   # 10^12 values would be 8 TB: the COUNT is read, not made


def test_a_value_nested_1000_deep_is_one_scene_error_naming_the_key():
    """``--set KEY=[[[...]]]``: the TOML parser recursed once per level (a RecursionError near 1000)."""
    with pytest.raises(SceneError, match="nested more than 32 deep") as info:
        parse_value("[" * 1000 + "]" * 1000, "contact.gap")
    assert info.value.key == "contact.gap"


def test_every_array_of_tables_takes_dotted_keys():
    """[[tabulated_damper]] like [[absorber]]: ``tabulated_damper.points`` when the scene has one, ``.N.`` to name
    one of several; an index beyond the array, or a bad table, is one SceneError naming the key (the slow
    extreme-value test set such keys and found them unknown)."""
    from mbs_models import load_scene
    from mbs_models.scenes import scene_path

    scene = load_scene(scene_path("tabulated_damper"))
    table = [[-1.0, -10.0], [0.0, 0.0], [1.0, 10.0]]
    changed = apply_overrides(scene, {"tabulated_damper.points": table})
    assert changed.tabulated_dampers[0].pairs == tuple(tuple(p) for p in table)
    assert apply_overrides(scene, {"tabulated_damper.0.points": table}) == changed
    with pytest.raises(SceneError) as info:
        apply_overrides(scene, {"tabulated_damper.2.points": table})
    assert info.value.key == "tabulated_damper.2.points" and "index 2 does not exist" in info.value.message
    with pytest.raises(SceneError) as info:
        apply_overrides(scene, {"tabulated_damper.points": [[-1.0, 10.0], [0.0, 0.0]]})
    assert info.value.key.startswith("tabulated_damper.points") and "passive" in info.value.message
    with pytest.raises(SceneError, match="no \\[\\[tabulated_spring\\]\\] table"):
        apply_overrides(scene, {"tabulated_spring.points": table})
