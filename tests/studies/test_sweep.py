"""Sweeps (mbs_models.studies.sweep): run_sweep's grids (the numbers of single runs whichever backend runs them,
resuming, failures kept per point) and the scene lists of run_scenes/gap_sweep/parallel_map."""

from __future__ import annotations

import os
import signal

import numpy as np
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


def test_a_cluster_without_workers_stops_the_sweep_saying_what_the_file_keeps(workerless_dask_cluster, tmp_path,
                                                                               capsys):
    address, out = workerless_dask_cluster.scheduler_address, tmp_path / "w.csv"
    with pytest.raises(mbs_models.ClusterError) as info:
        run_sweep(model_i(), {"contact.gap": [0.0, 0.01]}, end_time=0.2, scheduler=address, worker_timeout=1.0,
                  out=out, progress=False)
    assert str(info.value) == (f"no Dask worker has been available at {address} for 1 s (the worker timeout) after "
                               f"0 of 2 points; no row is in {out}: run the same sweep again to resume")
    assert capsys.readouterr().err == (f"dask: waiting for a worker: the scheduler {address} has none; giving up after "
                                       "1 s without one (the worker timeout)\n")
    workerless_dask_cluster.scale(1)   # the same sweep again, with a worker: every point, each once
    table = run_sweep(model_i(), {"contact.gap": [0.0, 0.01]}, end_time=0.2, scheduler=address, worker_timeout=1.0,
                      out=out, progress=False)
    pd.testing.assert_frame_equal(_values(table), _values(run_sweep(model_i(), {"contact.gap": [0.0, 0.01]},
                                                                      end_time=0.2, workers=1, progress=False)))


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


# ================================================================================================ streaming
class _Stop(Exception):
    """Ends a sweep from its progress callback (as an interrupt would)."""


def _instant_point(scene, overrides, settings=None):
    """evaluate_point without a solve: the grid, scheduling and table layers alone (a 4 ms 'solve')."""
    return {**overrides, "wall_time": 0.004, "status": "ok", "error": None}


def _stop_after(points: int):
    def progress(done, total):
        if done >= points:
            raise _Stop
    return progress


def _peak_bytes(run) -> int:
    """The peak of Python's (and numpy's) allocations while ``run()`` runs, over what was held before."""
    import tracemalloc

    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        try:
            run()
        except _Stop:
            pass
        return tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()


GRID_1E3 = {"absorber.mass": "1:1000:10", "contact.gap": "0:0.1:10", "contact.stiffness": "1e8:3e8:10"}
GRID_1E7 = {"absorber.mass": "1:1000:100", "contact.gap": "0:0.1:100", "contact.stiffness": "1e8:3e8:1000"}


def test_memory_does_not_grow_with_the_grid(tmp_path, monkeypatch):
    """Scheduling 100 points of a 10^7-point grid (then resuming it) holds no more than of a 10^3-point grid:
    nothing per point is kept but, on resume, one bit per grid index up to the largest held (10^7 / 8 bytes =
    1.25 MB at most).  A list of 10^7 indices alone would be 80 MB; the tolerance, 2.5 MB, covers the bitmap
    and the grid's 1,200 values."""
    monkeypatch.setattr(point_module, "evaluate_point", _instant_point)
    run_sweep(model_i(), {"contact.gap": [0.0, 0.01]}, workers=1, progress=False, out=tmp_path / "warm.csv")
    peaks = {}
    for name, grid in {"1e3": GRID_1E3, "1e7": GRID_1E7}.items():
        path = tmp_path / f"{name}.csv"
        for attempt in (1, 2):    # a fresh run, then one resuming its file
            peaks[name, attempt] = _peak_bytes(lambda: run_sweep(
                model_i(), grid, workers=1, out=path, large=True, table=False, progress=_stop_after(100 * attempt)))
        assert len(pd.read_csv(path)) >= 200
    assert peaks["1e7", 1] - peaks["1e3", 1] < 2_500_000, peaks
    assert peaks["1e7", 2] - peaks["1e3", 2] < 2_500_000, peaks


