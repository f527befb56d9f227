"""Shared by the engine's tests: exact comparison of two Results (``assert_results_identical``)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

#: attributes and metrics() keys; ``mechanism``: the solve's laws (not a result: a fresh object each solve, its
#: samples compared as ``samples``); ``step_ends``: a densified Result's own (None from a solve)
NOT_COMPARED = {"wall_time", "timings", "mechanism", "step_ends"}


def assert_identical(a, b, where: str = "result") -> None:
    """``a == b`` exactly, through dataclasses, dicts, lists and numpy arrays."""
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        assert type(a) is type(b), where
        for f in dataclasses.fields(a):
            if f.name not in NOT_COMPARED:
                assert_identical(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, dict):
        assert isinstance(b, dict) and list(a) == list(b), where
        for key in a:
            if key not in NOT_COMPARED:
                assert_identical(a[key], b[key], f"{where}[{key!r}]")
    elif isinstance(a, (list, tuple)):
        assert type(a) is type(b) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            assert_identical(x, y, f"{where}[{i}]")
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape, where
        assert np.array_equal(a, b), f"{where}: {np.max(np.abs(a - b))} off"
    else:
        assert type(a) is type(b) and a == b, f"{where}: {a!r} != {b!r}"


def assert_results_identical(a, b) -> None:
    assert_identical(a, b)
    for name in ("barrel_position", "absorber_position", "contact_force", "kinetic_energy_history",
                 "stored_energy_history"):
        assert_identical(getattr(a, name), getattr(b, name), name)
    assert_identical(a.energy_error(), b.energy_error(), "energy_error()")
    assert_identical(a.metrics(), b.metrics(), "metrics()")
    assert_identical(a.energy(), b.energy(), "energy()")


@pytest.fixture(name="assert_results_identical")
def results_identical_fixture():
    """``assert_results_identical(a, b)``: ``==`` on every array and metric of two Results (only the wall time
    and its split may differ)."""
    return assert_results_identical
