"""``recoil sweep`` and ``--set`` (mbs_models.cli.sweep): the table, resuming, one-line errors with exit 2."""

from __future__ import annotations

import io
import json
import re

import pandas as pd
import pytest

from mbs_models import model_i, run_sweep, simulate
from mbs_models.cli import main

GRID = ["--param", "absorber.mass=100,1000", "--param", "contact.gap=0:0.04:2"]


def test_sweep_writes_the_table_and_resumes(tmp_path, capsys):
    out = tmp_path / "gaps.csv"
    argv = ["sweep", "model_i", *GRID, "--out", str(out), "--end-time", "1", "--workers", "2"]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "4 points: 4 run, 0 resumed" in printed and "0 failed" in printed and str(out) in printed
    table = pd.read_csv(out)
    assert table[["absorber.mass", "contact.gap"]].values.tolist() == [[100, 0], [100, 0.04], [1000, 0], [1000, 0.04]]
    for row in table.to_dict("records"):
        expected = simulate(model_i(row["absorber.mass"], row["contact.gap"]), 1.0).max_barrel_displacement
        assert row["max_barrel_displacement"] == expected
    assert main(argv) == 0
    assert "4 points: 0 run, 4 resumed" in capsys.readouterr().out
    pd.testing.assert_frame_equal(pd.read_csv(out), table)


