"""The work-precision study on a carriage scene (validation/studies/carriage_precision.py)."""

from __future__ import annotations

import json

import pytest

from mbs_models.engine.accuracy import SolverSettings
from mbs_models.cli import main
from validation.studies.carriage_precision import METRICS, carriage_study

from carriage_scenes import carriage_scene


def test_tighter_tolerances_track_the_reference_closer():
    """Against the independent planar reference, DOPRI5 at rtol 1e-10 is closer than at 1e-5 on the carriage's
    pitch history and on the support loads (the quantities the carriage adds); every error is finite."""
    settings = [(f"DOPRI5 rtol={r:g}", SolverSettings(relative_tolerance=r, absolute_tolerance=r * 1e-2, max_step=5e-3))
                for r in (1e-5, 1e-10)]
    study = carriage_study(carriage_scene(), settings, end_time=0.3, repeats=1)
    loose, tight = study.outcomes
    assert not loose.failure and not tight.failure
    for metric in METRICS:
        assert loose.errors[metric] >= 0.0 and tight.errors[metric] >= 0.0
    assert tight.errors["pitch_l2"] < loose.errors["pitch_l2"]
    assert tight.errors["support_loads"] < loose.errors["support_loads"]
    assert tight.errors["pitch_l2"] < 1e-4


def test_recoil_precision_on_a_carriage_scene_writes_its_study(tmp_path, capsys):
    out = tmp_path / "precision"
    assert main(["precision", "towed_howitzer_45", "--quick", "--end-time", "0.5", "--repeats", "1",
                 "--out", str(out)]) == 0
    assert "carriage" in capsys.readouterr().out
    data = json.loads((out / "carriage_precision.json").read_text())
    assert {o["label"] for o in data["outcomes"]} >= {"preset draft", "preset standard", "preset reference"}
    assert (out / "work_precision_carriage.png").read_bytes()[:4] == b"\x89PNG"
    assert main(["precision", "towed_howitzer_45", "--presets", "--out", str(tmp_path / "x")]) == 2
