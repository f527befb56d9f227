"""Recoil mechanisms with impact absorbers, simulated with the Exudyn multibody engine.

Public API (one entry point per task)::

    from mbs_models import load_scene, model_ii, simulate
    result = simulate(model_ii(absorber_mass=1000.0, gap=0.04), end_time=10.0)
    print(result.max_barrel_displacement)

    from mbs_models import apply_overrides, run_sweep
    lighter = apply_overrides(model_ii(), {"absorber.mass": 500.0, "contact.gap": 0.02})   # dotted keys
    table = run_sweep(model_ii(), {"absorber.mass": [100, 1000], "contact.gap": "0:0.12:13"}, out="gaps.csv")

Scenes (:mod:`.scene`) are imported eagerly and need no Exudyn; an element's module (:mod:`.elements`) is imported
when one of its tables is first used (a scene that has it, its class looked up here); the engine (:mod:`.engine`), results (:mod:`.results`) and studies are imported on first use,
so that scenes can be read, checked and written without ever loading Exudyn.
"""

from __future__ import annotations

import importlib

from .elements import register_element
from .errors import ClusterError, RecoilError, SceneError, SimulationError, UnitWarning
from .scene import (TABLE_CLASSES, Conventions, Scene, apply_overrides, load_scene, model_i, model_ii, paper_model,
                    parse_spec, scene_from_dict, scene_to_dict, scene_to_toml, simplified_model)
from .stop_reason import StopReason


__version__ = "0.1.0"

# name -> module that defines it; loaded lazily (PEP 562) because these import Exudyn.
_LAZY = {
    "simulate": ".engine.simulation",
    "Simulator": ".engine.reuse",             # simulate() keeping the assembled systems (sweeps)
    "Result": ".results.result",
    "Impact": ".results.result",
    "ContactOutput": ".results.result",
    "SolverSettings": ".engine.accuracy",
    "ACCURACY_PRESETS": ".engine.accuracy",
    "solver_settings_for": ".engine.accuracy",
    "assemble": ".engine.assembly",
    "Assembly": ".engine.assembly",
    "Mechanism": ".engine.mechanism",
    "FINAL_METRICS": ".engine.finality",   # names accepted by simulate(..., stop_when_final=...)
    "EnergyBounds": ".engine.energy_bounds",
    "contacts_out_of_reach": ".engine.reach",  # gaps and stops beyond the barrel's free-recoil travel
    "add_contact": ".elements.contact_laws",
    "add_recoil_damper": ".elements.recoil_damper",
    "add_recoil_brake": ".elements.recoil_brake",
    "add_recuperator": ".elements.recuperator",
    "add_tabulated_spring": ".elements.tabulated_spring",
    "add_tabulated_damper": ".elements.tabulated_damper",
    "add_body": ".engine.assembly",
    "run_sweep": ".studies.sweep",           # a grid over dotted scene keys -> a pandas table (recoil sweep)
    "optimise": ".studies.optimise",         # the best design within bounds (recoil optimise)
}

__all__ = [
    *TABLE_CLASSES, "Conventions", "Scene", "StopReason", "register_element",
    "RecoilError", "SceneError", "SimulationError", "ClusterError", "UnitWarning",
    "load_scene", "scene_from_dict", "scene_to_dict", "scene_to_toml", "apply_overrides", "parse_spec",
    "model_i", "model_ii", "paper_model", "simplified_model",
    *_LAZY,
]


def __getattr__(name: str):
    if name in TABLE_CLASSES:  # Barrel, RecoilSpring, Absorber, Contact, ...: every element's table
        return TABLE_CLASSES[name]
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'mbs_models' has no attribute {name!r}")


def __dir__():
    return sorted(__all__)
