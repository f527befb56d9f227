"""mbs_models/results/battery.py: the return to battery on sampled trajectories of known crossing."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mbs_models.results.battery import BATTERY_TOLERANCE, return_to_battery


def test_the_crossing_of_a_cosine_is_refined_between_samples():
    """x = A sin(w t) from battery (x(0) = 0), maximum A at pi / (2 w), back within 1 mm at
    t = (pi - asin(1e-3 / A)) / w.  Coarse samples (50 per period): the refinement on the
    cubic Hermite interpolant (error ~ h^4) is within 1e-6 s of it."""
    amplitude, omega = 0.2, 2.0 * math.pi
    time = np.linspace(0.0, 1.0, 51)
    x, v = amplitude * np.sin(omega * time), amplitude * omega * np.cos(omega * time)
    expected = (math.pi - math.asin(BATTERY_TOLERANCE / amplitude)) / omega
    found = return_to_battery(time, x, v, 0.25, amplitude)
    assert found == pytest.approx(expected, abs=1e-6)
    assert abs(found - expected) < 0.5 * (time[1] - time[0]) / 100   # far finer than the samples


def test_a_maximum_within_the_tolerance_is_its_own_return_and_no_return_is_none():
    time = np.linspace(0.0, 1.0, 11)
    assert return_to_battery(time, 1e-4 * time, np.full(11, 1e-4), 1.0, 1e-4) == 1.0
    assert return_to_battery(time, 0.1 * time, np.full(11, 0.1), 0.5, 0.05) is None