def test_sweep_json_summary_lists_the_failures(tmp_path, capsys):
    out = tmp_path / "f.csv"
    assert main(["sweep", "model_ii", "--param", "conventions.compression_only=false,true", "--out", str(out),
                 "--end-time", "0.5", "--workers", "1", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["points"] == 2 and summary["failed"] == 1 and summary["out"] == str(out)
    assert summary["failures"][0]["conventions.compression_only"] is True
    assert summary["failures"][0]["status"] == "SimulationError" and "step budget" in summary["failures"][0]["error"]


@pytest.mark.parametrize("argv, needle", [
    (["--param", "contact.gapp=0,1"], "contact.gapp: unknown key; did you mean 'gap'?"),
    (["--param", "contact.gap=0:1"], "contact.gap: a range is START:STOP:COUNT"),
    (["--param", "contact.gap=0:1:1"], "contact.gap: COUNT"),
    (["--param", "contact.gap=-1,-2"], "contact.gap: must be >= 0 m"),
    (["--param", "absorber.mass=1,heavy"], "absorber.mass: must be a number"),
    (["--param", "contact.gap"], "--param: expected KEY=SPEC"),
    (["--param", "contact.gap=0", "--param", "contact.gap=1"], "contact.gap: given twice"),
    (["--param", "absorber.1.mass=1"], "absorber.1.mass: the scene has 1 absorber(s)"),
    (["--param", "contact.gap=0", "--workers", "0"], "--workers: must be a whole number >= 1"),
    (["--param", "contact.gap=0", "--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "--workers: give either"),
    (["--param", "contact.gap=0", "--end-time", "-1"], "--end-time: must be a number of seconds"),
    (["--param", "contact.gap=0", "--out-file", "x"], "unrecognized arguments"),
])
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, argv, needle):
    out = tmp_path / "s.csv"
    code = main(["sweep", "model_i", *argv, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert needle in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not out.exists()


@pytest.mark.parametrize("out, needle", [("s.txt", "--out: must be a .csv or .parquet file"),
                                         ("a_file/s.csv", "--out: "), ("a_file/deeper/s.csv", "--out: ")])
def test_bad_out_exits_2(tmp_path, capsys, out, needle):
    (tmp_path / "a_file").write_text("")
    assert main(["sweep", "model_i", "--param", "contact.gap=0", "--out", str(tmp_path / out)]) == 2
    assert needle in capsys.readouterr().err


def test_missing_param_or_out_exits_2(capsys):
    assert main(["sweep", "model_i", "--out", "x.csv"]) == 2
    assert "--param" in capsys.readouterr().err
    assert main(["sweep", "model_i", "--param", "contact.gap=0"]) == 2
    assert "--out" in capsys.readouterr().err


@pytest.mark.parametrize("address", ["garbage", "127.0.0.1:8786", "tcp://127.0.0.1", "tcp://127.0.0.1:0",
                                     "http://127.0.0.1:8786"])
def test_a_malformed_scheduler_address_exits_2_at_once(address, tmp_path, capfd):
    out = tmp_path / "s.csv"
    assert main(["sweep", "model_i", "--param", "contact.gap=0", "--out", str(out), "--scheduler", address]) == 2
    err = capfd.readouterr().err
    assert err == (f"recoil: error: --scheduler: must be a Dask scheduler address tcp://HOST:PORT (or tls://HOST:PORT; "
                   f"PORT 1-65535) or a dask.distributed.Client, got {address!r}\n")
    assert list(tmp_path.iterdir()) == []


def test_an_unreachable_scheduler_exits_1_with_one_line_and_writes_nothing(tmp_path, capfd):
    pytest.importorskip("dask.distributed")
    import gc

    from dask_processes import free_port

    out, port = tmp_path / "s.csv", free_port()
    assert main(["sweep", "model_i", "--param", "contact.gap=0", "--out", str(out),
                 "--scheduler", f"tcp://127.0.0.1:{port}"]) == 1
    gc.collect()   # a client left half-made would print its __del__ traceback here
    assert capfd.readouterr().err == (f"recoil: error: cannot connect to the Dask scheduler at tcp://127.0.0.1:{port}: "
                                      "connection refused (nothing listens on that port)\n")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv, needle", [
    (["--scheduler", "tcp://127.0.0.1:8786", "--worker-timeout", "0"],
     "--worker-timeout: must be a number of seconds > 0"),
    (["--scheduler", "tcp://127.0.0.1:8786", "--worker-timeout", "nan"], "--worker-timeout: must be a number"),
    (["--worker-timeout", "5"], "--worker-timeout: is the wait for the workers of a Dask cluster: give a scheduler"),
])
def test_a_bad_worker_timeout_exits_2(argv, needle, tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["sweep", "model_i", "--param", "contact.gap=0", "--out", str(out), *argv]) == 2
    assert needle in capsys.readouterr().err and not out.exists()


# ---------------------------------------------------------------- a Dask cluster of processes, killed mid-sweep
#: 300 points of model (i) (about 10 ms each): long enough to be killed mid-way on any machine
KILLED_PARAMS = ["absorber.mass=100,400,1000", "contact.gap=0:0.1:100"]


def _sweep_on(cluster, out, *extra):
    """``recoil sweep`` of KILLED_PARAMS on ``cluster`` into ``out`` (a subprocess), once its file holds more than
    12 rows (the probes are 4); the process, still running, and its arguments."""
    import subprocess
    import sys

    from dask_processes import environment, wait_until

    argv = ["sweep", "model_i", *[a for p in KILLED_PARAMS for a in ("--param", p)], "--out", str(out), "--end-time",
            "1", "--accuracy", "draft"]
    proc = subprocess.Popen([sys.executable, "-m", "mbs_models", *argv, "--scheduler", cluster.address, *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=environment())
    wait_until(lambda: proc.poll() is not None or out.exists() and out.read_bytes().count(b"\n") > 13, 300,
               "13 rows in the table")
    assert proc.poll() is None, "the sweep ended before it could be hit: " + proc.communicate()[1]
    return proc, argv


def _stopped(proc, out, reason: str) -> tuple[int, list[str]]:
    """The sweep's exit code is 1, its stderr the announcement first and last one line, ``reason`` (a regex) and
    how many rows the file keeps: as many as it holds, every one ok.  Returns that count and stderr's lines."""
    _, err = proc.communicate(timeout=300)
    lines = err.splitlines()
    assert proc.returncode == 1, err
    assert lines[0].startswith("sweep: 300 points (3 x 100)") and len(lines) >= 2, err
    match = re.fullmatch(rf"recoil: error: {reason} after (\d+) of 300 points; the (\d+) rows are in "
                         rf"{re.escape(str(out))}: run the same sweep again to resume", lines[-1])
    assert match and match[1] == match[2], err
    table = pd.read_csv(out)
    assert len(table) == int(match[1]) and (table["status"] == "ok").all()
    return int(match[1]), lines


def _assert_resumes_to_the_uninterrupted_sweep(out, argv):
    """Resuming the stopped sweep (one worker) gives exactly the table of an uninterrupted run."""
    assert main([*argv, "--workers", "1"]) == 0
    expected = run_sweep(model_i(), {"absorber.mass": "100,400,1000", "contact.gap": "0:0.1:100"}, end_time=1.0,
                         accuracy="draft", workers=1, progress=False)
    resumed = pd.read_csv(out, keep_default_na=False, na_values=[""])
    expected_text = pd.read_csv(io.StringIO(expected.to_csv(index=False)), keep_default_na=False, na_values=[""])
    pd.testing.assert_frame_equal(resumed.drop(columns="wall_time"), expected_text.drop(columns="wall_time"))


@pytest.mark.slow
def test_a_scheduler_killed_mid_sweep_exits_1_keeps_the_rows_and_resumes_exactly(tmp_path):
    """SIGKILL the Dask scheduler while rows are being written: one line (no traceback), exit 1, the rows kept;
    the same sweep again gives exactly the uninterrupted table (wall times aside)."""
    from dask_processes import dask_processes


    out = tmp_path / "s.csv"
    with dask_processes(tmp_path) as cluster:
        proc, argv = _sweep_on(cluster, out)
        cluster.kill_scheduler()
        rows, lines = _stopped(proc, out, re.escape(f"the Dask scheduler {cluster.address} was lost"))
    assert len(lines) == 2 and 13 <= rows < 300   # no traceback, no log line of distributed's
    _assert_resumes_to_the_uninterrupted_sweep(out, argv)


@pytest.mark.slow
def test_every_worker_killed_mid_sweep_waits_says_so_then_exits_1_after_the_worker_timeout(tmp_path):
    from dask_processes import dask_processes

    out = tmp_path / "s.csv"
    with dask_processes(tmp_path) as cluster:
        proc, _ = _sweep_on(cluster, out, "--worker-timeout", "3")
        cluster.kill_workers()
        rows, lines = _stopped(proc, out, re.escape(f"no Dask worker has been available at {cluster.address} for "
                                                    "3 s (the worker timeout)"))
    assert 13 <= rows < 300
    assert lines[1:-1] == [f"dask: waiting for a worker: the scheduler {cluster.address} has none; giving up after 3 s "
                           "without one (the worker timeout)"]


def test_run_set_changes_the_scene_and_says_so(capsys):
    assert main(["run", "model_i", "--set", "absorber.mass=500", "--set", "contact.gap=0.04", "--end-time", "1",
                 "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["max_barrel_displacement"] == simulate(model_i(500.0, 0.04), 1.0).max_barrel_displacement
    assert data["scene"] == f"{model_i().name}, with absorber.mass=500, contact.gap=0.04"
    assert main(["run", "model_i", "--set", "absorber.mass=500", "--set", "name=light", "--end-time", "1",
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["scene"] == "light"


@pytest.mark.parametrize("command", ["run", "validate"])
@pytest.mark.parametrize("assignment, needle", [("contact.gap=-1", "contact.gap: must be >= 0 m"),
                                                ("absorber.mas=1", "did you mean 'mass'"),
                                                ("contact.gap", "--set: expected KEY=VALUE")])
def test_bad_set_exits_2(capsys, command, assignment, needle):
    assert main([command, "model_i", "--set", assignment]) == 2
    err = capsys.readouterr().err
    assert needle in err and len(err.strip().splitlines()) == 1


def test_a_table_valued_parameter_is_swept_and_resumed(tmp_path, capsys):
    """``recoil_brake.orifice_area`` as a number or a table of (stroke, area) pairs: a TOML array spec; the
    column holds each value's TOML text, so the file resumes."""
    from mbs_models import load_scene
    from mbs_models.scene.overrides import apply_overrides
    from mbs_models.scenes import scene_path

    out = tmp_path / "brake.csv"
    argv = ["sweep", "recoil_brake", "--param", "recoil_brake.orifice_area=[3e-4, [[0.0, 4e-4], [0.2, 2e-4]]]",
            "--out", str(out), "--end-time", "0.5", "--workers", "1"]
    assert main(argv) == 0
    table = pd.read_csv(out)
    assert table["recoil_brake.orifice_area"].tolist() == ["0.0003", "[[0.0, 0.0004], [0.2, 0.0002]]"]
    scene = load_scene(scene_path("recoil_brake"))
    for value, row in zip([3e-4, [[0.0, 4e-4], [0.2, 2e-4]]], table.to_dict("records")):
        expected = simulate(apply_overrides(scene, {"recoil_brake.orifice_area": value}), 0.5)
        assert row["max_barrel_displacement"] == expected.max_barrel_displacement
    assert main(argv) == 0
    assert "2 points: 0 run, 2 resumed" in capsys.readouterr().out


def test_another_end_time_into_the_same_file_exits_2(tmp_path, capsys):
    out = tmp_path / "s.csv"
    argv = ["sweep", "model_i", "--param", "contact.gap=0", "--out", str(out), "--workers", "1"]
    assert main([*argv, "--end-time", "0.2"]) == 0
    capsys.readouterr()
    assert main([*argv, "--end-time", "0.3"]) == 2
    err = capsys.readouterr().err
    assert "--out:" in err and "another end_time" in err and len(err.strip().splitlines()) == 1


def test_a_sweep_over_gaps_in_millimetres_warns_once_before_it_runs(tmp_path, capsys):
    out = tmp_path / "mm.csv"
    assert main(["sweep", "model_ii", "--param", "contact.gap=0,40", "--out", str(out), "--end-time", "0.2",
                 "--accuracy", "draft", "--workers", "1", "--json"]) == 0
    captured = capsys.readouterr()
    line, announced = captured.err.strip().splitlines()  # the warning, then the sweep's announcement
    assert line.startswith("recoil: warning: absorber.contact.gap = 40 m is beyond")
    assert announced.startswith("sweep: 2 points (2)")
    assert json.loads(captured.out)["points"] == 2  # and the sweep ran every point
    assert main(["sweep", "model_ii", "--param", "contact.gap=0,40", "--out", str(out), "--end-time", "0.2",
                 "--accuracy", "draft", "--workers", "1"]) == 0  # resumed: the text summary
    captured = capsys.readouterr()
    assert "$" not in captured.out + captured.err


def test_sweep_says_how_many_points_and_about_how_long_first(tmp_path, capsys):
    out = tmp_path / "s.csv"
    argv = ["sweep", "model_i", *GRID, "--out", str(out), "--end-time", "1", "--workers", "2", "--json"]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert re.fullmatch(r"sweep: 4 points \(2 x 2\), ~[0-9.]+ ms per point on 2 workers: about [0-9.]+ s "
                        r"\(an estimate from one point's solve\)\n", err), err
    assert main(argv) == 0
    assert capsys.readouterr().err == f"sweep: 4 points (2 x 2), 4 already in {out}: nothing to run\n"


def test_a_grid_beyond_the_limit_exits_2_without_large(tmp_path, capsys):
    out = tmp_path / "big.csv"
    argv = ["sweep", "model_ii", "--param", "absorber.mass=1:1000:10000", "--param", "contact.gap=0:0.1:10000",
            "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == ("recoil: error: --large: the grid has 100,000,000 points (10,000 x 10,000), more than the "
                   "1,000,000 a sweep runs unless asked: give --large to run it anyway\n")
    assert list(tmp_path.iterdir()) == []


def test_large_runs_a_grid_beyond_the_limit(tmp_path, capsys, monkeypatch):
    from mbs_models.studies import grid as grid_module

    monkeypatch.setattr(grid_module, "MAX_POINTS", 3)
    out = tmp_path / "s.csv"
    argv = ["sweep", "model_i", *GRID, "--out", str(out), "--end-time", "0.5", "--workers", "1"]
    assert main(argv) == 2
    assert "4 points (2 x 2), more than the 3" in capsys.readouterr().err and not out.exists()
    assert main([*argv, "--large"]) == 0
    assert "4 points: 4 run" in capsys.readouterr().out and len(pd.read_csv(out)) == 4


def test_a_killed_sweep_resumes_to_exactly_the_uninterrupted_table(tmp_path):
    """SIGKILL (the process and its pool) while rows are being written, then the same command again: the table
    is the one an uninterrupted run gives (wall times aside)."""
    import os
    import signal
    import subprocess
    import sys
    import time


    params = ["absorber.mass=100,400,1000", "contact.gap=0:0.1:100"]
    out = tmp_path / "s.csv"
    argv = ["sweep", "model_i", *[a for p in params for a in ("--param", p)], "--out", str(out), "--end-time", "1",
            "--accuracy", "draft"]
    proc = subprocess.Popen([sys.executable, "-m", "mbs_models", *argv, "--workers", "2"], start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            if out.exists() and out.read_bytes().count(b"\n") > 12:
                break
            time.sleep(0.005)
        running = proc.poll() is None
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    assert running, "the sweep ended before it could be killed"
    rows = out.read_bytes().count(b"\n") - 1
    assert 12 <= rows < 300
    _assert_resumes_to_the_uninterrupted_sweep(out, argv)


# ================================================================================================ faults
FAKE = ["--param", "absorber.mass=100,400,1000", "--param", "contact.gap=0:0.1:101"]   # 303 points


def _fake_run(argv: list[str], **popen) -> "subprocess.Popen":
    """``recoil ARGV`` in a new process (its own session: its pool is killed with it) whose points are
    tests/fake_points.fake_point, after ``prelude`` (Python run first)."""
    import os
    import subprocess
    import sys

    prelude = popen.pop("prelude", "")
    script = ("import sys\nimport fake_points\nfrom mbs_models.studies import point\n"
              "point.evaluate_point = fake_points.fake_point\n" + prelude +
              "from mbs_models.cli import main\nsys.exit(main(sys.argv[1:]))\n")
    return subprocess.Popen([sys.executable, "-c", script, *argv], start_new_session=True,
                            env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}, **popen)


def _kill(proc) -> None:
    import os
    import signal

    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait()


def _uninterrupted(monkeypatch, grid=None):
    import fake_points


    fake_points.patch(monkeypatch)
    grid = grid or {"absorber.mass": "100,400,1000", "contact.gap": "0:0.1:101"}
    return fake_points.as_read(run_sweep(model_i(), grid, workers=1, progress=False))


def _read(out):
    """The table in ``out`` as plain pandas reads it from CSV, without wall times (fake_points.as_read)."""
    import fake_points

    if out.suffix == ".csv":
        return pd.read_csv(out, keep_default_na=False, na_values=[""]).drop(columns="wall_time")
    return fake_points.as_read(pd.read_parquet(out))


def test_a_point_that_raises_anything_is_a_failed_row(tmp_path, capsys, monkeypatch):
    """The report's case: an extreme value whose solve raises an OverflowError (here made to) is a row, the sweep
    goes on (on a pool: its worker reports it), and running the command again runs nothing."""
    from mbs_models.studies import point

    real = point.simulate_scene

    def overflowing(scene, settings):
        if scene.initial_velocity > 1e3:   # m/s of the barrel: the muzzle velocity of 1e7 m/s
            raise OverflowError(34, "Numerical result out of range")
        return real(scene, settings)

    monkeypatch.setattr(point, "simulate_scene", overflowing)
    out = tmp_path / "t.csv"
    argv = ["sweep", "model_i", "--param", "firing.muzzle_velocity=564,1e7,600", "--out", str(out), "--end-time",
            "0.2", "--accuracy", "draft", "--workers", "2"]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "3 points: 3 run, 0 resumed from the file, 1 failed" in printed
    assert "failed at firing.muzzle_velocity=10000000.0: OverflowError: (34, 'Numerical result out of range')" in printed
    assert pd.read_csv(out)["status"].tolist() == ["ok", "OverflowError", "ok"]
    assert main(argv) == 0
    assert "3 points: 0 run, 3 resumed from the file, 1 failed" in capsys.readouterr().out


def test_a_second_sweep_on_the_same_file_is_refused_naming_the_first(tmp_path, capsys, monkeypatch):
    import subprocess

    out = tmp_path / "s.csv"
    argv = ["sweep", "model_i", *FAKE, "--out", str(out), "--workers", "1"]
    first = _fake_run(argv, prelude="fake_points.FAKE_SECONDS = 0.05\n", stdout=subprocess.DEVNULL,
                      stderr=subprocess.DEVNULL)
    try:
        import time

        deadline = time.monotonic() + 60
        while not (tmp_path / "s.csv.lock").exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(0.2)
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"recoil: error: --out: {out} is being written by another sweep (process {first.pid} on ")
        assert err.endswith("): wait for it to end, or give another file\n") and err.count("\n") == 1
        assert first.poll() is None
    finally:
        _kill(first)
    import fake_points

    fake_points.patch(monkeypatch)
    assert main([*argv[:-2], "--workers", "2"]) == 0   # killed: its lock is gone with it; this one resumes its rows
    assert "303 points:" in capsys.readouterr().out


@pytest.mark.parametrize("settings, needle", [
    (None, "s.csv holds rows but not s.csv.sweep.json, the record of what they were computed with (scene, end "
           "time, accuracy): restore s.csv.sweep.json, or delete s.csv to start again"),
    ("[1, 2]", "s.csv.sweep.json (what"),
])
def test_rows_without_sound_settings_exit_2_with_one_line(tmp_path, capsys, settings, needle):
    out = tmp_path / "s.csv"
    argv = ["sweep", "model_i", "--param", "contact.gap=0", "--out", str(out), "--workers", "1"]
    assert main([*argv, "--end-time", "0.2"]) == 0
    sidecar = tmp_path / "s.csv.sweep.json"
    sidecar.unlink() if settings is None else sidecar.write_text(settings)
    capsys.readouterr()
    assert main([*argv, "--end-time", "0.3"]) == 2   # another end time: mixed in, were the settings unknown
    err = capsys.readouterr().err
    assert err.startswith("recoil: error: --out: ") and needle in err and err.count("\n") == 1


def test_a_full_disk_is_one_line_and_exit_1(tmp_path, capsys):
    """A real ENOSPC: the table is /dev/full."""
    import os

    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    out = tmp_path / "s.csv"
    out.symlink_to("/dev/full")
    assert main(["sweep", "model_i", "--param", "contact.gap=0,0.01", "--out", str(out), "--end-time", "0.2",
                 "--workers", "1"]) == 1
    err = capsys.readouterr().err
    assert err == (f"recoil: error: cannot write {out}: No space left on device; every row written before is kept: "
                   "make room and run the same sweep again to resume\n")


def test_unreadable_rows_are_one_line_on_stderr(tmp_path, capsys, monkeypatch):
    import fake_points

    fake_points.patch(monkeypatch)
    out = tmp_path / "s.csv"
    argv = ["sweep", "model_i", "--param", "contact.gap=0,0.01,0.02", "--out", str(out), "--workers", "1"]
    assert main(argv) == 0
    lines = out.read_bytes().splitlines(keepends=True)
    out.write_bytes(b"".join(lines[:2]) + lines[0] + lines[2][:20] + b"\n" + lines[3])
    capsys.readouterr()
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert captured.err.splitlines()[0] == f"{out}: 2 rows unreadable (line 3, 4): their points run again"
    assert "3 points: 1 run, 2 resumed from the file, 0 failed" in captured.out
    written = out.read_bytes().splitlines(keepends=True)   # rewritten in grid order, the bad lines gone
    assert len(written) == 4 and written[:2] == lines[:2] and written[3] == lines[3]
    pd.testing.assert_frame_equal(_read(out), _uninterrupted(monkeypatch, {"contact.gap": "0,0.01,0.02"}))


def test_a_kill_during_the_parquet_rewrite_leaves_nothing_the_next_run_keeps(tmp_path, monkeypatch):
    """SIGKILL while the finished Parquet table is being written (its temporary file half done): the next run
    removes the temporary file and ends with the table."""
    import subprocess

    pytest.importorskip("pyarrow")
    out = tmp_path / "s.parquet"
    argv = ["sweep", "model_i", *FAKE, "--out", str(out), "--workers", "1"]
    slow_rewrite = ("from mbs_models.studies import sweep_table\nimport time\nwrite = sweep_table._ChunkWriter.write\n"
                    "def slow(self, chunk):\n    write(self, chunk)\n    print('rewriting', flush=True)\n"
                    "    time.sleep(120)\nsweep_table._ChunkWriter.write = slow\n")
    proc = _fake_run(argv, prelude=slow_rewrite, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        assert proc.stdout.readline().strip() == "rewriting"
        left = [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
        assert left and all(name.startswith(".s.parquet.") for name in left)
    finally:
        _kill(proc)
    assert not out.exists() and (tmp_path / "s.parquet.rows.csv").exists() and left == [
        p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
    expected = _uninterrupted(monkeypatch)
    assert main(argv) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.parquet", "s.parquet.sweep.json"]
    pd.testing.assert_frame_equal(_read(out), expected)


def _damage(path, rng) -> str:
    """One fault a crash can leave in a table being appended to, chosen by ``rng``; what it was."""
    lines = path.read_bytes().splitlines(keepends=True)
    rows = [line for line in lines[1:] if line.endswith(b"\n")]
    if not rows:
        return "nothing"
    kind = rng.integers(5)
    row = rows[rng.integers(len(rows))]
    if kind == 0:     # the last complete row torn and ended by a newline (its point must run again)
        body = b"".join(lines[:-1]) if not lines[-1].endswith(b"\n") else b"".join(lines)
        last = body.splitlines(keepends=True)[-1]
        if last == lines[0]:
            return "nothing"
        path.write_bytes(body[:-len(last)] + last[:rng.integers(1, len(last) - 1)] + b"\n")
        return "torn last row"
    extra = {1: row[:rng.integers(1, len(row) - 1)] + b"\n",            # a torn copy of a row
             2: lines[0],                                                # a second header
             3: b"\0" * int(rng.integers(1, 200)) + b"\n",              # zeros
             4: row.replace(b",end_time,", b",end_time,oops", 1)                # steps no number, or
                   .replace(b",SimulationError,", b",Simulation Error,", 1)}[kind]   # a status no class name
    with open(path, "ab") as handle:
        handle.write(extra if lines[-1].endswith(b"\n") else b"\n" + extra)
    return ["", "torn copy", "header", "zeros", "garbled"][kind]


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_killed_at_random_moments_with_damaged_rows_resumes_to_the_uninterrupted_table(tmp_path, monkeypatch,
                                                                                        suffix):
    """Fault injection: the sweep is SIGKILLed (with its pool) at random moments -- while it writes rows, or
    folds a Parquet journal in -- and between runs its file gets the damage a crash can leave (a torn row ended by
    a newline, a second header, zeros, a garbled cell).  Once a run finishes, the table is exactly the one an
    uninterrupted run writes (wall times aside), with no temporary file, journal or lock left."""
    import subprocess
    import time

    import numpy as np

    if suffix == ".parquet":
        pytest.importorskip("pyarrow")
    rng = np.random.default_rng(20)
    out = tmp_path / f"s{suffix}"
    appended = out if suffix == ".csv" else tmp_path / "s.parquet.rows.csv"
    argv = ["sweep", "model_i", *FAKE, "--out", str(out), "--workers", "2"]
    kills, damage = 0, []

    def lines():
        return appended.read_bytes().count(b"\n") if appended.exists() else 0

    for attempt in range(6):
        before = lines()
        proc = _fake_run(argv, prelude="fake_points.FAKE_SECONDS = 0.01\n", stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)   # 1.5 s of points on 2 workers
        # the moment: once 1 to 60 more rows are written, or (one time in four) after 0 to 1.2 s: in the start-up,
        # the reading of the file, or the final rewrite
        grown, seconds = int(rng.integers(1, 61)), float(rng.uniform(0, 1.2)) if rng.integers(4) == 0 else None
        try:
            start = time.monotonic()
            while proc.poll() is None and time.monotonic() < start + 120:
                if (time.monotonic() - start >= seconds) if seconds is not None else lines() >= before + grown:
                    break
                time.sleep(0.002)
        finally:
            finished = proc.poll() == 0
            _kill(proc)
        if finished:
            break
        kills += 1
        if appended.exists():
            damage.append(_damage(appended, rng))
    assert kills >= 3, "the sweep was not killed often enough to test anything"
    expected = _uninterrupted(monkeypatch)
    assert main(argv) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([out.name, out.name + ".sweep.json"]), damage
    pd.testing.assert_frame_equal(_read(out), expected)
