"""The quasi-static front load's closed form against hand numbers."""

from __future__ import annotations

import math

import pytest

from validation.reference.planar import quasi_static_front_load


def test_at_rest_it_is_the_lever_rule():
    """The barrel held in battery at 30 degrees (R = M g sin theta holds its weight): N_f = g m_tot x_cg / x_f."""
    theta = math.radians(30.0)
    # carriage 2000 kg at x = 2.4; barrel 1000 kg at the trunnion (2.5, 1.0) + 0.5 m along the axis
    barrel_x = 2.5 + 0.5 * math.cos(theta)
    expected = 9.81 * (2000.0 * 2.4 + 1000.0 * barrel_x) / 2.8
    value = quasi_static_front_load(2000.0, 2.4, (2.5, 1.0), 0.5, theta, 9.81, [1000.0], [0.0],
                                    1000.0 * 9.81 * math.sin(theta), 2.8)
    assert value == pytest.approx(expected, rel=1e-14)


def test_design_mds_form_for_the_barrel_alone():
    """[g (m_tot d - M x_M cos th) - (R - M g sin th) h] / x_f with h = y_t cos th - x_t sin th, by hand."""
    theta, g, x_M, R = math.radians(20.0), 9.81, 0.3, 5.0e4
    h = 1.0 * math.cos(theta) - 2.5 * math.sin(theta)
    m_tot_d = 2000.0 * 2.4 + 1000.0 * 2.5
    expected = (g * (m_tot_d - 1000.0 * x_M * math.cos(theta)) - (R - 1000.0 * g * math.sin(theta)) * h) / 2.8
    value = quasi_static_front_load(2000.0, 2.4, (2.5, 1.0), 0.0, theta, g, [1000.0], [x_M], R, 2.8)
    assert value == pytest.approx(expected, rel=1e-14)


def test_an_absorber_counts_with_its_own_mass_and_position():
    """A 150 kg absorber at x = 0.2 adds its weight moment at its own place: 150 g (x_t - 0.2 cos th) more, and
    its weight along the axis to what R need not hold."""
    theta, g, R = math.radians(20.0), 9.81, 5.0e4
    h = 1.0 * math.cos(theta) - 2.5 * math.sin(theta)
    alone = quasi_static_front_load(2000.0, 2.4, (2.5, 1.0), 0.0, theta, g, [1000.0], [0.3], R, 2.8)
    both = quasi_static_front_load(2000.0, 2.4, (2.5, 1.0), 0.0, theta, g, [1000.0, 150.0], [0.3, 0.2], R, 2.8)
    extra = (g * 150.0 * (2.5 - 0.2 * math.cos(theta)) + 150.0 * g * math.sin(theta) * h) / 2.8
    assert both - alone == pytest.approx(extra, rel=1e-12)
