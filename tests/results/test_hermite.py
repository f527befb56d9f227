"""Hermite interpolation of several quantities at once (mbs_models.results.hermite)."""

from __future__ import annotations

import numpy as np
import pytest

from mbs_models.results import hermite as hermite_module
from mbs_models.results.hermite import HermiteStack, HermiteTrajectory, hermite


def sampled():
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(1e-4, 1e-2, 300))
    t[150] = t[149]  # a zero-length interval (a jump at a segment boundary)
    y = rng.normal(size=(3, len(t)))
    dy = rng.normal(size=(3, len(t)))
    return t, y, dy


def test_the_stack_gives_each_quantity_s_hermite_values_bit_for_bit():
    t, y, dy = sampled()
    grid = np.random.default_rng(6).uniform(t[0], t[-1], (7, 50))
    grid[0, :3] = t[[10, 149, 150]]  # at samples, on the jump
    stacked = HermiteStack(t, y, dy)(grid)
    i = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, len(t) - 2)
    for q in range(3):
        with np.errstate(invalid="ignore", divide="ignore"):
            expected = hermite(t[i], t[i + 1], y[q, i], y[q, i + 1], dy[q, i], dy[q, i + 1], grid)
        assert np.array_equal(stacked[q], expected, equal_nan=True)
        assert np.array_equal(HermiteTrajectory(t, y[q], dy[q])(grid), expected, equal_nan=True)


@pytest.mark.parametrize("at_once", [True, False], ids=["quantities at once", "one quantity at a time"])
def test_on_intervals_bit_for_bit_and_the_value_before_a_jump(at_once, monkeypatch):
    """Both ways of :meth:`HermiteStack.at_fractions` (all quantities in one pass, or in turn beyond
    AT_ONCE_ELEMENTS values) give hermite()'s values bit for bit."""
    monkeypatch.setattr(hermite_module, "AT_ONCE_ELEMENTS", 10 ** 9 if at_once else 0)
    t, y, dy = sampled()
    f = np.array([0.1, 0.5, 0.9])
    stacked = HermiteStack(t, y, dy).on_intervals(f)
    t0, t1 = t[:-1, None], t[1:, None]
    for q in range(3):
        with np.errstate(invalid="ignore", divide="ignore"):
            expected = hermite(t0, t1, y[q, :-1, None], y[q, 1:, None], dy[q, :-1, None], dy[q, 1:, None],
                               t0 + f * (t1 - t0))
        expected = np.where(t1 > t0, expected, y[q, :-1, None])
        assert np.array_equal(stacked[q], expected)
    assert np.array_equal(stacked[:, 149, :], np.repeat(y[:, 149, None], 3, axis=1))


def test_cubics_are_reproduced():
    t = np.array([0.0, 0.3, 1.0, 1.7])
    stack = HermiteStack(t, np.array([2 * t ** 3 - t, t ** 2]), np.array([6 * t ** 2 - 1, 2 * t]))
    grid = np.linspace(0, 1.7, 101)
    np.testing.assert_allclose(stack(grid), [2 * grid ** 3 - grid, grid ** 2], rtol=1e-13, atol=1e-13)


def test_the_derivative_of_a_cubic_is_exact_and_the_sampled_derivative_at_the_samples():
    """The interpolant reproduces a cubic, so its derivative is the cubic's, ``6 t^2 - 1`` and ``2 t``, written
    out; at the sample times (the interval after, the last one's end) the sampled derivatives themselves."""
    t = np.array([0.0, 0.3, 1.0, 1.7])
    dy = np.array([6 * t ** 2 - 1, 2 * t])
    stack = HermiteStack(t, np.array([2 * t ** 3 - t, t ** 2]), dy)
    grid = np.linspace(0, 1.7, 101)
    np.testing.assert_allclose(stack.derivative(grid), [6 * grid ** 2 - 1, 2 * grid], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(stack.derivative(t), dy, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(stack.derivative(grid, [1]), [2 * grid], rtol=1e-12, atol=1e-12)
