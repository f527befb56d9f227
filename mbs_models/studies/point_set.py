"""The points of a grid a sweep's table already holds, as a bitmap: one bit per grid index.

A resumed sweep must run only the points its file lacks, and a grid may have 10^8 points: a Python set of
their indices would take ~6 GB.  :class:`PointSet` keeps bit ``i % 8`` of byte ``i // 8`` (little-endian
bit order) for index ``i``, over the indices up to the largest one added: ``ceil((largest + 1) / 8)``
bytes (12.5 MB for 10^8 points, nothing at all for a sweep that starts from an empty file).
:meth:`PointSet.missing` gives the indices not in the set in increasing order, a block of 2^13 at a time.
"""

from __future__ import annotations

from typing import Iterator

import numpy as np

#: Indices examined per block by :meth:`PointSet.missing` (1 kB of bitmap; its temporaries ~100 kB).
BLOCK = 1 << 13


class PointSet:
    """A set of non-negative grid indices, stored as bits (module docstring); ``count`` of them."""

    def __init__(self):
        self._bits = np.zeros(0, dtype=np.uint8)
        self.count = 0

    @property
    def nbytes(self) -> int:
        """Bytes the bitmap takes."""
        return self._bits.nbytes

    def _grow(self, largest: int) -> None:
        needed = largest // 8 + 1
        if needed > self._bits.size:
            bits = np.zeros(max(needed, 2 * self._bits.size), dtype=np.uint8)
            bits[:self._bits.size] = self._bits
            self._bits = bits

    def contains(self, indices: np.ndarray) -> np.ndarray:
        """Whether each of ``indices`` (int64, >= 0) is in the set."""
        indices = np.asarray(indices, dtype=np.int64)
        inside = indices < self._bits.size * 8
        found = np.zeros(indices.shape, dtype=bool)
        kept = indices[inside]
        found[inside] = (self._bits[kept >> 3] >> (kept & 7).astype(np.uint8)) & 1 == 1
        return found

    def add(self, indices: np.ndarray) -> np.ndarray:
        """Add ``indices`` (int64, >= 0); returns a mask of the new ones: True at the first occurrence of each
        index that was not in the set yet."""
        indices = np.asarray(indices, dtype=np.int64)
        new = np.zeros(indices.shape, dtype=bool)
        if indices.size == 0:
            return new
        if indices.min() < 0:
            raise ValueError("grid indices are >= 0")
        unique, first = np.unique(indices, return_index=True)
        fresh = ~self.contains(unique)
        new[first[fresh]] = True
        unique = unique[fresh]
        if unique.size:
            self._grow(int(unique[-1]))
            np.bitwise_or.at(self._bits, unique >> 3, np.left_shift(1, unique & 7).astype(np.uint8))
            self.count += int(unique.size)
        return new

    def missing(self, size: int, start: int = 0) -> Iterator[int]:
        """The indices in ``[start, size)`` not in the set, in increasing order (a generator; the set may grow
        while it runs: a block is read when it is reached)."""
        low = start
        while low < size:
            if low >= self._bits.size * 8:
                yield from range(low, size)
                return
            base = low // BLOCK * BLOCK
            high = min(size, base + BLOCK)
            held = np.unpackbits(self._bits[base // 8:(high + 7) // 8], bitorder="little")[:high - base]
            free = np.ones(high - base, dtype=bool)
            free[:held.size] = held == 0
            for offset in np.flatnonzero(free[low - base:]):
                yield low + int(offset)
            low = high


__all__ = ["PointSet", "BLOCK"]
