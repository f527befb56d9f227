"""Sweeps (mbs_models.studies.sweep): run_sweep's grids (the numbers of single runs whichever backend runs them,
resuming, failures kept per point) and the scene lists of run_scenes/gap_sweep/parallel_map."""

from __future__ import annotations

import os
import signal

import pandas as pd
import pytest

import mbs_models
from mbs_models import Conventions, SceneError, model_i, model_ii, simulate
from mbs_models.studies import point as point_module
from mbs_models.studies.point import SCALAR_METRICS
from mbs_models.studies.sweep import (InlineExecutor, gap_sweep, parallel_map, process_pool, run_scenes, run_sweep,
                                      run_sweep_jobs, sweep_jobs)


def test_parallel_gap_sweep_equals_serial_simulate():
    gaps = [0.0, 0.02, 0.05]
    parallel = gap_sweep(model_i, 500.0, gaps, end_time=2.0, workers=2)
    serial = gap_sweep(model_i, 500.0, gaps, end_time=2.0, workers=1)
    assert [p.gap for p in parallel] == gaps
    for a, b, gap in zip(parallel, serial, gaps):
        assert a.max_barrel_displacement == b.max_barrel_displacement
        assert a.max_barrel_displacement == simulate(model_i(500.0, gap), 2.0).max_barrel_displacement
        assert a.error is None


def test_failed_point_carries_its_reason_and_does_not_stop_the_sweep():
    scenes = [model_ii(1000.0, 0.0), model_ii(1000.0, 0.0, Conventions(compression_only=True))]
    points = run_scenes(scenes, end_time=0.5, workers=1)
    assert points[0].error is None and points[0].max_barrel_displacement > 0
    assert points[1].max_barrel_displacement is None and "step budget" in points[1].error


@pytest.mark.parametrize("workers", [0, -1, 1.5, True])
def test_bad_worker_counts(workers):
    with pytest.raises(SceneError, match="workers"):
        parallel_map(abs, [1, 2], workers=workers)
    with pytest.raises(SceneError, match="workers"):
        with process_pool(workers):
            pass


@pytest.mark.parametrize("workers", [1, 2])
def test_sweep_jobs_in_chunks_on_a_shared_pool_equal_run_scenes(workers):
    """A sweep cut into chunks and run on a pool beside other jobs gives run_scenes's points, in order."""
    scenes = [model_i(500.0, gap) for gap in (0.0, 0.02, 0.05)]
    jobs = sweep_jobs(scenes, 2.0, stop_when_final=("max_barrel_displacement",))
    with process_pool(workers) as pool:
        assert isinstance(pool, InlineExecutor) == (workers == 1)
        other = pool.submit(abs, -3)
        chunks = [pool.submit(run_sweep_jobs, jobs[i:i + 2]) for i in range(0, len(jobs), 2)]
        points = [p for chunk in chunks for p in chunk.result()]
        assert other.result() == 3
    expected = run_scenes(scenes, 2.0, workers=1, stop_when_final=("max_barrel_displacement",))
    assert [p.max_barrel_displacement for p in points] == [p.max_barrel_displacement for p in expected]
    assert [p.gap for p in points] == [0.0, 0.02, 0.05]


def test_inline_executor_hands_errors_over_through_the_future():
    future = InlineExecutor().submit(int, "not a number")
    with pytest.raises(ValueError):
        future.result()


def test_bad_sweep_arguments_fail_fast():
    with pytest.raises(SceneError, match="end_time"):
        run_scenes([model_i()], end_time=-1.0)
    with pytest.raises(SceneError, match="scenes"):
        run_scenes(["not a scene"])
    with pytest.raises(SceneError, match="end_time"):
        sweep_jobs([model_i()], end_time=0.0)


def test_progress_is_reported():
    calls = []
    parallel_map(abs, [-1, -2, -3], workers=1, progress=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 3), (2, 3), (3, 3)]


# ================================================================================================ run_sweep: grids
FIG_GRID = {"absorber.mass": [100.0, 1000.0], "contact.gap": [0.0, 0.04, 0.08]}  # Figs 4/5, reduced