def test_the_points_are_made_as_the_backend_takes_them(monkeypatch):
    """The backend gets a generator of tasks, and takes them as it goes: a serial run of a 10^7-point grid
    stopped after 100 points has made ~100 points, not 10^7."""
    from mbs_models.studies import backends, grid as grid_module

    monkeypatch.setattr(point_module, "evaluate_point", _instant_point)
    made = []
    point = grid_module.Grid.point

    def counted(self, index):
        made.append(index)
        return point(self, index)

    monkeypatch.setattr(grid_module.Grid, "point", counted)
    seen = []
    run = backends.SerialBackend.run

    def recording(self, function, tasks, **kwargs):
        seen.append(tasks)
        return run(self, function, tasks, **kwargs)

    monkeypatch.setattr(backends.SerialBackend, "run", recording)
    with pytest.raises(_Stop):
        run_sweep(model_i(), GRID_1E7, workers=1, large=True, batch_size=10, progress=_stop_after(100))
    assert not isinstance(seen[-1], (list, tuple)) and iter(seen[-1]) is seen[-1]    # a generator
    assert 100 <= len(made) <= 110 and made[4:] == sorted(made[4:])    # 4 probes, then in grid order


def test_a_grid_beyond_the_limit_needs_large(tmp_path, monkeypatch):
    from mbs_models.studies import grid as grid_module
    from mbs_models.studies.grid import GridTooLarge

    path = tmp_path / "s.csv"
    with pytest.raises(GridTooLarge) as info:
        run_sweep(model_i(), {"absorber.mass": "1:1000:10000", "contact.gap": "0:0.1:10000"}, out=path)
    assert info.value.key == "large" and "100,000,000 points (10,000 x 10,000)" in str(info.value)
    assert "more than the 1,000,000" in str(info.value) and "large=True" in str(info.value)
    assert list(tmp_path.iterdir()) == []                       # nothing written
    monkeypatch.setattr(grid_module, "MAX_POINTS", 2)
    params = {"contact.gap": [0.0, 0.01, 0.02]}
    with pytest.raises(SceneError, match="3 points"):
        run_sweep(model_i(), params, end_time=0.2, workers=1, progress=False)
    table = run_sweep(model_i(), params, end_time=0.2, workers=1, progress=False, large=True)
    assert len(table) == 3 and (table["status"] == "ok").all()
    with pytest.raises(SceneError) as info:
        run_sweep(model_i(), params, large="yes")
    assert info.value.key == "large"


def test_the_announcement_counts_and_times_the_points(monkeypatch):
    """4 points spread over the grid run first; the line says their mean solve (4 ms here) times the points
    to run over the workers: 10,000 x 4 ms / 1 = 40 s."""
    monkeypatch.setattr(point_module, "evaluate_point", _instant_point)
    lines = []
    with pytest.raises(_Stop):
        run_sweep(model_i(), {"absorber.mass": "1:1000:100", "contact.gap": "0:0.1:100"}, workers=1,
                  announce=lines.append, progress=_stop_after(10))
    assert lines == ["sweep: 10,000 points (100 x 100), ~4.0 ms per point on 1 worker: about 40 s "
                     "(an estimate from the mean solve of 4 points)"]


def test_the_announcement_comes_before_the_others_run(monkeypatch):
    events = []

    def point(scene, overrides, settings=None):
        events.append("point")
        return _instant_point(scene, overrides, settings)

    monkeypatch.setattr(point_module, "evaluate_point", point)
    run_sweep(model_i(), {"contact.gap": "0:0.1:50"}, workers=1, batch_size=10,
              announce=lambda line: events.append("line"), progress=lambda done, total: events.append(done))
    assert events[:6] == ["point"] * 4 + ["line", 4]                 # the 4 timed points, the line, then the bar
    assert events[6:] == (["point"] * 10 + [14, ] + ["point"] * 10 + [24] + ["point"] * 10 + [34]
                          + ["point"] * 10 + [44] + ["point"] * 6 + [50])


def test_probes_spread_over_every_key():
    from mbs_models.studies.grid import make_grid
    from mbs_models.studies.grid_sweep import probe_indices
    from mbs_models.studies.point_set import PointSet

    grid = make_grid(model_i(), {"absorber.mass": "1:1000:40", "contact.gap": "0:0.1:25"})
    picks = probe_indices(PointSet(), grid, 4)
    positions = [divmod(i, 25) for i in picks]
    assert positions == [(5, 3), (15, 9), (25, 15), (35, 21)]    # (2j + 1) n / 8 of each key's 40 and 25 values
    held = PointSet()
    held.add(np.array(picks[:1]))
    assert probe_indices(held, grid, 4)[0] == picks[0] + 1           # the next missing point


