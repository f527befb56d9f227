"""Carriage scenes for the tests of the planar model (engine and reference): small TOML mappings, each built for
the closed form or the hard case a test checks (the hard cases: :func:`grazing_scene`, :func:`jump_scene`,
:func:`slipping_scene`)."""

from __future__ import annotations

import copy
import math

from mbs_models.elements.carriage import AxisBody, static_equilibrium
from mbs_models.scene.io import scene_from_dict, scene_to_dict

#: Spade at the origin, the wheels 2.8 m ahead; 2000 kg carriage, 1000 kg barrel at the trunnion (2.5, 1.0).
BASE = {
    "version": 2,
    "name": "carriage test",
    "barrel": {"mass": 1000.0, "initial_velocity": 2.0},
    "recoil_spring": {"stiffness": 27500.0},
    "recoil_damper": {"recoil": 6239.0, "counter_recoil": 6239.0},
    "cradle": {"elevation": 0.0},
    "carriage": {
        "mass": 2000.0, "inertia": 1500.0, "center_of_mass": [2.4, 0.8], "trunnion": [2.5, 1.0],
        "support": [
            {"name": "spade", "position": [0.0, 0.0], "law": "kelvin-voigt", "stiffness": 5.0e8, "damping": 2.0e6,
             "horizontal_stiffness": 2.0e8, "horizontal_damping": 1.0e6},
            {"name": "wheels", "position": [2.8, 0.0], "law": "kelvin-voigt", "stiffness": 2.0e8, "damping": 1.0e6},
        ],
    },
}


def carriage_scene(changes: dict | None = None, **tables):
    """The :data:`BASE` scene with top-level tables replaced (``tables``) and nested keys changed
    (``changes``: ``{"carriage.mass": 3000.0, "carriage.support.1.stiffness": 1e9}``)."""
    data = copy.deepcopy(BASE)
    for name, table in tables.items():
        if table is None:
            data.pop(name, None)
        else:
            data[name] = table
    for key, value in (changes or {}).items():
        node = data
        parts = key.split(".")
        for part in parts[:-1]:
            node = node[int(part)] if isinstance(node, list) else node[part]
        if value is None:
            node.pop(parts[-1], None)
        else:
            node[parts[-1]] = value
    return scene_from_dict(data)


#: The shipped scenes' folder.
from pathlib import Path  # noqa: E402

SCENES_DIR = Path(__file__).parents[1] / "mbs_models" / "scenes"


def grazing_scene():
    """BASE with a third support under the carriage's middle placed exactly at the ground in the static
    equilibrium of the other two (height 0, no load): the pitching after the shot makes it touch and leave."""
    two = carriage_scene()
    static = static_equilibrium(two.carriage, 0.0, 9.81, [AxisBody("barrel", 1000.0)])
    x = 1.4
    y = -(static.height + x * math.sin(static.pitch)) / math.cos(static.pitch)
    data = scene_to_dict(two)
    data["carriage"]["support"].append({"name": "skid", "position": [x, y], "law": "kelvin-voigt",
                                        "stiffness": 1.0e8, "damping": 1.0e5})
    return scene_from_dict(data)


def jump_scene():
    """A 300 kg carriage under a 3000 kg barrel fired at 5 m/s into a stiff damper: the carriage pivots on its
    spade, the wheels jump 0.1 m off the ground, the spade leaves it too, and both land again.  The spade digs in
    where it lands (``anchor = "touchdown"``), holds by its spring alone, and meets the ground by a Hunt-Crossley law
    (n = 1.5: its force rises from 0 at touch-down).  Measured: a Kelvin-Voigt spade (its force jumps by c p' at
    touch-down) chatters at the landing at the ``reference`` tolerances (the step collapses at 0.3926 s, on either
    Exudyn module), and so does a horizontal damper switching on at the touch-down of a spade sliding at 0.3 m/s;
    anchored at its old x the spring snaps at 1.9 MN on landing (DESIGN.md)."""
    return carriage_scene({"carriage.mass": 300.0, "carriage.inertia": 200.0, "barrel.mass": 3000.0,
                           "barrel.initial_velocity": 5.0, "carriage.support.0.anchor": "touchdown",
                           "carriage.support.0.horizontal_damping": 0.0, "carriage.support.0.law": "hunt-crossley",
                           "carriage.support.0.exponent": 1.5, "carriage.support.0.damping_factor": 0.5,
                           "carriage.support.0.stiffness": 5e10, "carriage.support.0.damping": None},
                          recoil_damper={"recoil": 6.0e4, "counter_recoil": 6.0e4})


def slipping_scene():
    """The spade holds by Coulomb friction (mu = 0.05) instead of an anchor: it slides."""
    data = scene_to_dict(carriage_scene())
    spade = data["carriage"]["support"][0]
    del spade["horizontal_stiffness"], spade["horizontal_damping"]
    spade["friction_coefficient"] = 0.05
    return scene_from_dict(data)
