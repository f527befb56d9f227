"""Version-1 scenes give bit-identical results through the elements restructuring.

``tests/data/v1_baseline.json`` was recorded by ``scripts/record_v1_baseline.py`` at the commit it names,
before any engine code moved: for the paper's 19 cases at the three presets (and with the early stops of
the sweeps), and for the hard cases at the three presets, every scalar of the result (as float.hex), the
impacts, the dissipated energies, the step count and a SHA-256 of every time history.  Nothing here is
computed by the code under test but the results compared.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from mbs_models import model_i, model_ii, simplified_model, simulate

from validation.studies.hard_cases import HARD_CASES_BY_NAME

BASELINE = json.loads((Path(__file__).resolve().parents[1] / "data" / "v1_baseline.json").read_text())
V1_METRICS = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "impacts")
SCALARS = ("end_time", "requested_end_time", "max_barrel_displacement", "time_of_max_barrel_displacement",
           "peak_contact_force", "time_of_peak_contact_force", "max_absorber_velocity",
           "time_of_max_absorber_velocity")
ARRAYS = ("time", "barrel_position", "barrel_velocity", "barrel_acceleration", "absorber_position",
          "absorber_velocity", "absorber_acceleration", "contact_force", "kinetic_energy_history",
          "stored_energy_history")


def paper_scene(name: str):
    if name == "simplified":
        return simplified_model()
    model, mass, gap = name.split("-")
    factory = model_i if model == "i" else model_ii
    return factory(float(mass[1:]), float(gap[3:]) / 1000.0)


def digest(array) -> str | None:
    if array is None:
        return None
    array = np.ascontiguousarray(np.asarray(array, dtype=float))
    return f"{array.size}:" + hashlib.sha256(array.tobytes()).hexdigest()


def hexed(value):
    return None if value is None else float(value).hex()


def assert_identical(result, recorded: dict) -> None:
    for name in SCALARS:
        assert hexed(getattr(result, name)) == recorded[name], name
    for name in ARRAYS:
        assert digest(getattr(result, name)) == recorded["arrays"][name], name
    assert {k: hexed(v) for k, v in result.dissipated_energy.items()} == recorded["dissipated_energy"]
    assert {k: digest(v) for k, v in result.dissipated_energy_history.items()} == \
        recorded["dissipated_energy_history"]
    impacts = None if result.impacts is None else [
        [hexed(i.start), hexed(i.end), hexed(i.peak_force), hexed(i.time_of_peak_force)] for i in result.impacts]
    assert impacts == recorded["impacts"]
    assert result.steps == recorded["steps"]
    assert result.settings.label() == recorded["solver"] and hexed(result.settings.max_step) == recorded["max_step"]
    assert result.stop_reason == recorded["stop_reason"]
    assert [m for m in result.final_metrics if m in V1_METRICS] == recorded["final_metrics"]


@pytest.mark.parametrize("key", sorted(BASELINE["paper"]))
def test_paper_cases(key):
    name, preset = key.split("/")
    assert_identical(simulate(paper_scene(name), 10.0, preset), BASELINE["paper"][key])


@pytest.mark.parametrize("key", sorted(BASELINE["paper_early_stop"]))
def test_paper_cases_with_early_stop(key):
    name, which = key.split("/")
    metrics = V1_METRICS if which == "all" else ("max_barrel_displacement",)
    assert_identical(simulate(paper_scene(name), 10.0, "standard", stop_when_final=metrics),
                     BASELINE["paper_early_stop"][key])


@pytest.mark.parametrize("key", sorted(BASELINE["hard"]))
def test_hard_cases(key):
    name, preset = key.split("/")
    case = HARD_CASES_BY_NAME[name]
    assert_identical(simulate(case.scene, case.end_time, preset), BASELINE["hard"][key])