def _values(table: pd.DataFrame) -> pd.DataFrame:
    """The table without its wall times (the only column that differs between two runs of a point)."""
    return table.drop(columns="wall_time")


def _assert_file_holds(path, table: pd.DataFrame) -> None:
    """The CSV file holds ``table`` in its order (read as plain CSV; wall times aside)."""
    written = pd.read_csv(path, keep_default_na=False, na_values=[""])
    assert list(written.columns) == list(table.columns)
    for column in table.columns:
        if column != "wall_time":
            left = written[column].astype(object).where(written[column].notna(), None).tolist()
            right = table[column].astype(object).where(table[column].notna(), None).tolist()
            assert left == right, column


def test_run_sweep_is_the_public_entry_point():
    assert mbs_models.run_sweep is run_sweep


@pytest.mark.parametrize("factory", [model_i, model_ii], ids=["model_i", "model_ii"])
def test_rows_equal_single_simulate_runs_point_by_point(factory):
    table = run_sweep(factory(), FIG_GRID, end_time=2.0, workers=2, progress=False)
    assert len(table) == 6 and (table["status"] == "ok").all() and table["error"].isna().all()
    for row, (mass, gap) in zip(table.to_dict("records"), [(m, g) for m in (100.0, 1000.0) for g in (0.0, 0.04, 0.08)]):
        assert (row["absorber.mass"], row["contact.gap"]) == (mass, gap)
        result = simulate(factory(mass, gap), 2.0)
        for name in SCALAR_METRICS:
            expected = len(result.impacts) if name == "impacts" else getattr(result, name)
            assert row[name] == expected or (expected is None and pd.isna(row[name])), (name, mass, gap)


def test_serial_equals_local_parallel(tmp_path):
    serial = run_sweep(model_ii(), FIG_GRID, end_time=1.0, workers=1, progress=False)
    parallel = run_sweep(model_ii(), FIG_GRID, end_time=1.0, workers=2, batch_size=1, progress=False,
                         out=tmp_path / "p.csv")
    pd.testing.assert_frame_equal(_values(serial), _values(parallel))
    _assert_file_holds(tmp_path / "p.csv", serial)


def test_a_failing_point_is_a_row_and_the_sweep_goes_on(tmp_path):
    table = run_sweep(model_ii(1000.0, 0.0), {"conventions.compression_only": [False, True]}, end_time=0.5,
                      workers=1, progress=False, out=tmp_path / "f.csv")
    assert table["status"].tolist() == ["ok", "SimulationError"]
    assert "step budget" in table["error"][1] and pd.isna(table["max_barrel_displacement"][1])
    assert table["max_barrel_displacement"][0] > 0
    assert table.attrs["sweep"]["failed"] == 1
    invalid = run_sweep(model_i(), {"contact.law": ["hunt-crossley", "flores"], "contact.restitution": [0.5]},
                        end_time=0.5, workers=1, progress=False)
    assert invalid["status"].tolist() == ["SceneError", "ok"]
    assert invalid["error"][0].startswith("contact.restitution: not a field of law 'hunt-crossley'")


