"""DenseSolution: the vectorised evaluation of the DOP853 dense output equals scipy's per-step loop bit for bit."""

import numpy as np
import pytest
from scipy.integrate import OdeSolution, solve_ivp

from validation.reference.dense import DenseSolution


def _oscillator(t, y):
    return [y[1], -40.0 * y[0] - 0.3 * y[1] + np.sin(3.0 * t)]


@pytest.mark.parametrize("method", ["DOP853", "RK45", "Radau", "LSODA"])
@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_same_values_as_scipy(method, direction):
    sol = solve_ivp(_oscillator, (0.0, 3.0 * direction), [1.0, 0.0], method=method, dense_output=True,
                    rtol=1e-9, atol=1e-12).sol
    fast = DenseSolution.of(sol)
    rng = np.random.default_rng(0)
    # unsorted times, the step ends themselves (ties pick the lower step), times outside the range
    t = np.concatenate((rng.uniform(0.0, 3.0, 500) * direction, sol.ts, [-0.5 * direction, 3.5 * direction]))
    assert np.array_equal(fast(t), sol(t))
    assert np.array_equal(fast(t[:1]), sol(t[:1]))
    assert np.array_equal(fast(1.234 * direction), sol(1.234 * direction))
    assert fast(t).flags.f_contiguous == sol(t).flags.f_contiguous  # same memory layout as scipy's


def test_joined_solution():
    a = solve_ivp(_oscillator, (0.0, 1.0), [1.0, 0.0], dense_output=True, method="DOP853").sol
    b = solve_ivp(_oscillator, (1.0, 2.0), [0.5, 0.1], dense_output=True, method="DOP853").sol
    joined = OdeSolution(np.concatenate((a.ts, b.ts[1:])), a.interpolants + b.interpolants)
    t = np.linspace(0.0, 2.0, 333)
    assert np.array_equal(DenseSolution.of(joined)(t), joined(t))
