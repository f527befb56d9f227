"""Refinement of extrema and crossings between samples (mbs_models.results.peaks)."""

from __future__ import annotations

import numpy as np
import pytest

from mbs_models.results.peaks import HermiteTrajectory, refine_crossing, refine_function_maximum, refine_maximum, runs_of_true


def test_hermite_reproduces_cubics_exactly():
    t = np.array([0.0, 0.3, 1.0, 1.7])
    y = lambda x: 2 * x ** 3 - x ** 2 + 0.5 * x - 1  # noqa: E731
    dy = lambda x: 6 * x ** 2 - 2 * x + 0.5  # noqa: E731
    interp = HermiteTrajectory(t, y(t), dy(t))
    grid = np.linspace(0, 1.7, 101)
    np.testing.assert_allclose(interp(grid), y(grid), rtol=1e-13, atol=1e-13)


def test_refine_maximum_of_a_sine_sampled_coarsely():
    t = np.linspace(0.2, 3.2, 7)  # h = 0.5 s; the maximum at pi/2 lies between samples
    value, time = refine_maximum(t, np.sin(t), np.cos(t))
    assert time == pytest.approx(np.pi / 2, abs=2e-3)
    assert value == pytest.approx(1.0, abs=1e-3)
    assert value > np.sin(t).max() + 0.005  # the raw sample maximum is clearly below


def test_refine_function_maximum_of_a_narrow_pulse():
    t = np.linspace(0.0, 0.03, 4)  # samples miss the 15 ms pulse's top
    pulse = lambda x: np.where((x > 0) & (x < 0.015), np.sin(np.pi * x / 0.015), 0.0) * 1e5  # noqa: E731
    k = int(np.argmax(pulse(t)))
    value, time = refine_function_maximum(pulse, t, k)
    assert value == pytest.approx(1e5, rel=1e-9)
    assert time == pytest.approx(0.0075, abs=1e-8)


def test_a_maximum_just_after_a_segment_boundary_is_found():
    """A segmented run repeats the sample at each segment boundary (here t = 0.3 s); the largest sample is the
    first of the two, and the maximum of f = 1 - (t - 0.34)^2 lies in the interval after the boundary."""
    t = np.array([0.0, 0.1, 0.2, 0.3, 0.3, 0.4, 0.5])
    f = lambda x: 1.0 - (x - 0.34) ** 2  # noqa: E731
    k = int(np.argmax(f(t)))
    assert k == 3  # the first copy: f(0.3) = 0.9984 > f(0.4) = 0.9964
    value, time = refine_function_maximum(f, t, k)
    assert time == pytest.approx(0.34, abs=1e-8)
    assert value == pytest.approx(1.0, abs=1e-12)


def test_refine_crossing_finds_switch_time():
    switch = 0.123456789
    found = refine_crossing(lambda x: x >= switch, 0.1, 0.2)
    assert found == pytest.approx(switch, abs=1e-9)


@pytest.mark.parametrize("flags, runs", [
    ([], []), ([0, 0, 0], []), ([1, 1, 1], [(0, 2)]), ([1, 0, 0], [(0, 0)]), ([0, 0, 1], [(2, 2)]),
    ([0, 1, 1, 0, 1, 0, 0, 1, 1], [(1, 2), (4, 4), (7, 8)]),
])
def test_runs_of_true(flags, runs):
    assert runs_of_true(np.array(flags, dtype=bool)) == runs


def test_run_argmax_is_argmax_per_run():
    from mbs_models.results.peaks import run_argmax, run_bounds
    rng = np.random.default_rng(3)
    values = np.round(rng.normal(size=500), 1)  # ties within runs: the first largest
    first, last = run_bounds(values > -0.3)
    k = run_argmax(values, first, last)
    assert list(zip(first.tolist(), last.tolist())) == runs_of_true(values > -0.3)
    assert k.tolist() == [i0 + int(np.argmax(values[i0:i1 + 1])) for i0, i1 in zip(first, last)]
    assert len(run_argmax(values, first[:0], last[:0])) == 0
