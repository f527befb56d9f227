"""Parallel sweeps (mbs_models.studies.sweep): same numbers as serial runs, failures kept per point."""

from __future__ import annotations

import pytest

from mbs_models import Conventions, SceneError, model_i, model_ii, simulate
from mbs_models.studies.sweep import gap_sweep, parallel_map, run_scenes


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


def test_bad_sweep_arguments_fail_fast():
    with pytest.raises(SceneError, match="end_time"):
        run_scenes([model_i()], end_time=-1.0)
    with pytest.raises(SceneError, match="scenes"):
        run_scenes(["not a scene"])


def test_progress_is_reported():
    calls = []
    parallel_map(abs, [-1, -2, -3], workers=1, progress=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 3), (2, 3), (3, 3)]
