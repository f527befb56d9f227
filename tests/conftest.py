"""Shared fixtures: paper scenes as TOML mappings, and the table of bad-scene cases."""

from __future__ import annotations

import copy
import math

import pytest

import tomllib

from mbs_models.scenes import scene_path


def paper_scene_dict() -> dict:
    """Model (ii), m = 1000 kg, gap 0: the shipped version-1 file as a TOML mapping."""
    return tomllib.loads(scene_path("model_ii").read_text())


def edit(path: str, value):
    """An edit of a mapping: set the value at a dotted path (list indices as numbers)."""
    def apply(data: dict) -> dict:
        data = copy.deepcopy(data)
        *tables, key = path.split(".")
        target = data
        for table in tables:
            target = target[int(table)] if isinstance(target, list) else target[table]
        target[key] = value
        return data
    return apply


def delete(path: str):
    """An edit of a mapping: remove the key at a dotted path."""
    def apply(data: dict) -> dict:
        data = copy.deepcopy(data)
        *tables, key = path.split(".")
        target = data
        for table in tables:
            target = target[int(table)] if isinstance(target, list) else target[table]
        del target[key]
        return data
    return apply


#: (case id, edit of the valid mapping, key the error must name, text the message must contain)
BAD_SCENES = [
    ("unknown-key", edit("contact.stifness", 1.0), "contact.stifness", "did you mean 'stiffness'"),
    ("unknown-table", edit("absorbr", {}), "absorbr", "did you mean 'absorber'"),
    ("missing-key", delete("absorber.damping"), "absorber.damping", "missing"),
    ("missing-table", delete("recoil_spring"), "recoil_spring", "missing"),
    ("missing-velocity", delete("firing"), "barrel.initial_velocity", "missing"),
    ("wrong-type-string", edit("barrel.mass", "heavy"), "barrel.mass", "must be a number"),
    ("wrong-type-bool", edit("recoil_spring.stiffness", True), "recoil_spring.stiffness", "must be a number"),
    ("wrong-type-table", edit("contact", 3.0), "contact", "must be a table"),
    ("nan", edit("contact.damping_factor", math.nan), "contact.damping_factor", "finite"),
    ("infinite", edit("absorber.stiffness", math.inf), "absorber.stiffness", "finite"),
    ("zero-barrel-mass", edit("barrel.mass", 0.0), "barrel.mass", "> 0"),
    ("negative-absorber-mass", edit("absorber.mass", -5.0), "absorber.mass", "> 0"),
    ("negative-stiffness", edit("recoil_spring.stiffness", -1.0), "recoil_spring.stiffness", ">= 0"),
    ("negative-damping", edit("recoil_damper.counter_recoil", -1.0), "recoil_damper.counter_recoil", ">= 0"),
    ("negative-absorber-damping", edit("absorber.damping", -3.0), "absorber.damping", ">= 0"),
    ("zero-contact-stiffness", edit("contact.stiffness", 0.0), "contact.stiffness", "> 0"),
    ("zero-exponent", edit("contact.exponent", 0.0), "contact.exponent", "> 0"),
    ("negative-gap", edit("contact.gap", -0.001), "contact.gap", ">= 0"),
    ("absorber-without-contact", delete("contact"), "contact", "needs a [contact]"),
    ("contact-without-absorber", delete("absorber"), "absorber", "needs an [absorber]"),
    ("unknown-mount", edit("absorber.mount", "roof"), "absorber.mount", "unknown mount"),
    ("unknown-law", edit("contact.law", "hertzian"), "contact.law", "unknown law"),
    ("law-of-version-2", edit("contact.law", "hertz"), "contact.law", "version-2 scene"),
    ("zero-projectile-mass", edit("firing.projectile_mass", 0.0), "firing.projectile_mass", "> 0"),
    ("both-velocities", edit("barrel.initial_velocity", 0.7), "barrel.initial_velocity", "not both"),
    ("bad-version", edit("version", 3), "version", "unsupported"),
    ("bad-convention", edit("conventions", {"literal_lambda_sign": "yes"}), "conventions.literal_lambda_sign",
     "true or false"),
]


