"""The base of the scene tables (``mbs_models/elements/table.py``): numbers, and quantities derived from them that
double precision must hold (DESIGN.md, "Bad input beyond the ranges")."""

from __future__ import annotations

import math
import sys

import pytest

from mbs_models import SceneError
from mbs_models.elements.table import Rule, check_derived, check_number, culprit, ieee_power


@pytest.mark.parametrize("value", [10 ** 400, -10 ** 400, 2 ** 1024])
def test_an_integer_beyond_the_largest_double_is_not_a_finite_number(value):
    """float() of it would raise OverflowError: refused in one line with the range instead."""
    with pytest.raises(SceneError) as info:
        check_number("barrel.mass", value, Rule(0.0, strict=True, unit="kg"))
    assert info.value.key == "barrel.mass" and "beyond the largest double" in info.value.message
    assert "> 0 kg" in info.value.message and "\n" not in str(info.value)


def test_the_largest_integer_a_double_holds_is_a_number():
    assert check_number("k", 2 ** 1023, Rule(0.0)) == 2.0 ** 1023


def test_the_culprit_is_the_value_farthest_from_one():
    assert culprit({"a": 1e300, "b": 1e-10, "c": 5.0}) == "a"
    assert culprit({"a": 1e300, "b": 1e-301}) == "b"
    assert culprit({"a": 1e300, "b": 0.0}) == "b"  # 0 is the farthest
    assert culprit({"a": -1e-5, "b": 1e3}) == "a"   # |log 1e-5| > |log 1e3|


def test_a_representable_derived_quantity_passes_through():
    assert check_derived({"a": 2.0}, "twice", 4.0) == 4.0
    assert check_derived({"a": 2.0}, "a difference", -3.0) == -3.0
    assert check_derived({"a": 5e-324}, "the least", 5e-324, positive=True) == 5e-324


@pytest.mark.parametrize("value, positive, allowed", [(math.inf, False, "finite"), (-math.inf, False, "finite"),
                                                      (math.nan, False, "finite"), (0.0, True, "finite and > 0"),
                                                      (math.inf, True, "finite and > 0")])
def test_a_derived_quantity_beyond_double_precision_names_the_culprit_and_every_key(value, positive, allowed):
    with pytest.raises(SceneError) as info:
        check_derived({"t.a": 1e300, "t.b": 3.0}, "the product a b", value, "N", positive=positive)
    assert info.value.key == "t.a" and "\n" not in str(info.value)
    message = info.value.message
    assert message.startswith(f"the product a b = {value:g} N is beyond double precision: it must be {allowed}")
    assert "t.a = 1e+300, t.b = 3" in message and f"{sys.float_info.max:.4g}" in message


def test_ieee_power_overflows_to_inf_and_is_python_s_power_otherwise():
    assert ieee_power(1e200, 2.0) == math.inf     # Python's 1e200 ** 2 raises OverflowError
    assert ieee_power(2.0, 0.5) == 2.0 ** 0.5 and ieee_power(0.3, 1.3) == 0.3 ** 1.3
    assert ieee_power(1e-200, 2.0) == 0.0 and ieee_power(0.0, 1.3) == 0.0
