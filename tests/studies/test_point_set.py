"""The points a sweep's file holds (mbs_models.studies.point_set): a bitmap, one bit per grid index."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from mbs_models.studies.point_set import BLOCK, PointSet


def test_add_reports_the_new_indices_once():
    points = PointSet()
    assert points.add(np.array([5, 3, 5, 9])).tolist() == [True, True, False, True]   # the second 5: a duplicate
    assert points.add(np.array([3, 4])).tolist() == [False, True]
    assert points.count == 4
    assert points.contains(np.array([3, 4, 5, 6, 9, 10, 10**9])).tolist() == [True, True, True, False, True,
                                                                              False, False]
    assert points.add(np.array([], dtype=np.int64)).tolist() == []
    with pytest.raises(ValueError):
        points.add(np.array([-1]))


def test_missing_gives_the_others_in_order_across_blocks():
    size = 3 * BLOCK + 17
    held = np.array([0, 1, 7, 8, BLOCK - 1, BLOCK, 2 * BLOCK + 5, 3 * BLOCK + 16])
    points = PointSet()
    points.add(held)
    missing = list(points.missing(size))
    assert missing == sorted(set(range(size)) - set(held.tolist()))
    assert list(points.missing(size, start=BLOCK - 2)) == [i for i in missing if i >= BLOCK - 2]


def test_missing_reads_a_block_only_when_it_gets_there():
    points = PointSet()
    points.add(np.array([3]))
    missing = points.missing(10**12)          # a huge grid: a generator, nothing made ahead
    assert list(itertools.islice(missing, 4)) == [0, 1, 2, 4]
    points.add(np.array([5]))                 # held meanwhile (within the block already read: still given)
    assert next(missing) == 5
    points.add(np.array([BLOCK + 1]))         # in a block not read yet: skipped
    assert list(itertools.islice(points.missing(BLOCK + 3, start=BLOCK), 3)) == [BLOCK, BLOCK + 2]


def test_the_bitmap_takes_one_bit_per_index_up_to_the_largest():
    points = PointSet()
    assert points.nbytes == 0                  # a sweep from an empty file keeps nothing
    points.add(np.arange(0, 8_000_000, 1000))        # the largest: 7,999,000 -> 7,999,001 bits
    assert points.nbytes == 7_999_000 // 8 + 1
    points.add(np.array([8_000_007]))                # one more byte: the bitmap doubles (at most twofold)
    assert points.nbytes == 2 * (7_999_000 // 8 + 1)
    assert points.count == 8001
