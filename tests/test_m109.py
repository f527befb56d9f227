"""The check against the M109's published figures (scripts/m109_check.py): the free-recoil numbers by hand, the
designed brake's resistance and recoil."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

_SPEC = importlib.util.spec_from_file_location(
    "m109_check", Path(__file__).resolve().parents[1] / "scripts" / "m109_check.py")
m109_check = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(m109_check)


def test_the_m109_brake_for_21_inches():
    """I = m_p v_p + m_c v_gas with v_gas = 4,700 ft/s; v0 = I / M; E = M v0^2 / 2; a constant resistance over
    21 in: E / L (by hand, from the published figures in pounds, feet and inches).  The design iterates its length
    on the simulation until the recoil is 21 in (0.1 %); its resistance is E over its design length, a few per cent
    above E / L (the table stops at 95 % of the stroke: the tail recoils further)."""
    pound, foot, inch = 0.45359237, 0.3048, 0.0254
    momentum = 98 * pound * 3250 * foot + 40 * pound * 4700 * foot
    mass = 9600 * pound
    energy = momentum ** 2 / (2 * mass)
    result = m109_check.check(4700 * foot)
    assert result["momentum"] == pytest.approx(momentum, rel=1e-12)
    assert result["energy"] == pytest.approx(energy, rel=1e-12)
    assert result["implied_resistance"] == pytest.approx(energy / (21 * inch), rel=1e-12)
    assert result["recoil"] == pytest.approx(21 * inch, rel=1e-3)
    assert 1.0 < result["designed_resistance"] / result["implied_resistance"] < 1.15