def test_announcement_lines():
    from mbs_models.studies.grid_sweep import announcement, duration_text

    from mbs_models.studies.grid import Grid

    grid = Grid(("absorber.mass", "contact.gap"), (tuple(range(1, 10001)), tuple(range(10000))))
    line = announcement(grid, 0, 10**8, 2, 0.004, 4)
    assert line == ("sweep: 100,000,000 points (10,000 x 10,000), ~4.0 ms per point on 2 workers: about 2.3 days "
                    "(an estimate from the mean solve of 4 points)")       # 1e8 x 4 ms / 2 = 2e5 s = 2.31 days
    resumed = announcement(grid, 5000, 10**8 - 5000, 2, 0.004, 4, where="big.csv")
    assert ", 5,000 already in big.csv, ~4.0 ms" in resumed and "for the 99,995,000 to run" in resumed
    assert announcement(grid, 10**8, 0, 2, None, 0, where="big.csv").endswith("already in big.csv: nothing to run")
    assert "no time estimate: all 4 points tried failed" in announcement(grid, 0, 10**8, 2, None, 4)
    assert [duration_text(s) for s in (0.43, 42, 600, 3 * 3600, 2e5, 4e8)] == [
        "0.4 s", "42 s", "10 min", "3.0 h", "2.3 days", "12.7 years"]


def test_table_false_returns_the_summary_and_lists_the_first_failures(tmp_path, monkeypatch):
    from mbs_models.studies import grid_sweep

    monkeypatch.setattr(grid_sweep, "SUMMARY_FAILURES", 2)
    path = tmp_path / "f.csv"
    params = {"contact.law": ["hunt-crossley", "flores"], "contact.restitution": [0.3, 0.5, 0.7]}
    summary = run_sweep(model_i(), params, end_time=0.2, workers=1, progress=False, out=path, table=False)
    table = pd.read_csv(path)
    assert summary["points"] == 6 and summary["failed"] == 3 and summary["out"] == str(path)
    assert (table["status"] == "SceneError").sum() == 3 and table["contact.law"].tolist()[:3] == ["hunt-crossley"] * 3
    assert summary["failures"] == [{"contact.law": "hunt-crossley", "contact.restitution": r, "status": "SceneError",
                                    "error": table["error"][i]} for i, r in enumerate([0.3, 0.5])]
    with pytest.raises(SceneError) as info:
        run_sweep(model_i(), params, table=False)
    assert info.value.key == "table"


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_file_in_any_order_is_resumed_and_ends_in_grid_order(tmp_path, suffix):
    """A file whose rows are in finish order (shuffled here), with points missing, resumes and ends in grid order;
    the kept rows are those of the file (their wall times)."""
    path = tmp_path / f"s{suffix}"
    full = run_sweep(model_i(), FIG_GRID, end_time=0.5, workers=1, progress=False, out=path)  # and its settings
    kept = full.drop(index=[1, 4]).sample(frac=1.0, random_state=3)
    if suffix == ".csv":
        kept.to_csv(path, index=False)
    else:
        kept.to_parquet(path, index=False)
    resumed = run_sweep(model_i(), FIG_GRID, end_time=0.5, workers=2, progress=False, out=path)
    assert resumed.attrs["sweep"]["resumed"] == 4 and resumed.attrs["sweep"]["run"] == 2
    pd.testing.assert_frame_equal(_values(resumed), _values(full))
    assert resumed["wall_time"][[0, 2, 3, 5]].tolist() == full["wall_time"][[0, 2, 3, 5]].tolist()
    written = pd.read_csv(path) if suffix == ".csv" else pd.read_parquet(path)
    assert written[["absorber.mass", "contact.gap"]].values.tolist() == full[["absorber.mass", "contact.gap"]].values.tolist()
    assert [p.name for p in tmp_path.iterdir() if not p.name.endswith(".sweep.json")] == [path.name]


def test_a_parquet_table_journals_its_rows_until_the_end(tmp_path, monkeypatch):
    """Parquet cannot be appended to: rows go to FILE.parquet.rows.csv, which a killed run leaves behind, the
    next run resumes from, and the end folds into the table."""
    path = tmp_path / "s.parquet"
    journal = tmp_path / "s.parquet.rows.csv"
    uninterrupted = run_sweep(model_ii(), FIG_GRID, end_time=0.5, workers=1, progress=False)
    seen = []

    def look(done, total):
        seen.append(journal.exists() and not path.exists())
        if done == 4:
            raise SystemExit   # not an Exception: as a kill, nothing is folded in (only a KeyboardInterrupt is)

    monkeypatch.setattr("mbs_models.studies.grid_sweep._FileSink.abandon", lambda self: None)
    with pytest.raises(SystemExit):
        run_sweep(model_ii(), FIG_GRID, end_time=0.5, workers=1, batch_size=1, progress=look, out=path)
    assert all(seen) and len(pd.read_csv(journal)) == 4
    monkeypatch.undo()
    resumed = run_sweep(model_ii(), FIG_GRID, end_time=0.5, workers=1, progress=False, out=path)
    assert resumed.attrs["sweep"]["resumed"] == 4 and not journal.exists()
    pd.testing.assert_frame_equal(_values(resumed), _values(uninterrupted))
    pd.testing.assert_frame_equal(_values(pd.read_parquet(path).astype(object).where(lambda t: t.notna(), None)),
                                  _values(uninterrupted.astype(object).where(uninterrupted.notna(), None)))


