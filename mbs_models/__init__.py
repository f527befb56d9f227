"""Recoil mechanisms with impact absorbers, simulated with the Exudyn multibody engine.

Public API (one entry point per task)::

    from mbs_models import load_scene, model_ii, simulate
    result = simulate(model_ii(absorber_mass=1000.0, gap=0.04), end_time=10.0)
    print(result.max_barrel_displacement)

Scene handling (:mod:`.scene`, :mod:`.scene_io`, :mod:`.models`) is imported eagerly and needs no
Exudyn; the engine (:mod:`.simulation` and below) is imported on first use, so that the independent
``validation`` package can read scenes without ever loading Exudyn.
"""

from __future__ import annotations

import importlib

from .errors import RecoilError, SceneError, SimulationError
from .scene import (Absorber, Barrel, BatteryStop, Contact, Conventions, Firing, RecoilDamper, RecoilSpring, RecoilStop,
                    Scene, load_scene, model_i, model_ii, paper_model, scene_from_dict, scene_to_dict, scene_to_toml,
                    simplified_model)

__version__ = "0.1.0"

# name -> module that defines it; loaded lazily (PEP 562) because these import Exudyn.
_LAZY = {
    "simulate": ".simulation",
    "Result": ".result",
    "Impact": ".result",
    "SolverSettings": ".accuracy",
    "ACCURACY_PRESETS": ".accuracy",
    "solver_settings_for": ".accuracy",
    "assemble": ".assembly",
    "Assembly": ".assembly",
    "FINAL_METRICS": ".final_metrics",   # names accepted by simulate(..., stop_when_final=...)
    "EnergyBounds": ".final_metrics",
}

__all__ = [
    "Absorber", "Barrel", "BatteryStop", "Contact", "Conventions", "Firing", "RecoilDamper", "RecoilSpring",
    "RecoilStop", "Scene",
    "RecoilError", "SceneError", "SimulationError",
    "load_scene", "scene_from_dict", "scene_to_dict", "scene_to_toml",
    "model_i", "model_ii", "paper_model", "simplified_model",
    *_LAZY,
]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'mbs_models' has no attribute {name!r}")


def __dir__():
    return sorted(__all__)