def test_resumed_after_a_cut_file_equals_uninterrupted(tmp_path):
    path = tmp_path / "s.csv"
    full = run_sweep(model_i(), FIG_GRID, end_time=1.0, workers=1, progress=False, out=path)
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines[:3]) + lines[3][:10])   # two rows kept, the third cut mid-line (a kill)
    resumed = run_sweep(model_i(), FIG_GRID, end_time=1.0, workers=2, progress=False, out=path)
    assert resumed.attrs["sweep"]["resumed"] == 2 and resumed.attrs["sweep"]["run"] == 4
    pd.testing.assert_frame_equal(_values(resumed), _values(full))
    assert resumed["wall_time"][:2].tolist() == full["wall_time"][:2].tolist()   # the kept rows come from the file
    again = run_sweep(model_i(), FIG_GRID, end_time=1.0, progress=False, out=path)
    assert again.attrs["sweep"]["run"] == 0
    pd.testing.assert_frame_equal(again, resumed)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_interrupted_and_resumed_equals_uninterrupted(tmp_path, monkeypatch, suffix):
    uninterrupted = run_sweep(model_ii(), FIG_GRID, end_time=1.0, workers=1, progress=False)
    calls = []
    evaluate = point_module.evaluate_point

    def interrupted_after_three(*args, **kwargs):
        if len(calls) == 3:
            raise KeyboardInterrupt
        calls.append(1)
        return evaluate(*args, **kwargs)

    monkeypatch.setattr(point_module, "evaluate_point", interrupted_after_three)
    path = tmp_path / f"s{suffix}"
    with pytest.raises(KeyboardInterrupt):
        run_sweep(model_ii(), FIG_GRID, end_time=1.0, workers=1, batch_size=1, progress=False, out=path)
    monkeypatch.setattr(point_module, "evaluate_point", evaluate)
    written = pd.read_csv(path) if suffix == ".csv" else pd.read_parquet(path)
    assert len(written) == 3
    resumed = run_sweep(model_ii(), FIG_GRID, end_time=1.0, workers=1, progress=False, out=path)
    assert resumed.attrs["sweep"]["resumed"] == 3
    pd.testing.assert_frame_equal(_values(resumed), _values(uninterrupted))


def test_a_file_of_other_points_is_not_resumed(tmp_path):
    path = tmp_path / "s.csv"
    run_sweep(model_i(), {"contact.gap": [0.0]}, end_time=0.2, workers=1, progress=False, out=path)
    with pytest.raises(SceneError, match="not in this sweep") as info:
        run_sweep(model_i(), {"contact.gap": [0.01]}, end_time=0.2, workers=1, progress=False, out=path)
    assert info.value.key == "out"


@pytest.mark.parametrize("params, kwargs, key", [
    ({"contact.gapp": [0.0]}, {}, "contact.gapp"),
    ({"contact.gap": "0:1"}, {}, "contact.gap"),
    ({"contact.gap": [-1.0]}, {}, "contact.gap"),
    ({"contact.gap": [0.0]}, {"end_time": -1.0}, "end_time"),
    ({"contact.gap": [0.0]}, {"accuracy": "best"}, "accuracy"),
    ({"contact.gap": [0.0]}, {"workers": 0}, "workers"),
    ({"contact.gap": [0.0]}, {"batch_size": 0}, "batch_size"),
    ({"contact.gap": [0.0]}, {"stop_when_final": ("max_barrel",)}, "stop_when_final"),
])
def test_bad_input_raises_before_anything_is_written(tmp_path, params, kwargs, key):
    path = tmp_path / "s.csv"
    with pytest.raises(SceneError) as info:
        run_sweep(model_i(), params, out=path, progress=False, **kwargs)
    assert info.value.key == key and "\n" not in str(info.value)
    assert not path.exists()


def test_progress_callback():
    calls = []
    run_sweep(model_i(), {"contact.gap": [0.0, 0.01, 0.02]}, end_time=0.2, workers=1, batch_size=1,
              progress=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 3), (2, 3), (3, 3)]


def test_stop_when_final_reaches_the_points():
    table = run_sweep(model_i(), {"contact.gap": [0.0, 0.04]}, end_time=4.0, workers=1, progress=False,
                      stop_when_final=("max_barrel_displacement",))
    for row in table.to_dict("records"):
        result = simulate(model_i(1000.0, row["contact.gap"]), 4.0, stop_when_final=("max_barrel_displacement",))
        assert row["max_barrel_displacement"] == result.max_barrel_displacement
        assert row["end_time"] == result.end_time < 4.0


# ================================================================================================ Dask
@pytest.fixture(scope="module")
def dask_cluster():
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        yield cluster


def test_dask_equals_serial(dask_cluster):
    serial = run_sweep(model_ii(), FIG_GRID, end_time=1.0, workers=1, progress=False)
    on_cluster = run_sweep(model_ii(), FIG_GRID, end_time=1.0, scheduler=dask_cluster.scheduler_address,
                           progress=False)
    pd.testing.assert_frame_equal(_values(serial), _values(on_cluster))


