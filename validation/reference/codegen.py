"""The equations of one mode, compiled into one straight-line Python function.

The integrator calls the right-hand side ~10^4-10^5 times per run: one Python call per connector (or
numpy scalar arithmetic, 5x slower still) would dominate the run.  So each connector gives its force
in a state as a few lines of source (:class:`~validation.reference.model.Equations`) and this module
joins them, for one :class:`~validation.reference.model.Mode`, into one function::

    x0, v0, x1, v1, _, _, _ = y.tolist()       # positions and velocities of the bodies
    f0 = f1 = fg = 0.0                         # forces on the bodies and on the ground
    <connector 0: sets F0 (and P0)>;  fg += F0;  f0 -= F0      # F pushes b to -x, a to +x
    ...                                        # constraints (a sliding contact) last
    return array([v0, f0 / M, v1, f1 / m, P1, P2, P3])

Kinds: ``"rhs"`` (Python floats; ``dy/dt``, inf where the arithmetic overflows, as numpy would give),
``"scalar"`` and ``"array"`` (one state on Python floats, or numpy rows: the raw forces, the
accelerations and the support force ``fg`` = S; ``omit`` leaves one connector out), ``"axis"`` and
``"axis_array"`` (the same on floats or rows for the planar model, :mod:`validation.reference.planar`: the
connectors alone -- no loads, no constraints, whose forces the planar model solves for -- returning the raw
forces, the force ``f_i`` (N) on every body, ``fg`` and the dissipated powers of the dissipating connectors).  The same source
serves all three: only ``copysign`` differs (``math`` or ``numpy``).  Constants are written with
``repr`` (exact); a callable constant (a connector's law, :meth:`Connector.equations`'s default) is called by
name.  ``source(...)`` shows the code of a mode.

A model with external loads (:class:`~validation.reference.model.Load`) adds, before the connectors
(a sliding contact's constraint force sees them), ``L_k = <the load's piece in the mode, from t>`` and
``f_i += L_k`` (nothing goes to the ground), and to ``dy/dt`` the work rates ``L_k v_i``; its
``evaluate`` takes the time as well: ``evaluate(y, t)``.  A model without loads gets exactly the code
above.
"""

from __future__ import annotations

import math

import numpy as np

def _ratio_power(numerator: float, denominator: float, exponent: float) -> float:
    """``(numerator / denominator) ** exponent`` for a positive ``denominator``, else inf (a state no physical
    motion reaches, e.g. a gas spring compressed beyond its volume: the solver rejects a trial step there,
    where Python's power of a negative ratio would be a complex number)."""
    return (numerator / denominator) ** exponent if denominator > 0.0 else math.inf


def _ratio_power_array(numerator, denominator, exponent):
    """:func:`_ratio_power` elementwise."""
    denominator = np.asarray(denominator, dtype=float)
    positive = denominator > 0.0
    safe = np.where(positive, denominator, 1.0)
    return np.where(positive, (numerator / safe) ** exponent, np.inf)


_NAMESPACES = {
    "rhs": {"copysign": math.copysign, "array": np.array, "full": np.full, "inf": math.inf,
            "ratio_power": _ratio_power},
    "scalar": {"copysign": math.copysign, "ratio_power": _ratio_power},
    "array": {"copysign": np.copysign, "ratio_power": _ratio_power_array},
}
_NAMESPACES["axis"], _NAMESPACES["axis_array"] = _NAMESPACES["scalar"], _NAMESPACES["array"]


def _point(model, body) -> tuple[str, str, str]:
    """(position, velocity, force accumulator) names of a connector end (the ground: 0.0, 0.0, fg)."""
    if body is None:
        return "0.0", "0.0", "fg"
    return f"x{body}", f"v{body}", f"f{body}"


