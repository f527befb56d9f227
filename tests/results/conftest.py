"""Shared by the post-processing tests."""

from __future__ import annotations

import numpy as np
import pytest


def _one_bracket_crossing(indicator, a, b, points=129, levels=4):
    """The scalar search for the first True of ``indicator`` in ``(a, b]`` as the post-processing ran it before
    issue #11 (nested grids of ``points`` per level, ``levels`` deep; the midpoint of the last bracket): the
    reference of the batched :func:`mbs_models.results.nested_grids.first_true`."""
    for _ in range(levels):
        grid = np.linspace(a, b, points)
        flags = np.asarray(indicator(grid), dtype=bool)
        flags[-1] = True
        j = int(np.argmax(flags[1:])) + 1
        a, b = grid[j - 1], grid[j]
    return float(0.5 * (a + b))


@pytest.fixture
def one_bracket_crossing():
    """:func:`_one_bracket_crossing` (the pre-issue-#11 scalar crossing search)."""
    return _one_bracket_crossing
