"""``recoil run`` (mbs_models/cli/run.py): outputs in the format asked, checked before the solve; the warning
for contacts that cannot close; the end of the window; the time histories as CSV."""

from __future__ import annotations

import csv
import json
import math
import os
import stat

import numpy as np
import pytest

from mbs_models import model_ii, scene_to_toml, simulate
from mbs_models.cli import main

_PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def no_solve(monkeypatch):
    """Make any solve fail loudly: the checks under test must come before it."""
    import mbs_models.engine.simulation as simulation

    def refuse(*args, **kwargs):
        raise AssertionError("simulate() was called")

    monkeypatch.setattr(simulation, "simulate", refuse)


@pytest.mark.parametrize("name, magic", [("run.png", _PNG), ("run.PNG", _PNG), ("run.pdf", b"%PDF-"),
                                         ("run.svg", b"<?xml")])
def test_the_plot_is_written_in_the_format_its_extension_names(tmp_path, capsys, name, magic):
    target = tmp_path / name
    assert main(["run", "model_ii", "--end-time", "0.3", "--accuracy", "draft", "--plot", str(target)]) == 0
    data = target.read_bytes()
    assert data.startswith(magic)
    if name.endswith(".svg"):
        assert b"<svg" in data[:2000]


@pytest.mark.parametrize("name", ["run.jpg", "run", "run.png.txt"])
def test_another_figure_format_is_refused_before_the_solve(tmp_path, capsys, no_solve, name):
    target = tmp_path / name
    assert main(["run", "model_ii", "--plot", str(target)]) == 2
    captured = capsys.readouterr()
    [line] = captured.err.strip().splitlines()
    assert line.startswith("recoil: error: --plot:") and ".png, .pdf, .svg" in line
    assert captured.out == "" and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("option, name", [("--plot", "run.png"), ("--csv", "run.csv")])
def test_a_directory_that_cannot_be_created_is_refused_before_the_solve(tmp_path, capsys, no_solve, option, name):
    (tmp_path / "a_file").write_text("")
    target = tmp_path / "a_file" / "dir" / name
    assert main(["run", "model_ii", option, str(target)]) == 2
    [line] = capsys.readouterr().err.strip().splitlines()
    assert line.startswith(f"recoil: error: {option}:") and "not a writable directory" in line
    assert [p.name for p in tmp_path.iterdir()] == ["a_file"]


def test_missing_directories_are_created_once_the_run_has_solved(tmp_path, capsys, monkeypatch):
    import mbs_models.engine.simulation as simulation

    solve, seen = simulation.simulate, []

    def solve_and_look(*args, **kwargs):
        seen.append((tmp_path / "plots").exists() or (tmp_path / "tables").exists())
        return solve(*args, **kwargs)

    monkeypatch.setattr(simulation, "simulate", solve_and_look)
    plot, table = tmp_path / "plots" / "a" / "run.png", tmp_path / "tables" / "run.csv"
    assert main(["run", "model_ii", "--end-time", "0.2", "--accuracy", "draft", "--plot", str(plot),
                 "--csv", str(table)]) == 0
    assert seen == [False]   # nothing created before the solve
    assert plot.read_bytes()[:8] == _PNG and table.read_text().startswith("time")


def test_a_directory_as_csv_target_is_refused(tmp_path, capsys, no_solve):
    assert main(["run", "model_ii", "--csv", str(tmp_path)]) == 2
    assert "is a directory" in capsys.readouterr().err


def test_outputs_honour_the_umask(tmp_path, capsys):
    saved = os.umask(0o022)
    try:
        assert main(["run", "model_ii", "--end-time", "0.2", "--accuracy", "draft",
                     "--plot", str(tmp_path / "run.png"), "--csv", str(tmp_path / "run.csv")]) == 0
    finally:
        os.umask(saved)
    for name in ("run.png", "run.csv"):
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o644, name


def test_a_gap_in_millimetres_warns_on_one_line_and_still_runs(tmp_path, capsys):
    path = tmp_path / "mm.toml"
    path.write_text(scene_to_toml(model_ii(1000.0, 40.0)))
    assert main(["run", str(path), "--end-time", "1", "--accuracy", "draft"]) == 0
    captured = capsys.readouterr()
    [line] = captured.err.strip().splitlines()
    k, e0 = 27500.0, 0.5 * 5600.0 * model_ii().initial_velocity ** 2
    reach = math.sqrt(2.0 * e0 / k)  # the undamped free recoil's amplitude
    assert line.startswith("recoil: warning: absorber.contact.gap = 40 m")
    assert float(line.split("(")[1].split()[0]) == pytest.approx(reach, rel=1e-3)
    assert "no contact" in captured.out


