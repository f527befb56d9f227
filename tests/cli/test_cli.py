"""The ``recoil`` command line: bad input gives one line on stderr and exit code 2."""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib

import pytest

from mbs_models import model_ii, scene_to_toml
from mbs_models.cli import main
from mbs_models.elements.contact_laws import LawFields
from validation.reference.assembly import build_model


def _write_toml(path, data: dict) -> None:
    lines = []
    scalars = {k: v for k, v in data.items() if not isinstance(v, dict)}
    tables = {k: v for k, v in data.items() if isinstance(v, dict)}

    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, float) and v != v:
            return "nan"
        if isinstance(v, float) and v in (float("inf"), float("-inf")):
            return "inf" if v > 0 else "-inf"
        return repr(v)

    lines += [f"{k} = {value(v)}" for k, v in scalars.items()]
    for name, table in tables.items():
        lines.append(f"[{name}]")
        lines += [f"{k} = {value(v)}" for k, v in table.items()]
    path.write_text("\n".join(lines) + "\n")


def test_bad_scene_via_cli(tmp_path, capsys, bad_scene):
    data, key, text = bad_scene
    path = tmp_path / "bad.toml"
    _write_toml(path, data)
    assert tomllib.loads(path.read_text()) is not None
    code = main(["run", str(path)])
    captured = capsys.readouterr()
    assert code == 2
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert key in lines[0] and text in lines[0]
    assert "Traceback" not in captured.err
    assert captured.out == ""