def _gone(pid: int, within: float = 10.0) -> bool:
    """The process has ended (a zombie not yet reaped counts as ended)."""
    import time

    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        try:
            with open(f"/proc/{pid}/stat") as handle:
                if handle.read().split(")")[-1].split()[0] == "Z":
                    return True
        except OSError:
            return True
        time.sleep(0.1)
    return False


def test_a_dask_worker_killed_mid_sweep_loses_no_point(dask_cluster, tmp_path):
    from dask.distributed import Client

    grid = {"absorber.mass": [100.0, 1000.0], "contact.gap": [0.0, 0.02, 0.04, 0.06, 0.08, 0.1]}
    serial = run_sweep(model_ii(), grid, end_time=1.0, workers=1, progress=False)
    with Client(dask_cluster, set_as_default=False) as client:   # not the default client: named everywhere
        pids = client.run(os.getpid)   # worker address -> pid
        killed = []

        def kill_a_busy_worker(done, total):
            if killed:
                return
            # after a point: kill a worker that holds tasks of the sweep (or try again after the next point)
            busy = [(address, keys) for address, keys in client.processing().items() if keys and address in pids]
            if busy:
                address, keys = busy[0]
                os.kill(pids[address], signal.SIGKILL)
                killed.append((pids[address], keys))

        table = run_sweep(model_ii(), grid, end_time=1.0, scheduler=client, batch_size=1,
                          progress=kill_a_busy_worker, out=tmp_path / "k.csv")
    (pid, lost), = killed
    assert lost and _gone(pid)   # it held tasks when it died; the scheduler ran them elsewhere
    assert table.attrs["sweep"]["run"] == 12 and (table["status"] == "ok").all()
    pd.testing.assert_frame_equal(_values(table), _values(serial))
    _assert_file_holds(tmp_path / "k.csv", serial)


def test_a_tqdm_bar_on_a_terminal_only(capsys, monkeypatch):
    grid = {"contact.gap": [0.0, 0.01]}
    run_sweep(model_i(), grid, end_time=0.2, workers=1, batch_size=1)
    assert capsys.readouterr().err == ""                      # not a terminal: no bar
    monkeypatch.setattr("sys.stderr.isatty", lambda: True)
    run_sweep(model_i(), grid, end_time=0.2, workers=1, batch_size=1)
    err = capsys.readouterr().err
    assert "sweep: 100%" in err and "2/2" in err and "point/s" in err   # the rate (and the time left) shown
    run_sweep(model_i(), grid, end_time=0.2, workers=1, progress=False)
    assert capsys.readouterr().err == ""


def test_bad_workers_are_refused_even_with_nothing_left_to_run(tmp_path):
    path = tmp_path / "s.csv"
    run_sweep(model_i(), {"contact.gap": [0.0]}, end_time=0.2, workers=1, progress=False, out=path)
    with pytest.raises(SceneError) as info:
        run_sweep(model_i(), {"contact.gap": [0.0]}, end_time=0.2, workers=0, progress=False, out=path)
    assert info.value.key == "workers"


@pytest.mark.parametrize("change", [{"end_time": 0.3}, {"accuracy": "draft"}, {"scene": model_i(500.0, 0.0)},
                                    {"stop_when_final": ("max_barrel_displacement",)}],
                         ids=["end_time", "accuracy", "scene", "stop_when_final"])
def test_a_file_computed_with_other_settings_is_not_resumed(tmp_path, change):
    path = tmp_path / "s.csv"
    arguments = {"scene": model_i(), "end_time": 0.2, "accuracy": "standard"}
    run_sweep(params={"contact.gap": [0.0]}, workers=1, progress=False, out=path, **arguments)
    assert (tmp_path / "s.csv.sweep.json").exists()
    before = path.read_text()
    with pytest.raises(SceneError) as info:
        run_sweep(params={"contact.gap": [0.0, 0.01]}, workers=1, progress=False, out=path,
                  **{**arguments, **change})
    assert info.value.key == "out" and f"another {next(iter(change))}" in info.value.message
    assert path.read_text() == before
    table = run_sweep(params={"contact.gap": [0.0, 0.01]}, workers=1, progress=False, out=path, **arguments)
    assert table.attrs["sweep"]["resumed"] == 1
