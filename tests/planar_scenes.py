"""Carriage scenes of the reference's tests (DESIGN.md, "The recoil axis on a carriage"): built from dicts, every number here.

``carriage_scene(**changes)`` is the test gun of the brief: a 1000 kg barrel on a 2000 kg carriage (CG at
(2.4, 0.8) m, trunnion at (2.5, 1.0) m), a dug-in spade at (0, 0) and wheels with Coulomb friction at
(2.8, 0); ``changes`` replace whole top-level tables (``carriage=...``) or, with dotted keys of one level
(``"carriage.mass"``), single values; ``supports=[...]`` replaces the supports.
"""

from __future__ import annotations

import copy

from mbs_models.scene import scene_from_dict

SPADE = {"name": "spade", "position": [0.0, 0.0], "law": "kelvin-voigt", "stiffness": 5.0e8, "damping": 2.0e6,
         "horizontal_stiffness": 2.0e8, "horizontal_damping": 1.0e6}
WHEELS = {"name": "wheels", "position": [2.8, 0.0], "law": "hunt-crossley", "stiffness": 2.0e7, "exponent": 1.0,
          "damping_factor": 0.5, "friction_coefficient": 0.3}
BASE = {"version": 2, "name": "carriage test",
        "barrel": {"mass": 1000.0, "initial_velocity": 10.0},
        "recoil_spring": {"stiffness": 27500.0},
        "recoil_damper": {"recoil": 6239.0, "counter_recoil": 6239.0},
        "cradle": {"elevation": 0.0},
        "carriage": {"mass": 2000.0, "inertia": 1500.0, "center_of_mass": [2.4, 0.8], "trunnion": [2.5, 1.0],
                     "support": [SPADE, WHEELS]}}


def carriage_dict(supports=None, **changes) -> dict:
    data = copy.deepcopy(BASE)
    for key, value in changes.items():
        if "." in key:
            table, field = key.split(".")
            data.setdefault(table, {})[field] = value
        elif value is None:
            data.pop(key, None)
        else:
            data[key] = copy.deepcopy(value)
    if supports is not None:
        data["carriage"]["support"] = copy.deepcopy(supports)
    return data


def carriage_scene(supports=None, **changes):
    """The scene of ``carriage_dict`` (module docstring)."""
    return scene_from_dict(carriage_dict(supports, **changes))