def test_console_script_reports_without_traceback(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(scene_to_toml(model_ii()).replace("gap = 0.0", "gap = -0.5"))
    proc = subprocess.run([sys.executable, "-m", "mbs_models", "run", str(path)], capture_output=True, text=True)
    assert proc.returncode == 2
    assert proc.stderr.strip() == "recoil: error: absorber.contact.gap: must be >= 0 m, got -0.5"


@pytest.mark.parametrize("argv, needle", [
    (["run", "model_ii", "--end-time", "0"], "--end-time"),
    (["run", "model_ii", "--end-time", "nan"], "--end-time"),
    (["run", "model_ii", "--accuracy", "sloppy"], "--accuracy"),
    (["run", "model_ii", "--impact-threshold", "-1"], "--impact-threshold"),
    (["run"], "scene"),
    (["frobnicate"], "invalid choice"),
])
def test_bad_arguments_exit_2(capsys, argv, needle):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and needle in err


def test_run_json_has_design_keys(capsys):
    assert main(["run", "model_ii", "--json", "--end-time", "1.0"]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("max_barrel_displacement", "time_of_max_barrel_displacement", "peak_contact_force",
                "max_absorber_velocity", "time_of_max_absorber_velocity", "impacts", "wall_time"):
        assert key in data
    assert all(set(impact) >= {"start", "end", "peak_force"} for impact in data["impacts"])
    assert data["impacts"] and data["peak_contact_force"] == max(i["peak_force"] for i in data["impacts"])


def test_run_simplified_json_has_null_contact_metrics(capsys):
    assert main(["run", "simplified", "--json", "--end-time", "2"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["peak_contact_force"] is None and data["max_absorber_velocity"] is None
    assert data["impacts"] == []


def test_run_plot_writes_png(tmp_path, capsys):
    (tmp_path / "plots").mkdir()
    target = tmp_path / "plots" / "run.png"
    assert main(["run", "model_i", "--end-time", "1", "--plot", str(target)]) == 0
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "max barrel displacement" in capsys.readouterr().out


def test_plot_into_unwritable_place_is_bad_input(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["run", "model_i", "--end-time", "1", "--plot", str(blocker / "run.png")]) == 2
    assert "--plot" in capsys.readouterr().err


def test_run_json_of_a_version_2_scene_has_the_new_keys(tmp_path, capsys, every_element):
    """Version-1 keys keep their meaning; peak_support_force, absorbers, stops and energy are added (a scene
    of every element: tests/conftest.py's every_element)."""
    scene = every_element()
    path = tmp_path / "every_element.toml"
    path.write_text(scene_to_toml(scene))
    assert main(["run", str(path), "--end-time", "3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("max_barrel_displacement", "time_of_max_barrel_displacement", "peak_contact_force",
                "max_absorber_velocity", "time_of_max_absorber_velocity", "impacts", "wall_time",
                "peak_support_force", "time_of_peak_support_force", "absorbers", "stops", "energy"):
        assert key in data, key
    assert [a["name"] for a in data["absorbers"]] == scene.absorber_names()
    assert max(a["peak_contact_force"] for a in data["absorbers"]) == data["peak_contact_force"]
    # the contacts of the other tables are the stops, named like their tables (DESIGN.md)
    stops = [name for name, table in scene.elements() if isinstance(table, LawFields)]
    assert stops and [s["name"] for s in data["stops"]] == stops
    # every stop reached is reported with its force and energy (one out of reach -- gravity keeping an unpreloaded
    # barrel from battery -- with neither)
    assert any(s["peak_contact_force"] > 0 for s in data["stops"])
    assert all((s["peak_contact_force"] > 0) == (s["dissipated_energy"] > 0) for s in data["stops"])
    # per element: kinetic + stored + dissipated - work of the external inputs (shots, loads) = initial energy,
    # as the independent reference has it (kinetic + stored at t = 0: a preload stores energy)
    energy = sum(parts["kinetic"] + parts["stored"] + parts["dissipated"] - parts.get("work", 0.0)
                 for parts in data["energy"].values())
    model = build_model(scene)
    initial = float(model.mechanical_energy(model.initial_state()))
    supplied = abs(initial) + scene.initial_kinetic_energy + sum(abs(p.get("work", 0.0)) for p in data["energy"].values())
    assert abs(energy - initial) < 1e-5 * supplied
    assert data["initial_velocity"] == scene.initial_velocity


def test_run_plot_of_several_absorbers(tmp_path, capsys):
    path = tmp_path / "run.png"
    assert main(["run", "two_absorbers", "--end-time", "1", "--plot", str(path)]) == 0
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "peak support force" in capsys.readouterr().out


def test_version_prints_the_package_version():
    from mbs_models import __version__

    proc = subprocess.run([sys.executable, "-m", "mbs_models", "--version"], capture_output=True, text=True)
    assert proc.returncode == 0 and proc.stdout.strip() == f"recoil {__version__}"


def _subparsers(parser):
    """Every (name, parser) of ``parser``'s subcommands, nested ones included."""
    import argparse

    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield name, sub
                yield from ((f"{name} {inner}", p) for inner, p in _subparsers(sub))


def test_every_option_of_every_subcommand_has_help():
    import argparse

    from mbs_models.cli import build_parser

    parser = build_parser()
    commands = [("recoil", parser), *_subparsers(parser)]
    assert len(commands) > 10  # the walk found the subcommands
    missing = [f"{name} {action.option_strings[0] if action.option_strings else action.dest}"
               for name, command in commands for action in command._actions
               if not isinstance(action, (argparse._SubParsersAction,)) and not (action.help or "").strip()]
    assert missing == []


@pytest.mark.parametrize("command", ["run", "validate", "contact-laws", "design-brake", "sweep", "optimise",
                                     "stability"])
def test_accuracy_help_shows_the_default_and_what_each_preset_means(capsys, command):
    with pytest.raises(SystemExit) as exit_info:
        main([command, "--help"])
    assert exit_info.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "(default: standard)" in text
    for preset in ("draft =", "standard =", "reference ="):
        assert preset in text, preset


def test_validate_table_has_a_unit_column(capsys):
    assert main(["validate", "model_ii", "--end-time", "0.5", "--accuracy", "draft"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1].split()[:2] == ["quantity", "unit"]
    units = {line.split()[0]: line.split()[1] for line in lines[2:-1]}
    assert units["max_barrel_displacement"] == "m" and units["time_of_max_barrel_displacement"] == "s"
    assert units["peak_contact_force"] == "N" and units["max_absorber_velocity"] == "m/s"
    assert units["peak_support_force"] == "N"


def test_validate_warns_of_a_contact_that_cannot_close(tmp_path, capsys):
    path = tmp_path / "mm.toml"
    path.write_text(scene_to_toml(model_ii(1000.0, 40.0)))
    main(["validate", str(path), "--end-time", "0.5", "--accuracy", "draft"])
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("recoil: warning: absorber.contact.gap = 40 m")


def test_output_piped_into_a_reader_that_stops_gives_no_traceback():
    """``recoil run ... | head -1``: the reader closes the pipe; no traceback, the run's exit code."""
    proc = subprocess.Popen([sys.executable, "-m", "mbs_models", "run", "model_ii", "--end-time", "0.2",
                             "--accuracy", "draft"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # before the process writes anything (it is still importing)
    err = proc.stderr.read().decode()
    assert proc.wait() == 0 and "Traceback" not in err and "BrokenPipe" not in err, err


def _one_error_line(capsys) -> str:
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("recoil: error:"), captured.err
    assert "Traceback" not in captured.err and captured.out == ""
    return lines[0]


@pytest.mark.parametrize("command", ["run", "validate", "sweep", "optimise"])
def test_a_misspelt_shipped_scene_gets_a_did_you_mean(capsys, tmp_path, monkeypatch, command):
    monkeypatch.chdir(tmp_path)  # no file of that name here
    extra = {"sweep": ["--param", "contact.gap=0,0.01", "--out", "s.csv"],
             "optimise": ["--vary", "contact.gap=0:0.1", "--minimise", "max_barrel_displacement"]}.get(command, [])
    assert main([command, "two_absorber", *extra]) == 2
    line = _one_error_line(capsys)
    assert "'two_absorber'" in line and "did you mean 'two_absorbers'?" in line
    assert list(tmp_path.iterdir()) == []


def test_a_name_far_from_every_shipped_scene_lists_them(capsys, tmp_path, monkeypatch):
    from pathlib import Path

    import mbs_models.scenes

    shipped = sorted(p.stem for p in Path(mbs_models.scenes.__file__).parent.glob("*.toml"))
    monkeypatch.chdir(tmp_path)
    assert main(["run", "xyzzy"]) == 2
    line = _one_error_line(capsys)
    assert "did you mean" not in line and line.endswith(", ".join(shipped))


def test_a_shipped_name_with_toml_that_is_not_here_points_at_the_name(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["run", "model_ii.toml"]) == 2
    assert "the shipped scene 'model_ii'" in _one_error_line(capsys)
    assert main(["run", "elsewhere/model_ii.toml"]) == 2  # a path: its own error
    assert "scene file not found: elsewhere/model_ii.toml" in _one_error_line(capsys)


def test_a_version_2_scene_without_its_version_key_is_one_line_exit_2(capsys, tmp_path):
    from mbs_models.scenes import scene_path

    path = tmp_path / "two.toml"
    path.write_text(scene_path("two_absorbers").read_text().replace("version = 2", ""))
    assert main(["run", str(path)]) == 2
    line = _one_error_line(capsys)
    assert "[[absorber]]" in line and line.endswith("add version = 2 at the top")


def test_scenes_lists_every_shipped_scene_with_its_name(capsys):
    from pathlib import Path

    import mbs_models.scenes

    files = sorted(Path(mbs_models.scenes.__file__).parent.glob("*.toml"), key=lambda p: p.stem)
    assert main(["scenes"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == len(files)
    for line, file in zip(lines, files):
        name, description = line.split(None, 1)
        assert name == file.stem and description == tomllib.loads(file.read_text())["name"]
    assert main(["scenes", "--path"]) == 0
    for line, file in zip(capsys.readouterr().out.splitlines(), files):
        assert line.split()[0] == file.stem and f"  {file}  " in line  # a path may hold spaces
        assert line.endswith("  " + tomllib.loads(file.read_text())["name"])


def _cpu_seconds(pid: int) -> float:
    """User + system CPU time (s) of a running process (Linux /proc)."""
    import os
    from pathlib import Path

    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def test_ctrl_c_stops_a_long_run_at_once_with_one_line_and_exit_130(tmp_path):
    """Issue #20: a stiff spring over 300 s (millions of steps) is interrupted in its solve: exit 130 within a few
    seconds, one line, no traceback, no CSV half-written."""
    import os
    import signal
    import time
    from pathlib import Path

    if not Path(f"/proc/{os.getpid()}/stat").exists():
        pytest.skip("needs /proc to know the child is solving")
    csv = tmp_path / "histories.csv"
    proc = subprocess.Popen([sys.executable, "-m", "mbs_models", "run", "simplified", "--set",
                             "recoil_spring.stiffness=1e12", "--end-time", "300", "--no-stop-at-rest",
                             "--csv", str(csv)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120.0
        while _cpu_seconds(proc.pid) < 1.5:  # a whole short run takes 0.3 s of CPU: it is solving
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        sent = time.monotonic()
        out, err = proc.communicate(timeout=30)
        waited = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, (out, err)
    assert err == "recoil: interrupted\n" and out == ""
    assert waited < 5.0  # the solve does not run on to the end (a guard, not a speed test)
    assert not csv.exists() and not list(tmp_path.iterdir())


def test_an_accuracy_warning_is_one_line(capsys):
    """Every warning of the project is recoil's own line (found by tests/test_fuzz.py: an AccuracyWarning came in
    Python's two-line format with the source path): a barrel barely moving (E0 ~ 1e-12 J), a damper of 3.7e9."""
    code = main(["run", "simplified", "--set", "recoil_damper.counter_recoil=3670205102.2571373",
                 "--set", "firing.muzzle_velocity=2.2203689270004785e-05", "--end-time", "2", "--json"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 0 and any("energy balance is off" in line for line in err), err
    assert all(line.startswith("recoil: warning: ") for line in err), err


#: Per command writing files: arguments that write into the directory OUT (not yet there), and arguments with
#: one bad input (an option out of range, an unknown metric or file...) that must leave nothing behind.
_WRITERS = {
    "run": (["run", "model_ii", "--end-time", "0.2", "--accuracy", "draft", "--plot", "OUT/r.png", "--csv",
             "OUT/r.csv"], ["run", "model_ii", "--end-time", "-1", "--plot", "OUT/r.png"]),
    "sweep": (["sweep", "model_i", "--param", "contact.gap=0", "--end-time", "0.2", "--accuracy", "draft",
               "--workers", "1", "--out", "OUT/s.csv"],
              ["sweep", "model_i", "--param", "contact.gap=zero", "--out", "OUT/s.csv"]),
    "plot-sweep": (["plot-sweep", "TABLE", "--out", "OUT/p.png"], ["plot-sweep", "NO_TABLE.csv", "--out", "OUT/p.png"]),
    "optimise": (["optimise", "model_i", "--vary", "contact.gap=0:0.1", "--minimise", "max_barrel_displacement",
                  "--popsize", "2", "--maxiter", "1", "--workers", "1", "--end-time", "1", "--out", "OUT"],
                 ["optimise", "model_i", "--vary", "contact.gap=0:0.1", "--minimise", "no_such_metric",
                  "--out", "OUT"]),
    "design-brake": (["design-brake", "simplified", "--recoil-length", "0.15", "--end-time", "3", "--accuracy",
                      "draft", "--out", "OUT"], ["design-brake", "simplified", "--recoil-length", "-1", "--out", "OUT"]),
    "stability": (["stability", "towed_howitzer", "--elevations", "0", "--end-time", "0.5", "--accuracy", "draft",
                   "--out", "OUT"], ["stability", "towed_howitzer", "--end-time", "-1", "--out", "OUT"]),
    "precision": (["precision", "--quick", "--end-time", "0.5", "--repeats", "1", "--out", "OUT"],
                  ["precision", "--repeats", "0", "--out", "OUT"]),
    "contact-laws": (["contact-laws", "--accuracy", "draft", "--out", "OUT"],
                     ["contact-laws", "--accuracy", "rough", "--out", "OUT"]),
    # its run (a report, seconds) is tests/validation/studies/test_report.py's, written into a new directory
    "paper": (None, ["paper", "--workers", "0", "--out", "OUT"]),
}


def _argv(argv, tmp_path):
    table = tmp_path / "table" / "s.csv"
    return [a.replace("OUT", str(tmp_path / "new" / "deeper")).replace("NO_TABLE", str(tmp_path / "none"))
            .replace("TABLE", str(table)) for a in argv]


def test_every_command_that_writes_is_listed():
    from mbs_models.cli import build_parser

    parser = build_parser()
    writers = {name for name, command in _subparsers(parser)
               if any(a.dest in ("out", "plot", "csv") for a in command._actions)}
    assert writers == set(_WRITERS)


@pytest.mark.parametrize("command", sorted(_WRITERS))
def test_bad_input_leaves_no_directory_behind(tmp_path, capsys, command):
    assert main(_argv(_WRITERS[command][1], tmp_path)) == 2
    err = capsys.readouterr().err
    assert err.startswith("recoil: error:") and "Traceback" not in err
    assert not (tmp_path / "new").exists()


@pytest.mark.parametrize("command", sorted(name for name, (good, _) in _WRITERS.items() if good is not None))
def test_missing_output_directories_are_created(tmp_path, capsys, command):
    """One rule for every command: a missing output directory is created (with its parents)."""
    if command == "plot-sweep":
        assert main(["sweep", "model_i", "--param", "contact.gap=0,0.01", "--end-time", "0.2", "--accuracy", "draft",
                     "--workers", "1", "--out", str(tmp_path / "table" / "s.csv")]) == 0
    assert main(_argv(_WRITERS[command][0], tmp_path)) == 0
    written = [p for p in (tmp_path / "new" / "deeper").iterdir() if not p.name.startswith(".")]
    assert written, f"{command} wrote nothing into the new directory"