# ================================================================================================ faults
def _failing_at(scene, settings, real=point_module.simulate_scene):
    """simulate_scene, but at gap 10 mm an OverflowError (an extreme value), 20 mm a MemoryError, 30 mm a
    RecursionError; at 40 mm a result whose max barrel displacement is NaN."""
    gap = scene.absorbers[0].contact.gap
    errors = {0.01: OverflowError(34, "Numerical result out of range"), 0.02: MemoryError(),
              0.03: RecursionError("maximum recursion depth exceeded")}
    if gap in errors:
        raise errors[gap]
    result = real(scene, settings)
    if gap == 0.04:
        object.__setattr__(result, "max_barrel_displacement", float("nan")) if hasattr(result, "__dataclass_fields__") \
            else setattr(result, "max_barrel_displacement", float("nan"))
    return result


FAULT_GAPS = {"contact.gap": [0.0, 0.01, 0.02, 0.03, 0.04, 0.05]}
FAULT_STATUS = ["ok", "OverflowError", "MemoryError", "RecursionError", "SimulationError", "ok"]


def _check_fault_table(table):
    assert table["status"].tolist() == FAULT_STATUS
    assert table["error"][1] == "(34, 'Numerical result out of range')" and table["error"][2] == "MemoryError"
    assert table["error"][4] == "max_barrel_displacement: the result's value is nan, not a finite number"
    assert table.loc[1:4, "max_barrel_displacement"].isna().all() and table.loc[1:4, "steps"].isna().all()
    for i in (0, 5):
        expected = simulate(model_i(1000.0, FAULT_GAPS["contact.gap"][i]), 0.2, "draft")
        assert table["max_barrel_displacement"][i] == expected.max_barrel_displacement
    assert table.attrs["sweep"]["failed"] == 4


@pytest.mark.parametrize("workers", [1, 2], ids=["serial", "processes"])
def test_any_exception_of_a_point_is_its_row_and_the_sweep_goes_on(tmp_path, monkeypatch, workers):
    """Whatever a point raises -- not only SceneError and SimulationError -- is its row (status the class,
    error one line), a NaN metric a SimulationError; the others run; the file resumes without running any again."""
    monkeypatch.setattr(point_module, "simulate_scene", _failing_at)   # before the pool forks: its workers too
    path = tmp_path / "f.csv"
    table = run_sweep(model_i(), FAULT_GAPS, end_time=0.2, accuracy="draft", workers=workers, batch_size=2,
                      progress=False, out=path)
    _check_fault_table(table)
    again = run_sweep(model_i(), FAULT_GAPS, end_time=0.2, accuracy="draft", workers=workers, progress=False,
                      out=path)
    assert again.attrs["sweep"]["run"] == 0 and again["status"].tolist() == FAULT_STATUS


def test_any_exception_of_a_point_is_its_row_on_dask(dask_cluster):
    from dask.distributed import Client

    def patch_workers():   # run on each worker (pickled by value)
        from mbs_models.studies import point

        point._real_simulate_scene = getattr(point, "_real_simulate_scene", point.simulate_scene)

        def failing(scene, settings):
            gap = scene.absorbers[0].contact.gap
            errors = {0.01: OverflowError(34, "Numerical result out of range"), 0.02: MemoryError(),
                      0.03: RecursionError("maximum recursion depth exceeded")}
            if gap in errors:
                raise errors[gap]
            result = point._real_simulate_scene(scene, settings)
            if gap == 0.04:
                object.__setattr__(result, "max_barrel_displacement", float("nan"))
            return result
        point.simulate_scene = failing

    def restore_workers():
        from mbs_models.studies import point

        point.simulate_scene = getattr(point, "_real_simulate_scene", point.simulate_scene)

    with Client(dask_cluster, set_as_default=False) as client:
        client.run(patch_workers)
        try:
            table = run_sweep(model_i(), FAULT_GAPS, end_time=0.2, accuracy="draft", scheduler=client, batch_size=2,
                              progress=False)
        finally:
            client.run(restore_workers)
    _check_fault_table(table)


