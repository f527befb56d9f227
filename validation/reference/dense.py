"""The reference's dense output evaluated at many times at once, bit-identical to scipy's.

``scipy.integrate.OdeSolution(t)`` with an array ``t`` calls the interpolant of every solver step
separately (one Python call and ~20 small numpy operations per step): the metrics' grids
(:mod:`validation.reference.result`), the missed-crossing scan (:mod:`validation.reference.switching`)
and the finality bounds (:mod:`validation.reference.finality`) evaluate every step, so that loop cost
as much as the integration itself.  :class:`DenseSolution` evaluates the DOP853 interpolant of all the
steps in one pass.  It performs the same floating-point operations in the same order as
``scipy.integrate._ivp.rk.Dop853DenseOutput`` (with ``x = (t - t_old) / h`` of the point's step and the
step's coefficients ``F``)::

    y = 0;  for k = K-1, ..., 0:  y += F_k;  y *= x if (K-1-k) is even else (1 - x);   y += y_old

and picks each point's step exactly as ``OdeSolution`` does, so the values are bit-identical
(tests/validation/reference/test_dense.py compares them with ``==``).  Other interpolants (RK45,
Radau, LSODA) and scalar times go through scipy unchanged.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import OdeSolution
from scipy.integrate._ivp.rk import Dop853DenseOutput

__all__ = ["DenseSolution"]


class DenseSolution(OdeSolution):
    """An :class:`~scipy.integrate.OdeSolution` whose evaluation at an array of times is vectorised over
    the solver's steps when every interpolant is DOP853's (same values as scipy's, see the module)."""

    @classmethod
    def of(cls, solution: OdeSolution) -> "DenseSolution":
        """``solution`` (as made by ``solve_ivp``) with the vectorised evaluation; shares its interpolants."""
        if isinstance(solution, cls):
            return solution
        out = cls.__new__(cls)
        out.__dict__.update(solution.__dict__)
        return out

    def _stacked(self):
        """(t_old, h, F, y_old) of every step as arrays (steps first), or None for other interpolants."""
        stacked = self.__dict__.get("_stack", False)
        if stacked is False:
            stacked = None
            if self.interpolants and all(type(i) is Dop853DenseOutput for i in self.interpolants):
                stacked = (np.array([i.t_old for i in self.interpolants], dtype=float),
                           np.array([i.h for i in self.interpolants], dtype=float),
                           np.stack([i.F for i in self.interpolants]),
                           np.stack([i.y_old for i in self.interpolants]))
            self.__dict__["_stack"] = stacked
        return stacked

    def __call__(self, t):
        t = np.asarray(t)
        stacked = self._stacked() if t.ndim == 1 else None
        if stacked is None or t.dtype.kind != "f" or len(t) == 0:
            return super().__call__(t)
        t_old, h, F, y_old = stacked
        # the step of each point, as OdeSolution.__call__ picks it (on the sorted times; the sort does
        # not change which step a point falls in)
        segments = np.searchsorted(self.ts_sorted, t, side=self.side)
        segments -= 1
        segments[segments < 0] = 0
        segments[segments > self.n_segments - 1] = self.n_segments - 1
        if not self.ascending:
            segments = self.n_segments - 1 - segments
        x = ((t - t_old[segments]) / h[segments])[:, None]
        y = np.zeros((len(t), y_old.shape[1]), dtype=y_old.dtype)
        power = F.shape[1]
        for i in range(power):
            y += F[segments, power - 1 - i]
            if i % 2 == 0:
                y *= x
            else:
                y *= 1 - x
        y += y_old[segments]
        return y.T  # the layout of scipy's result too (a transposed view)
