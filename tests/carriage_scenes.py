"""Carriage scenes for the tests of the planar model (engine and reference): small TOML mappings, each built for
the closed form or the hard case a test checks."""

from __future__ import annotations

import copy

from mbs_models.scene.io import scene_from_dict

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
