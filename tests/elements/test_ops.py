"""The backend ops: every backend evaluates the same law to the same number."""

import exudyn
import numpy as np
import pytest

from mbs_models.elements.ops import NUMPY_OPS, PYTHON_OPS, LinearPieces, piecewise_linear, symbolic_ops

PULSE = [(0.0, 0.0), (0.002, 2.0e6), (0.006, 6.0e5), (0.012, 0.0)]


def _symbolic(function, x):
    return function(exudyn.symbolic.Real(float(x)), symbolic_ops()).Evaluate()


@pytest.mark.parametrize("points", [PULSE, [(0.0, 3e-4), (0.3, 1e-4), (0.5, 0.5e-4)], [(0.1, 7.0), (0.2, 7.0)]])
def test_piecewise_linear_agrees_with_numpy_interp_on_every_backend(points):
    xs = np.linspace(points[0][0] - 0.05, points[-1][0] + 0.05, 57)
    expected = np.interp(xs, [p[0] for p in points], [p[1] for p in points])
    assert np.array_equal(piecewise_linear(xs, points, NUMPY_OPS), expected)
    python = [piecewise_linear(float(x), points, PYTHON_OPS) for x in xs]
    symbolic = [_symbolic(lambda v, ops: piecewise_linear(v, points, ops), x) for x in xs]
    assert np.allclose(python, expected, rtol=1e-14, atol=1e-9 * max(abs(p[1]) for p in points))
    assert np.allclose(symbolic, expected, rtol=1e-14, atol=1e-9 * max(abs(p[1]) for p in points))


def test_piecewise_linear_hits_the_table_points_exactly():
    for x, y in PULSE:
        assert piecewise_linear(x, PULSE, PYTHON_OPS) == y


@pytest.mark.parametrize("name", ["absolute", "tanh", "log"])
def test_unary_ops_agree(name):
    values = [0.3, 1.7, 2.5]
    for x in values:
        python = getattr(PYTHON_OPS, name)(x)
        assert getattr(NUMPY_OPS, name)(np.array([x]))[0] == pytest.approx(python, rel=1e-15)
        assert _symbolic(lambda v, ops: getattr(ops, name)(v), x) == pytest.approx(python, rel=1e-15)
    assert PYTHON_OPS.absolute(-2.0) == 2.0 and _symbolic(lambda v, ops: ops.absolute(v), -2.0) == 2.0


def test_piecewise_linear_with_a_jump_is_right_continuous_on_every_backend():
    points = [(0.0, 0.0), (0.0, 5.0), (1.0, 3.0), (1.0, 0.0)]  # jumps up at 0 and down at 1
    for x, expected in ((-0.5, 0.0), (0.0, 5.0), (0.5, 4.0), (0.999, 3.002), (1.0, 0.0), (2.0, 0.0)):
        assert piecewise_linear(x, points, PYTHON_OPS) == pytest.approx(expected, abs=1e-12)
        assert piecewise_linear(np.array([x]), points, NUMPY_OPS)[0] == pytest.approx(expected, abs=1e-12)
        assert _symbolic(lambda v, ops: piecewise_linear(v, points, ops), x) == pytest.approx(expected, abs=1e-12)


def test_linear_pieces_are_the_pieces_of_piecewise_linear():
    """A solver integrating the piece that holds a segment's start (:class:`LinearPieces`) gets the function's
    value inside the piece and, at the piece's end, its left limit: 3 at x = 1 where the function jumps to 0."""
    points = [(0.0, 0.0), (0.0, 5.0), (1.0, 3.0), (1.0, 0.0)]  # 5 - 2 x on [0, 1), 0 elsewhere
    pieces = LinearPieces(points)
    assert pieces.at(-0.5) == (0.0, 0.0, 0.0) and pieces.at(1.0) == (1.0, 0.0, 0.0) and pieces.at(3.0) == (1.0, 0.0, 0.0)
    assert pieces.at(0.0) == pieces.at(0.7) == (0.0, 5.0, -2.0)
    start, value, slope = pieces.at(0.25)
    assert value + slope * (1.0 - start) == 3.0  # the left limit at the jump
    for x in np.linspace(-0.5, 1.5, 41):  # inside every piece: the same float as the function
        start, value, slope = pieces.at(float(x))
        assert value + slope * (float(x) - start) == piecewise_linear(float(x), points, PYTHON_OPS), x
    for x in np.linspace(0.0, 0.012, 25):
        start, value, slope = LinearPieces(PULSE).at(float(x))
        assert value + slope * (float(x) - start) == piecewise_linear(float(x), PULSE, PYTHON_OPS), x


def test_objects_holding_symbolic_variables_copy_and_pickle_without_them():
    """A contact's onset capture with its lam as an Exudyn symbolic variable (while a solve runs) pickles with
    None in its place and every number kept: a Result keeps its solve's laws across processes."""
    import pickle

    import exudyn

    from mbs_models.elements.contact_laws import OnsetCapture
    from mbs_models.elements.ops import SymbolicVariables

    capture = OnsetCapture(chi=0.5, floor=0.01, offset=0.0)
    capture.start(-1e-3, 2.0)
    capture._variable = exudyn.symbolic.Real("lam_test_pickle", capture.lam)
    with pytest.raises(TypeError):
        pickle.dumps(capture._variable)
    back = pickle.loads(pickle.dumps(capture))
    assert isinstance(capture, SymbolicVariables) and back._variable is None and capture._variable is not None
    assert back.lam == capture.lam == 0.25 and back.history == capture.history
