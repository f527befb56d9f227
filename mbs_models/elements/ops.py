"""The few operations a force law needs, for each backend: a law is written once and run by three.

* ``PYTHON_OPS`` -- plain floats, used by Exudyn's Python user functions (what people debug with);
* symbolic (:func:`symbolic_ops`) -- :mod:`exudyn.symbolic` expressions, recorded once and evaluated
  in C++ (the default backend of the engine);
* ``NUMPY_OPS`` -- arrays, used in post-processing (peak refinement, energies, the support force).

Because every backend runs the *same* law function, they cannot drift apart; a test checks that the
Python and symbolic user functions give the same simulation to 1e-9.  Element modules write their laws
over these ops (see :mod:`mbs_models.elements.recoil_damper` and :mod:`mbs_models.elements.contact_laws`).
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np


@dataclass(frozen=True)
class Ops:
    """The operations of one backend.

    ``maximum(a, b)``, ``power(a, x)``, ``choose(condition, value_if_true, value_if_false)`` (values are
    numbers), ``select(condition, a, b)`` (values may be expressions of the backend), ``absolute(a)``,
    ``tanh(a)``, ``log(a)``, ``sin(a)``, ``cos(a)``; ``name``: ``"python"``, ``"symbolic"`` or ``"numpy"``.
    """

    maximum: Callable[[Any, Any], Any]
    power: Callable[[Any, float], Any]
    choose: Callable[[Any, float, float], Any]
    name: str = "python"
    select: Callable[[Any, Any, Any], Any] = None
    absolute: Callable[[Any], Any] = None
    tanh: Callable[[Any], Any] = None
    log: Callable[[Any], Any] = None
    sin: Callable[[Any], Any] = None
    cos: Callable[[Any], Any] = None


def _py_choose(condition, a, b):
    return a if condition else b


PYTHON_OPS = Ops(maximum=max, power=math.pow, choose=_py_choose, name="python", select=_py_choose, absolute=abs,
                 tanh=math.tanh, log=math.log, sin=math.sin, cos=math.cos)
NUMPY_OPS = Ops(maximum=np.maximum, power=np.power, choose=np.where, name="numpy", select=np.where,
                absolute=np.abs, tanh=np.tanh, log=np.log, sin=np.sin, cos=np.cos)


def symbolic_ops() -> Ops:
    """The :mod:`exudyn.symbolic` backend (imports Exudyn)."""
    import exudyn

    esym = exudyn.symbolic

    def choose(condition, a, b):
        return esym.IfThenElse(condition, esym.Real(a), esym.Real(b))

    def select(condition, a, b):
        wrap = (lambda value: esym.Real(value) if isinstance(value, (int, float)) else value)
        return esym.IfThenElse(condition, wrap(a), wrap(b))

    return Ops(maximum=esym.max, power=esym.pow, choose=choose, name="symbolic", select=select,
               absolute=esym.abs, tanh=esym.tanh, log=esym.log, sin=esym.sin, cos=esym.cos)


def piecewise_linear(x, points, ops: Ops):
    """The piecewise-linear function through ``points`` (``[(x0, y0), (x1, y1), ...]``, x non-decreasing; a
    repeated x is a jump, right-continuous) at ``x``,
    over ``ops``; constant ``y0`` before ``x0`` and ``y_last`` after the last point (use explicit end
    points, e.g. a 0 force, where the function must vanish outside the table).

    ``y = y_i + (y_{i+1} - y_i) (x - x_i) / (x_{i+1} - x_i)`` on ``[x_i, x_{i+1}]``: a chain of selections
    (one comparison per point in the symbolic backend; ``numpy.interp`` for arrays).
    """
    if ops.name == "numpy":
        return NumpyPiecewiseLinear(points)(x)
    xs = [float(p[0]) for p in points]
    ys = [float(p[1]) for p in points]
    result = ys[-1]
    for i in range(len(xs) - 2, -1, -1):  # from the last segment back: select(x < x_{i+1}, segment_i, rest)
        if xs[i + 1] == xs[i]:
            continue  # a jump: right-continuous, the value after it is the next segment's start
        slope = (ys[i + 1] - ys[i]) / (xs[i + 1] - xs[i])
        result = ops.select(x < xs[i + 1], ys[i] + slope * (x - xs[i]), result)
    return ops.select(x < xs[0], ys[0], result)


class SymbolicVariables:
    """A mixin for the objects that hold Exudyn symbolic variables while a solve runs (``SYMBOLIC``: the names
    of those attributes): a copy or pickle holds None there, the numbers kept (a Result keeps its solve's laws
    for the forces between the samples, :mod:`mbs_models.results.dense`, and crosses process boundaries)."""

    SYMBOLIC: tuple[str, ...] = ("_variable",)

    def __getstate__(self):
        state = dict(self.__dict__)
        state.update({name: None for name in self.SYMBOLIC})
        return state


class LinearPieces:
    """The linear pieces of :func:`piecewise_linear` through ``points``, for a solver that integrates one piece
    at a time.

    :meth:`at` gives ``(start x, value, slope)`` of the piece :func:`piecewise_linear` selects at ``x``
    (right-continuous: at a repeated x, the piece after the jump); ``value + slope (x' - start)`` is then the
    same float as :func:`piecewise_linear` at any ``x'`` inside that piece, and the piece's own end value at its
    end (the left limit where the function jumps there).  Before the first point and after the last the
    piece is the constant ``y0`` or ``y_last`` (slope 0).
    """

    def __init__(self, points):
        xs = [float(p[0]) for p in points]
        ys = [float(p[1]) for p in points]
        self.ends: list[float] = []                        # piece i holds the x in [its start, ends[i])
        self.pieces: list[tuple[float, float, float]] = []
        for i in range(len(xs) - 1):
            if xs[i + 1] == xs[i]:
                continue  # a jump: no piece
            self.ends.append(xs[i + 1])
            self.pieces.append((xs[i], ys[i], (ys[i + 1] - ys[i]) / (xs[i + 1] - xs[i])))
        self.first_x = xs[0]
        self.before, self.after = (xs[0], ys[0], 0.0), (xs[-1], ys[-1], 0.0)

    def at(self, x: float) -> tuple[float, float, float]:
        """``(start x, value, slope)`` of the piece that holds ``x``."""
        if x < self.first_x:
            return self.before
        i = bisect.bisect_right(self.ends, x)
        return self.pieces[i] if i < len(self.pieces) else self.after


class NumpyPiecewiseLinear:
    """:func:`piecewise_linear` over numpy as a function of ``x`` alone, its table converted once (the same
    values, bit for bit): for a table evaluated many times (a breech pulse of hundreds of points)."""

    def __init__(self, points):
        self.xs = np.array([float(p[0]) for p in points])
        self.ys = np.array([float(p[1]) for p in points])
        self.without_jumps = bool(np.all(self.xs[1:] > self.xs[:-1]))

    def __call__(self, x):
        if self.without_jumps:
            return np.interp(x, self.xs, self.ys)
        return _numpy_piecewise_linear(np.asarray(x, dtype=float), self.xs, self.ys)


def _numpy_piecewise_linear(x: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """:func:`piecewise_linear` for tables with jumps (repeated x): right-continuous, as the chain of selections."""
    i = np.clip(np.searchsorted(xs, x, side="right") - 1, 0, len(xs) - 2)
    h = xs[i + 1] - xs[i]
    with np.errstate(invalid="ignore", divide="ignore"):
        inside = ys[i] + (ys[i + 1] - ys[i]) * (x - xs[i]) / h
    value = np.where(h > 0, inside, ys[i + 1])
    return np.where(x < xs[0], ys[0], np.where(x >= xs[-1], ys[-1], value))


def ops_for(backend: str) -> Ops:
    """The ops of a user-function backend: ``"symbolic"`` or ``"python"``."""
    if backend == "symbolic":
        return symbolic_ops()
    if backend == "python":
        return PYTHON_OPS
    raise ValueError(f"user_functions must be 'symbolic' or 'python', got {backend!r}")


def make_user_function(mbs, python_function, backend: str, item_index):
    """What to pass as a connector's ``springForceUserFunction``: the Python callable, or its symbolic record.

    ``python_function(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset)`` is the
    signature of ``ObjectConnectorCoordinateSpringDamper.springForceUserFunction``; ``backend`` is
    ``"python"`` or ``"symbolic"``.  The symbolic object must be kept alive as long as the system exists.
    """
    if backend == "python":
        return python_function
    from exudyn.advancedUtilities import CreateSymbolicUserFunction

    return CreateSymbolicUserFunction(mbs, python_function, "springForceUserFunction", item_index)