def _killed_at_gap(scene, settings, real=point_module.simulate_scene):
    if scene.absorbers[0].contact.gap == 0.02:
        os.kill(os.getpid(), signal.SIGKILL)   # as the out-of-memory killer, or a crash in compiled code
    return real(scene, settings)


def test_a_point_that_kills_its_worker_is_a_row_and_the_sweep_goes_on(tmp_path, monkeypatch):
    monkeypatch.setattr(point_module, "simulate_scene", _killed_at_gap)
    grid = {"contact.gap": [0.0, 0.01, 0.02, 0.03, 0.04, 0.05]}
    path = tmp_path / "k.csv"
    table = run_sweep(model_i(), grid, end_time=0.2, accuracy="draft", workers=2, batch_size=3, progress=False,
                      out=path)
    assert table["status"].tolist() == ["ok", "ok", "WorkerDied", "ok", "ok", "ok"]
    assert table["error"][2].startswith("its worker process died of SIGKILL")
    for i, gap in enumerate(grid["contact.gap"]):
        if i != 2:
            assert table["max_barrel_displacement"][i] == simulate(model_i(1000.0, gap), 0.2, "draft").max_barrel_displacement
    assert run_sweep(model_i(), grid, end_time=0.2, accuracy="draft", workers=2, progress=False,
                     out=path).attrs["sweep"]["run"] == 0


def _lines(path) -> list[bytes]:
    return path.read_bytes().splitlines(keepends=True)


def test_unreadable_rows_are_dropped_named_and_run_again(tmp_path, monkeypatch):
    """A torn row ended by a newline, a second header and a cell that is no number: one line names them, their
    points run again, and the file ends as the uninterrupted one (the bad lines gone)."""
    import fake_points

    fake_points.patch(monkeypatch)
    grid = {"absorber.mass": [100.0, 1000.0], "contact.gap": [0.0, 0.005, 0.01, 0.02]}
    path = tmp_path / "s.csv"
    full = run_sweep(model_i(), grid, workers=1, progress=False, out=path)
    lines = _lines(path)
    assert len(lines) == 9 and lines[2].endswith(b',SimulationError,"made to fail at gap 0.005, mass 100.0"\n')
    torn = lines[8][:lines[8].index(b",end_time,") + 4] + b"\n"          # steps cut short, no status: the last row
    garbled = lines[4].replace(b"100.0,0.02,", b"100.0,0.02,n/a")                 # a metric that is no number
    path.write_bytes(b"".join(lines[:3] + [lines[0]] + lines[3:5] + [garbled] + lines[5:8] + [torn]))
    said = []
    resumed = run_sweep(model_i(), grid, workers=1, progress=False, out=path, announce=said.append)
    assert said[0] == f"{path}: 3 rows unreadable (line 4, 7, 11): their points run again"
    assert resumed.attrs["sweep"]["resumed"] == 7 and resumed.attrs["sweep"]["run"] == 1
    assert resumed.attrs["sweep"]["unreadable"] == 3
    pd.testing.assert_frame_equal(_values(resumed), _values(full))
    assert [line for line in _lines(path) if line != lines[8]] == lines[:8]   # only the torn point's row rewritten
    with pytest.warns(UserWarning, match="1 row unreadable"):     # no announcement: a warning
        path.write_bytes(path.read_bytes() + torn)
        run_sweep(model_i(), grid, workers=1, progress=False, out=path)


def test_rows_without_their_settings_are_refused(tmp_path):
    """Without FILE.sweep.json the settings of the rows are unknown: a run (with other settings, here) is refused,
    saying how to go on, and nothing is changed."""
    path = tmp_path / "s.csv"
    run_sweep(model_i(), {"contact.gap": [0.0]}, end_time=0.2, workers=1, progress=False, out=path)
    (tmp_path / "s.csv.sweep.json").unlink()
    before = path.read_bytes()
    with pytest.raises(SceneError) as info:
        run_sweep(model_i(), {"contact.gap": [0.0, 0.01]}, end_time=0.3, workers=1, progress=False, out=path)
    assert info.value.key == "out" and info.value.message == (
        f"{path} holds rows but not s.csv.sweep.json, the record of what they were computed with (scene, end time, "
        "accuracy): restore s.csv.sweep.json, or delete s.csv to start again")
    assert path.read_bytes() == before and not (tmp_path / "s.csv.sweep.json").exists()


