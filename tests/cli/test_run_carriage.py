"""``recoil run`` on a carriage scene: the stability margin and the supports in --json, the carriage's columns in
--csv, its panels in --plot."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from mbs_models.cli import main


def test_json_has_the_stability_margin_and_the_supports(capsys):
    assert main(["run", "towed_howitzer_45", "--end-time", "1", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("max_carriage_pitch", "max_lift", "lift_off_time", "max_carriage_displacement", "stability_margin"):
        assert key in data
    assert 0.0 < data["stability_margin"] <= 1.0 and data["lift_off_time"] is None
    names = [s["name"] for s in data["supports"]]
    assert names == ["spade", "wheels"]
    for support in data["supports"]:
        assert support["min_normal_force"] <= support["static_normal_force"] <= support["max_normal_force"]
    # the static loads carry the gun's weight (10 t)
    assert sum(s["static_normal_force"] for s in data["supports"]) == pytest.approx(10000.0 * 9.81, rel=1e-9)


def test_a_scene_without_carriage_has_no_carriage_key(capsys):
    assert main(["run", "model_ii", "--end-time", "0.5", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert "stability_margin" not in data and "supports" not in data


def test_csv_and_plot_of_a_carriage_scene(tmp_path, capsys):
    table, figure = tmp_path / "run.csv", tmp_path / "run.png"
    assert main(["run", "towed_howitzer", "--end-time", "0.5", "--csv", str(table), "--plot", str(figure)]) == 0
    with open(table) as handle:
        rows = list(csv.DictReader(handle))
    for column in ("carriage x [m]", "carriage y [m]", "carriage pitch [rad]", "spade normal force [N]",
                   "spade tangential force [N]", "spade height [m]", "wheels normal force [N]", "wheels height [m]"):
        assert column in rows[0]
    normal = np.array([float(r["wheels normal force [N]"]) for r in rows])
    assert np.all(normal >= 0.0) and normal[0] > 0.0
    assert figure.read_bytes().startswith(b"\x89PNG")
    assert "stability margin" in capsys.readouterr().out
