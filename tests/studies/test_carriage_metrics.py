"""A carriage scene's metrics in sweeps and in the optimiser (mbs_models/studies/point.py, optimise.py)."""

from __future__ import annotations

import pytest

from mbs_models.studies.optimise import optimisable_metrics, optimise
from mbs_models.studies.point import PointSettings, evaluate_point, metric_columns

from carriage_scenes import carriage_scene

CARRIAGE_COLUMNS = ["max_carriage_pitch", "max_lift", "lift_off_time", "max_carriage_displacement",
                    "stability_margin", "support.spade.min_normal_force", "support.wheels.min_normal_force"]


def test_sweep_rows_have_the_carriage_columns():
    scene = carriage_scene()
    columns = metric_columns(scene)
    assert all(column in columns for column in CARRIAGE_COLUMNS)
    assert not any(column in metric_columns(carriage_scene(carriage=None)) for column in CARRIAGE_COLUMNS)
    row = evaluate_point(scene, {"carriage.mass": 2500.0}, PointSettings(end_time=0.5))
    assert row["status"] == "ok"
    assert 0.0 <= row["stability_margin"] <= 1.0
    assert row["support.wheels.min_normal_force"] >= 0.0


def test_the_optimiser_keeps_the_gun_on_the_ground():
    """Minimise the recoil (a stiffer damper) subject to stability_margin >= 0.5: the stiffest damper within the
    bounds lifts the wheels (margin 0), so the optimum sits where the margin constraint binds."""
    scene = carriage_scene()
    assert "stability_margin" in optimisable_metrics(scene)
    best = optimise(scene, {"recoil_damper.recoil": (5.0e3, 4.0e4)}, "max_barrel_displacement",
                    ["stability_margin>=0.5"], end_time=0.3, popsize=5, maxiter=6, workers=1)
    assert best.feasible
    assert best.metrics["stability_margin"] >= 0.5
    stiff = evaluate_point(scene, {"recoil_damper.recoil": 4.0e4}, PointSettings(end_time=0.3))
    assert stiff["stability_margin"] < 0.5  # the constraint mattered
