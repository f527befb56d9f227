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


def _edit(path: str, value):
    def apply(data: dict) -> dict:
        data = copy.deepcopy(data)
        *tables, key = path.split(".")
        target = data
        for table in tables:
            target = target[table]
        target[key] = value
        return data
    return apply


def _delete(path: str):
    def apply(data: dict) -> dict:
        data = copy.deepcopy(data)
        *tables, key = path.split(".")
        target = data
        for table in tables:
            target = target[table]
        del target[key]
        return data
    return apply


#: (case id, edit of the valid mapping, key the error must name, text the message must contain)
BAD_SCENES = [
    ("unknown-key", _edit("contact.stifness", 1.0), "contact.stifness", "did you mean 'stiffness'"),
    ("unknown-table", _edit("absorbr", {}), "absorbr", "did you mean 'absorber'"),
    ("missing-key", _delete("absorber.damping"), "absorber.damping", "missing"),
    ("missing-table", _delete("recoil_spring"), "recoil_spring", "missing"),
    ("missing-velocity", _delete("firing"), "barrel.initial_velocity", "missing"),
    ("wrong-type-string", _edit("barrel.mass", "heavy"), "barrel.mass", "must be a number"),
    ("wrong-type-bool", _edit("recoil_spring.stiffness", True), "recoil_spring.stiffness", "must be a number"),
    ("wrong-type-table", _edit("contact", 3.0), "contact", "must be a table"),
    ("nan", _edit("contact.damping_factor", math.nan), "contact.damping_factor", "finite"),
    ("infinite", _edit("absorber.stiffness", math.inf), "absorber.stiffness", "finite"),
    ("zero-barrel-mass", _edit("barrel.mass", 0.0), "barrel.mass", "> 0"),
    ("negative-absorber-mass", _edit("absorber.mass", -5.0), "absorber.mass", "> 0"),
    ("negative-stiffness", _edit("recoil_spring.stiffness", -1.0), "recoil_spring.stiffness", ">= 0"),
    ("negative-damping", _edit("recoil_damper.counter_recoil", -1.0), "recoil_damper.counter_recoil", ">= 0"),
    ("negative-absorber-damping", _edit("absorber.damping", -3.0), "absorber.damping", ">= 0"),
    ("zero-contact-stiffness", _edit("contact.stiffness", 0.0), "contact.stiffness", "> 0"),
    ("zero-exponent", _edit("contact.exponent", 0.0), "contact.exponent", "> 0"),
    ("negative-gap", _edit("contact.gap", -0.001), "contact.gap", ">= 0"),
    ("absorber-without-contact", _delete("contact"), "contact", "needs a [contact]"),
    ("contact-without-absorber", _delete("absorber"), "absorber", "needs an [absorber]"),
    ("unknown-mount", _edit("absorber.mount", "roof"), "absorber.mount", "unknown mount"),
    ("unknown-law", _edit("contact.law", "hertzian"), "contact.law", "unknown law"),
    ("law-of-version-2", _edit("contact.law", "hertz"), "contact.law", "version-2 scene"),
    ("zero-projectile-mass", _edit("firing.projectile_mass", 0.0), "firing.projectile_mass", "> 0"),
    ("both-velocities", _edit("barrel.initial_velocity", 0.7), "barrel.initial_velocity", "not both"),
    ("bad-version", _edit("version", 3), "version", "unsupported"),
    ("bad-convention", _edit("conventions", {"literal_lambda_sign": "yes"}), "conventions.literal_lambda_sign",
     "true or false"),
]


@pytest.fixture(params=BAD_SCENES, ids=[case[0] for case in BAD_SCENES])
def bad_scene(request):
    """(mapping, key, text) of one invalid scene."""
    _, edit, key, text = request.param
    return edit(paper_scene_dict()), key, text