def test_no_warning_for_a_contact_that_closes(capsys):
    assert main(["run", "model_ii", "--end-time", "0.2", "--accuracy", "draft"]) == 0
    assert capsys.readouterr().err == ""


def test_a_maximum_at_the_end_of_the_window_is_flagged(capsys):
    assert main(["run", "model_ii", "--end-time", "0.001", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["time_of_max_barrel_displacement"] == data["end_time"] == 0.001
    assert data["max_at_end_of_window"] is True
    assert "max_barrel_displacement" in data["maxima_at_end_of_window"]
    assert main(["run", "model_ii", "--end-time", "0.001"]) == 0
    line = next(l for l in capsys.readouterr().out.splitlines() if "max barrel displacement" in l)
    assert "not a turning point" in line


def test_a_turning_point_is_not_flagged(capsys):
    assert main(["run", "model_ii", "--end-time", "1", "--json", "--accuracy", "draft"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["time_of_max_barrel_displacement"] < 0.9 and data["max_at_end_of_window"] is False
    assert data["maxima_at_end_of_window"] == []
    assert main(["run", "model_ii", "--end-time", "1", "--accuracy", "draft"]) == 0
    assert "turning point" not in capsys.readouterr().out


def test_the_header_names_the_model_once(capsys):
    assert main(["run", "model_ii", "--end-time", "0.1", "--accuracy", "draft"]) == 0
    header = capsys.readouterr().out.splitlines()[0]
    assert header.count("model (ii)") == 1


def test_csv_has_the_time_histories_with_units(tmp_path, capsys):
    target = tmp_path / "run.csv"
    assert main(["run", "model_ii", "--end-time", "0.5", "--accuracy", "draft", "--csv", str(target)]) == 0
    with target.open(newline="") as stream:
        rows = list(csv.reader(stream))
    header, values = rows[0], np.array(rows[1:], dtype=float)
    assert all(name.endswith("]") and " [" in name for name in header)
    expected = simulate(model_ii(), 0.5, "draft").densified()  # the rows are dense (1 ms, or finer: 0.5 s / 2000)
    column = {name: values[:, i] for i, name in enumerate(header)}
    np.testing.assert_array_equal(column["time [s]"], expected.time)
    np.testing.assert_array_equal(column["barrel position [m]"], expected.barrel_position)
    np.testing.assert_array_equal(column["absorber velocity [m/s]"], expected.absorber_velocity)
    np.testing.assert_array_equal(column["contact force [N]"], expected.contact_force)
    np.testing.assert_array_equal(column["support force [N]"], expected.support_force)
    for name in ("kinetic energy [J]", "stored energy [J]", "dissipated energy [J]", "energy balance error [J]"):
        assert name in column
    assert "time histories (CSV)" in capsys.readouterr().out


def _csv_times(path) -> np.ndarray:
    with path.open(newline="") as stream:
        return np.array([float(row[0]) for row in list(csv.reader(stream))[1:]])


def test_the_history_interval_sets_the_rows_and_step_ends_writes_the_solver_s_points(tmp_path, capsys):
    """A 5 s ``standard`` run steps up to 20 ms: ``--history-interval 0.002`` gives rows at most 2 ms apart
    (the step-end samples among them), the default at most 1 ms, ``--step-ends`` the solver's points exactly;
    the plot is written the same way and the metrics do not change."""
    expected = simulate(model_ii(), 5.0)
    assert np.max(np.diff(expected.time)) > 1.9e-2
    metrics = {}
    for options, gap in ((["--history-interval", "0.002"], 2e-3), ([], 1e-3), (["--step-ends"], None)):
        target = tmp_path / f"run{len(metrics)}.csv"
        plot = tmp_path / f"run{len(metrics)}.png"
        assert main(["run", "model_ii", "--end-time", "5", "--json", "--csv", str(target), "--plot", str(plot),
                     *options]) == 0
        metrics[gap] = json.loads(capsys.readouterr().out)
        times = _csv_times(target)
        assert plot.read_bytes().startswith(_PNG)
        if gap is None:
            np.testing.assert_array_equal(times, expected.time)
        else:
            assert np.max(np.diff(times)) <= gap + 1e-14 and np.all(np.isin(expected.time, times))
    for values in metrics.values():
        values.pop("wall_time")
    assert metrics[2e-3] == metrics[1e-3] == metrics[None]


@pytest.mark.parametrize("value", ["0", "-0.001", "5", "1e-7", "nan"])
def test_a_history_interval_out_of_range_exits_2_on_one_line_before_the_solve(tmp_path, capsys, no_solve, value):
    target = tmp_path / "run.csv"
    assert main(["run", "model_ii", "--csv", str(target), "--history-interval", value]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--history-interval" in err and "from 1e-05 to 1 s" in err
    assert "Traceback" not in err and not target.exists()


def test_step_ends_and_an_interval_are_exclusive(capsys, no_solve):
    assert main(["run", "model_ii", "--step-ends", "--history-interval", "0.001"]) == 2
    assert "not allowed with" in capsys.readouterr().err


def test_a_barrel_mass_in_tonnes_warns_on_one_line_naming_the_key(tmp_path, capsys):
    from mbs_models import simplified_model

    path = tmp_path / "tonnes.toml"
    path.write_text(scene_to_toml(simplified_model().with_changes(**{"barrel.mass": 5.6})))
    main(["run", str(path), "--end-time", "0.05", "--accuracy", "draft"])
    [line] = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("recoil: warning: barrel.mass = 5.6 kg gives a recoil velocity of ")
    assert float(line.split("velocity of ")[1].split()[0]) == pytest.approx(6.86 * 564.0 / 5.6, rel=1e-3)


def test_a_pulse_in_milliseconds_and_kilonewtons_warns_naming_its_times_and_forces(tmp_path, capsys):
    from mbs_models.scenes import scene_path

    path = tmp_path / "pulse.toml"
    path.write_text(scene_path("breech_pulse").read_text()
                    .replace("times  = [0.0, 0.002, 0.006, 0.012]", "times  = [0.0, 2.0, 6.0, 12.0]")
                    .replace("forces = [0.0, 2.0e6, 6.0e5, 0.0]", "forces = [0.0, 2.0e3, 6.0e2, 0.0]")
                    .replace("scale_to_momentum = true", "scale_to_momentum = false"))
    assert main(["run", str(path), "--end-time", "0.5", "--accuracy", "draft"]) == 0
    captured = capsys.readouterr()
    times, forces = captured.err.strip().splitlines()
    assert times.startswith("recoil: warning: firing.pulse.times span 12 s")
    assert forces.startswith("recoil: warning: firing.pulse.forces peak at 2000 N")
    assert "$" not in captured.out + captured.err


def test_a_run_at_rest_says_so_on_one_line_and_keeps_its_csv_small(tmp_path, capsys):
    """Model (ii) to 1000 s rests after ~25 s: one stderr line with the rest time and the proven bound, the JSON's
    ``stop_reason``, ``rest_time`` and ``rest_tolerance``, and a CSV whose rows do not grow with the end time."""
    rows = {}
    for end_time in ("200", "1000"):
        target = tmp_path / f"run{end_time}.csv"
        assert main(["run", "model_ii", "--end-time", end_time, "--json", "--csv", str(target)]) == 0
        captured = capsys.readouterr()
        data = json.loads(captured.out)
        (line,) = captured.err.splitlines()
        assert data["stop_reason"] == "at_rest" and data["end_time"] == float(end_time)
        assert data["rest_tolerance"] == 1e-11 and 0.0 < data["rest_time"] < 100.0
        assert line.startswith(f"recoil: at rest from t = {data['rest_time']:.6g} s (proven: every position within "
                               "1e-11 m") and f"remaining {float(end_time) - data['rest_time']:.6g} s" in line
        with target.open(newline="") as stream:
            rows[end_time] = list(csv.reader(stream))
        assert float(rows[end_time][-1][0]) == float(end_time)
    assert len(rows["200"]) == len(rows["1000"])


def test_no_stop_at_rest_integrates_to_the_end(capsys):
    assert main(["run", "model_ii", "--end-time", "150", "--accuracy", "draft", "--json", "--no-stop-at-rest"]) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert data["stop_reason"] == "end_time" and "rest_time" not in data and captured.err == ""