@pytest.mark.parametrize("text, needle", [("[]", "holds a JSON list, not the object a sweep writes"),
                                          ('"scene"', "holds a JSON str, not the object"),
                                          ("null", "holds a JSON NoneType"),
                                          ('{"end_time": 0.2', "cannot read"),
                                          (b"\xff\xfe", "cannot read")])
def test_a_malformed_settings_file_is_one_line(tmp_path, text, needle):
    path = tmp_path / "s.csv"
    run_sweep(model_i(), {"contact.gap": [0.0]}, end_time=0.2, workers=1, progress=False, out=path)
    settings = tmp_path / "s.csv.sweep.json"
    settings.write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(SceneError) as info:
        run_sweep(model_i(), {"contact.gap": [0.0]}, end_time=0.2, workers=1, progress=False, out=path)
    assert info.value.key == "out" and needle in info.value.message and "\n" not in str(info.value)


def _full_after(batches: int, monkeypatch):
    """SweepFile writes fill the disk at the ``batches + 1``-th batch: half its text written, then ENOSPC."""
    import errno

    from mbs_models.studies.sweep_table import SweepFile

    calls = []
    real = SweepFile._write

    def write(handle, text):
        calls.append(text)
        if len(calls) > batches:
            real(handle, text[:len(text) // 2])
            raise OSError(errno.ENOSPC, "No space left on device")
        real(handle, text)

    monkeypatch.setattr(SweepFile, "_write", staticmethod(write))
    return calls


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_full_disk_stops_the_sweep_keeping_every_row_written(tmp_path, monkeypatch, suffix):
    import fake_points

    from mbs_models.studies.sweep_table import SweepWriteError

    fake_points.patch(monkeypatch)
    grid = {"absorber.mass": [100.0, 1000.0], "contact.gap": "0:0.1:10"}
    uninterrupted = run_sweep(model_i(), grid, workers=1, progress=False)
    path = tmp_path / f"s{suffix}"
    writes = _full_after(3, monkeypatch)   # the 2 probes' rows and a batch of 4; then half a batch
    with pytest.raises(SweepWriteError) as info:
        run_sweep(model_i(), grid, workers=1, batch_size=4, progress=False, out=path)
    half = writes[3][:len(writes[3]) // 2]
    assert len(writes) == 4 and 1 <= half.count("\n") < 4 and not half.endswith("\n")   # rows, and one cut short
    written = path.with_name(path.name + ".rows.csv") if suffix == ".parquet" else path
    assert str(info.value) == (f"cannot write {written}: No space left on device; every row written before is kept: "
                               "make room and run the same sweep again to resume")
    monkeypatch.undo()
    fake_points.patch(monkeypatch)
    resumed = run_sweep(model_i(), grid, workers=1, progress=False, out=path)
    assert resumed.attrs["sweep"]["resumed"] == 2 + 4 + half.count("\n")   # every complete row written
    pd.testing.assert_frame_equal(_values(resumed), _values(uninterrupted))


def test_temporary_files_a_killed_run_left_are_removed(tmp_path):
    path = tmp_path / "s.csv"
    left = [".s.csv.ab12cd_9.tmp", ".s.csv.sort-x1y2z3w4.tmp", ".s.csv.sweep.json.qwertyui.tmp"]
    kept = ["s.csv.notes.tmp", ".s.csv.tmp", ".s.csv.x.csv.abcdefgh.tmp", ".other.csv.abcdefgh.tmp"]
    for name in left + kept:
        (tmp_path / name).write_text("x")
    run_sweep(model_i(), {"contact.gap": [0.0]}, end_time=0.2, workers=1, progress=False, out=path)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(kept + ["s.csv", "s.csv.sweep.json"])


def test_a_last_point_that_kills_its_worker_runs_in_a_worker_too(tmp_path, monkeypatch):
    """One point left (a resumed sweep's last, here the only one): with workers=2 it still runs in a worker
    process -- a pool of one -- so that its crash is a row, not the end of the sweep for good."""
    monkeypatch.setattr(point_module, "simulate_scene", _killed_at_gap)
    table = run_sweep(model_i(), {"contact.gap": [0.02]}, end_time=0.2, accuracy="draft", workers=2, progress=False,
                      out=tmp_path / "one.csv")
    assert table["status"].tolist() == ["WorkerDied"]
