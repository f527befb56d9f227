"""Parallel sweeps (mbs_models.studies.sweep): same numbers as serial runs, failures kept per point."""

from __future__ import annotations

import pytest

from mbs_models import Conventions, SceneError, model_i, model_ii, simulate
from mbs_models.studies.sweep import (InlineExecutor, gap_sweep, parallel_map, process_pool, run_sweep, run_sweep_jobs,
                                      sweep_jobs)


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
    points = run_sweep(scenes, end_time=0.5, workers=1)
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
def test_sweep_jobs_in_chunks_on_a_shared_pool_equal_run_sweep(workers):
    """A sweep cut into chunks and run on a pool beside other jobs gives run_sweep's points, in order."""
    scenes = [model_i(500.0, gap) for gap in (0.0, 0.02, 0.05)]
    jobs = sweep_jobs(scenes, 2.0, stop_when_final=("max_barrel_displacement",))
    with process_pool(workers) as pool:
        assert isinstance(pool, InlineExecutor) == (workers == 1)
        other = pool.submit(abs, -3)
        chunks = [pool.submit(run_sweep_jobs, jobs[i:i + 2]) for i in range(0, len(jobs), 2)]
        points = [p for chunk in chunks for p in chunk.result()]
        assert other.result() == 3
    expected = run_sweep(scenes, 2.0, workers=1, stop_when_final=("max_barrel_displacement",))
    assert [p.max_barrel_displacement for p in points] == [p.max_barrel_displacement for p in expected]
    assert [p.gap for p in points] == [0.0, 0.02, 0.05]


def test_inline_executor_hands_errors_over_through_the_future():
    future = InlineExecutor().submit(int, "not a number")
    with pytest.raises(ValueError):
        future.result()


def test_bad_sweep_arguments_fail_fast():
    with pytest.raises(SceneError, match="end_time"):
        run_sweep([model_i()], end_time=-1.0)
    with pytest.raises(SceneError, match="scenes"):
        run_sweep(["not a scene"])
    with pytest.raises(SceneError, match="end_time"):
        sweep_jobs([model_i()], end_time=0.0)


def test_progress_is_reported():
    calls = []
    parallel_map(abs, [-1, -2, -3], workers=1, progress=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 3), (2, 3), (3, 3)]