@pytest.fixture(params=BAD_SCENES, ids=[case[0] for case in BAD_SCENES])
def bad_scene(request):
    """(mapping, key, text) of one invalid scene."""
    _, edit, key, text = request.param
    return edit(paper_scene_dict()), key, text


def v2_scene_dict() -> dict:
    """A version-2 mapping: two absorbers (Hunt-Crossley on the ground, Flores on the barrel)."""
    return tomllib.loads('''
version = 2
name = "every table"
[barrel]
mass = 5600.0
[firing]
projectile_mass = 6.86
muzzle_velocity = 564.0
[recoil_spring]
stiffness = 27500.0
[recoil_damper]
recoil = 6239.0
counter_recoil = 14050.0
[[absorber]]
name = "front"
mass = 600.0
mount = "ground"
stiffness = 8100.0
damping = 2205.0
[absorber.contact]
gap = 0.0
stiffness = 2.1e8
exponent = 1.3
damping_factor = 0.6
[[absorber]]
name = "rear"
mass = 400.0
mount = "barrel"
stiffness = 5400.0
damping = 1470.0
[absorber.contact]
law = "flores"
gap = 0.02
stiffness = 2.1e8
exponent = 1.3
restitution = 0.5
''')


@pytest.fixture
def bad_input(tmp_path, capsys):
    """``check(mapping, key, text)``: the mapping is refused with a SceneError naming ``key`` whose message
    contains ``text`` -- by the API, and by the command line (one line on stderr, exit 2, no traceback)."""
    from mbs_models import SceneError, scene_from_dict
    from mbs_models.cli import main
    from mbs_models.scene.io import mapping_to_toml

    def check(mapping: dict, key: str, text: str) -> None:
        with pytest.raises(SceneError) as info:
            scene_from_dict(mapping)
        assert info.value.key == key, info.value
        assert text in info.value.message, info.value
        path = tmp_path / "scene.toml"
        path.write_text(mapping_to_toml(mapping))
        code = main(["run", str(path)])
        captured = capsys.readouterr()
        assert code == 2 and captured.out == ""
        lines = captured.err.strip().splitlines()
        assert len(lines) == 1 and key in lines[0] and "Traceback" not in captured.err, captured.err

    return check


#: The value that deletes a key in :func:`changed`.
DELETED = "<delete>"


@pytest.fixture
def v2_mapping() -> dict:
    """A fresh version-2 mapping (see :func:`v2_scene_dict`)."""
    return v2_scene_dict()


@pytest.fixture
def v1_mapping() -> dict:
    """A fresh version-1 mapping: the shipped model (ii)."""
    return paper_scene_dict()


@pytest.fixture
def changed():
    """``changed(mapping, path, value)``: a copy with the value at a dotted path set (``"<delete>"``: removed)."""
    def apply(mapping: dict, path: str, value) -> dict:
        return delete(path)(mapping) if value == DELETED else edit(path, value)(mapping)
    return apply


@pytest.fixture
def agrees_with_reference():
    """``check(scene, end_time, accuracy)``: the engine's result meets the README's guarantee against the
    independent reference (:mod:`validation.studies.guarantee`); returns the errors."""
    from mbs_models import simulate
    from validation.studies.guarantee import (TOLERANCES, errors_against_reference, physical_violations, reference_for,
                                              violations)

    def check(scene, end_time: float, accuracy: str) -> dict:
        result = simulate(scene, end_time, accuracy)
        problems = physical_violations(result, TOLERANCES[accuracy]["energy"])
        assert not problems, problems
        errors = errors_against_reference(result, reference_for(scene, end_time, (), accuracy),
                                          TOLERANCES[accuracy]["time"])
        problems = violations(errors, accuracy)
        assert not problems, (problems, errors)
        return errors

    return check
