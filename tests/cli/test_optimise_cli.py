"""``recoil optimise``: writes the optimum, history and figure; no feasible design is exit 1; bad input exit 2."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from mbs_models.cli import main

SMALL = ["--popsize", "3", "--maxiter", "1", "--workers", "1"]


def test_writes_results(tmp_path, capsys):
    out = tmp_path / "opt"
    code = main(["optimise", "model_i", "--vary", "contact.gap=0:0.12", "--minimise", "max_barrel_displacement",
                 "--constraint", "peak_support_force<=7000", "--out", str(out), "--json", *SMALL])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    data = json.loads(captured.out)
    assert data["feasible"] and data["constraints"][0]["satisfied"]
    assert data["settings"]["seed"] == 1 and data["settings"]["population"] == 5  # scipy's smallest
    assert sorted(p.name for p in out.iterdir()) == ["convergence.csv", "history.csv", "optimise.png", "optimum.json"]
    history = pd.read_csv(out / "history.csv")
    assert len(history) == data["evaluations"] and "contact.gap" in history.columns
    assert json.loads((out / "optimum.json").read_text()) == data
    assert "generation 0" in captured.err


def test_no_feasible_design_is_exit_1(tmp_path, capsys):
    code = main(["optimise", "model_i", "--vary", "contact.gap=0:0.12", "--minimise", "peak_support_force",
                 "--constraint", "max_barrel_displacement<=0.05", "--out", str(tmp_path / "o"), *SMALL])
    captured = capsys.readouterr()
    assert code == 1 and "NO FEASIBLE DESIGN FOUND" in captured.out
    assert (tmp_path / "o" / "optimum.json").exists()


@pytest.mark.parametrize("args, text", [
    (["--vary", "contact.gap=0:0.12", "--minimise", "max_barrel_displacment"],
     "--minimise: unknown metric 'max_barrel_displacment'; did you mean 'max_barrel_displacement'?"),
    (["--minimise", "max_barrel_displacement"], "--vary: give at least one parameter"),
    (["--vary", "contact.gap=0.1:0", "--minimise", "max_barrel_displacement"], "contact.gap: bounds must be"),
    (["--vary", "contact.gap=0:a", "--minimise", "max_barrel_displacement"], "--vary"),
    (["--vary", "absorber.mass=0:100", "--minimise", "max_barrel_displacement"], "absorber.mass"),
    (["--vary", "contact.gap=0:0.1", "--minimise", "max_barrel_displacement", "--constraint", "x<1"],
     "--constraint: must be METRIC<=VALUE"),
    (["--vary", "contact.gap=0:0.1", "--vary", "contact.gap=0:0.2", "--minimise", "max_barrel_displacement"],
     "given twice"),
    (["--vary", "contact.gap=0:0.1", "--minimise", "max_barrel_displacement", "--popsize", "0"], "--popsize"),
    (["--vary", "contact.gap=0:0.1"], "--minimise"),
    (["--vary", "contact.gap=0:0.1", "--minimise", "max_barrel_displacement", "--scheduler", "garbage"],
     "--scheduler: must be a Dask scheduler address tcp://HOST:PORT"),
    (["--vary", "contact.gap=0:0.1", "--minimise", "max_barrel_displacement", "--scheduler", "tcp://127.0.0.1:8786",
      "--worker-timeout", "-1"], "--worker-timeout: must be a number of seconds > 0"),
    (["--vary", "contact.gap=0:0.1", "--minimise", "max_barrel_displacement", "--worker-timeout", "5"],
     "--worker-timeout: is the wait for the workers of a Dask cluster"),
])
def test_bad_input_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys, args, text):
    out = tmp_path / "never"
    assert main(["optimise", "model_i", *args, "--out", str(out)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("recoil: error:") and text in lines[0], captured.err
    assert captured.out == "" and not out.exists()


def test_the_summary_prints_one_unit_system_without_plot_markup(tmp_path, capsys):
    """Every value of the summary in the SI unit typed on the command line: a constraint's limit and its value
    in the same unit, the value the one optimum.json records; plain unit strings (no matplotlib ``$``)."""
    out = tmp_path / "opt"
    code = main(["optimise", "recoil_brake", "--vary", "recoil_brake.piston_area=0.008:0.016",
                 "--vary", "recoil_brake.fluid_density=800:900", "--minimise", "peak_support_force",
                 "--constraint", "max_barrel_displacement<=1.2", "--constraint", "peak_support_force>=100",
                 "--out", str(out), *SMALL])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "$" not in captured.out + captured.err
    data = json.loads((out / "optimum.json").read_text())
    lines = captured.out.splitlines()
    head = lines[0].split(" = ")[1].split()
    assert float(head[0]) == pytest.approx(data["objective"], rel=1e-5) and head[1] == "N"
    area = next(line.split() for line in lines if "recoil_brake.piston_area" in line)
    assert float(area[1]) == pytest.approx(data["parameters"]["recoil_brake.piston_area"], rel=1e-5)
    assert area[2] == "m^2"
    for constraint, (metric, op, limit, unit) in zip(data["constraints"], [
            ("max_barrel_displacement", "<=", 1.2, "m"), ("peak_support_force", ">=", 100.0, "N")]):
        [line] = [l for l in lines if l.strip().startswith(f"constraint {metric} {op}")]
        words = line.split()
        # constraint METRIC OP LIMIT UNIT value VALUE UNIT (met)
        assert float(words[3]) == limit and words[4] == unit
        assert words[5] == "value" and words[7] == unit
        assert float(words[6]) == pytest.approx(constraint["value"], rel=1e-5)
        assert (float(words[6]) <= limit if op == "<=" else float(words[6]) >= limit) and words[8] == "(met)"


def test_a_barrel_mass_in_tonnes_warns_on_one_line(tmp_path, capsys):
    from mbs_models import model_i, scene_to_toml

    path = tmp_path / "tonnes.toml"
    path.write_text(scene_to_toml(model_i().with_changes(**{"barrel.mass": 5.6})))
    main(["optimise", str(path), "--vary", "contact.gap=0:0.1", "--minimise", "max_barrel_displacement",
          "--end-time", "0.05", "--accuracy", "draft", "--out", str(tmp_path / "o"), *SMALL])
    warned = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(warned) == 1 and warned[0].startswith("recoil: warning: barrel.mass = 5.6 kg")


def test_an_unreachable_scheduler_is_one_line_exit_1(tmp_path, capfd):
    pytest.importorskip("dask.distributed")
    from dask_processes import free_port

    port = free_port()
    assert main(["optimise", "model_i", "--vary", "contact.gap=0:0.1", "--minimise", "max_barrel_displacement",
                 "--out", str(tmp_path / "o"), "--scheduler", f"tcp://127.0.0.1:{port}"]) == 1
    assert capfd.readouterr().err == (f"recoil: error: cannot connect to the Dask scheduler at tcp://127.0.0.1:{port}: "
                                      "connection refused (nothing listens on that port)\n")