def source(model, mode, kind: str, omit: int | None = None, functions: dict | None = None) -> str:
    """The Python source of ``kind`` (module docstring) for ``mode`` of ``model``; the callable constants of the
    equations (a law called as a function) are named ``<constant>_<j>`` and put into ``functions``."""
    functions = {} if functions is None else functions
    nb = model.n_bodies
    names = [n for i in range(nb) for n in (f"x{i}", f"v{i}")] + ["_"] * (model.n_states - 2 * nb)
    axis = kind.startswith("axis")
    unpack = "y" if kind in ("array", "axis_array") else "y.tolist()"
    body = [f"{', '.join(names)}, = {unpack}", " = ".join([f"f{i}" for i in range(nb)] + ["fg", "0.0"])]
    works = []
    for k, load in enumerate(() if axis else model.loads):
        i = model.body_index[load.body]
        code = load.equations(mode.loads[k]) if mode.loads else f"{{L}} = load{k}(t)"
        if code is None:
            works.append("0.0")
            continue
        body += ([f"# load {load.name}" + (f": piece {mode.loads[k]!r}" if mode.loads else "")]
                 + [line.strip() for line in code.format(L=f"L{k}").strip().splitlines()] + [f"f{i} += L{k}"])
        works.append(f"L{k} * v{i}")
    works += ["0.0"] * len(model.impulses)
    blocks, late = [], []
    forces, powers = {}, {}
    for j, (c, state) in enumerate(zip(model.connectors, mode.states)):
        equations = None if j == omit else c.equations(state)
        if equations is None or (axis and equations.constraint):
            continue
        xa, va, fa = _point(model, c.body_a)
        xb, vb, fb = _point(model, c.body_b)
        fields = {}
        for k, v in equations.constants.items():
            if callable(v):
                fields[k] = f"{k}_{j}"
                functions[fields[k]] = v
            else:
                fields[k] = repr(float(v))
        code = equations.code.format(xa=xa, xb=xb, va=va, vb=vb, fa=fa, fb=fb, F=f"F{j}", P=f"P{j}", **fields)
        lines = [f"# {c.name}: {state!r}"] + [line.strip() for line in code.strip().splitlines()]
        lines += [f"{fa} += F{j}", f"{fb} -= F{j}"]
        (late if equations.constraint else blocks).append(lines)
        forces[j] = f"F{j}"
        if c.dissipates and "{P}" in equations.code:
            powers[j] = f"P{j}"
    for lines in blocks + late:
        body += lines
    accelerations = [f"f{i} / {model.masses[i]!r}" for i in range(nb)]
    if kind == "rhs":
        derivative = [x for i in range(nb) for x in (f"v{i}", accelerations[i])]
        derivative += [powers.get(c.index, "0.0") for c in model.dissipating] + works
        body.append(f"return array([{', '.join(derivative)}])")
        inner = "\n".join("        " + line for line in body)
        return (f"def rhs(t, y):\n    try:\n{inner}\n    except OverflowError:\n"
                f"        return full({model.n_states}, inf)\n")
    all_forces = [forces.get(j, "0.0") for j in range(len(model.connectors))]
    if axis:
        body.append(f"return [{', '.join(all_forces)}], [{', '.join(f'f{i}' for i in range(nb))}], fg, "
                    f"[{', '.join(powers.get(c.index, '0.0') for c in model.dissipating)}]")
        return "def evaluate(y):\n" + "\n".join("    " + line for line in body) + "\n"
    body.append(f"return [{', '.join(all_forces)}], [{', '.join(accelerations)}], fg")
    signature = "y, t" if model.loads else "y"
    return f"def evaluate({signature}):\n" + "\n".join("    " + line for line in body) + "\n"


def compile_mode(model, mode, kind: str, omit: int | None = None):
    """The function of ``kind`` for ``mode`` (see the module docstring)."""
    namespace = dict(_NAMESPACES[kind])
    namespace.update({f"load{k}": load.force for k, load in enumerate(model.loads)})
    functions: dict = {}
    text = source(model, mode, kind, omit, functions)
    namespace.update(functions)
    exec(compile(text, f"<reference {kind} of {mode!r}>", "exec"), namespace)  # noqa: S102 - our own source
    return namespace["rhs" if kind == "rhs" else "evaluate"]
