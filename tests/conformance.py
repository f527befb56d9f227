"""The element contract's checks (mbs_models.elements.connector.Connector), one function per clause.

Used by ``tests/elements/test_conformance.py`` over every connector of the shipped scenes, and by the
out-of-tree example's test on a user's connector.  Each check raises AssertionError naming the connector and
the state where the contract fails.  Expectations come from the law alone (the derived pieces are integrals,
differences and evaluations of ``law``), never from the closed form under test.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from mbs_models.elements import Connector
from mbs_models.elements.ops import NUMPY_OPS, PYTHON_OPS, symbolic_ops

#: The shipped scene files (every element and contact law has one: tests/elements/test_conformance.py checks it).
SCENE_FILES = sorted((Path(__file__).parents[1] / "mbs_models" / "scenes").glob("*.toml"))


def shipped_scenes() -> dict:
    """Every shipped scene by its file's stem."""
    from mbs_models import load_scene

    return {path.stem: load_scene(path) for path in SCENE_FILES}


def shipped_connectors(scenes: dict) -> dict:
    """Every connector of ``scenes`` as the engine builds it, keyed ``"scene:connector"``."""
    from mbs_models.engine.mechanism import Mechanism

    return {f"{key}:{c.name}": c for key, scene in scenes.items() for c in Mechanism(scene).connectors}

#: Boxes |d| <= D (m), |d'| <= V (m/s) sampled for a connector; a contact's D is its penetration bound.
BOXES = ((1e-3, 0.05), (0.05, 1.0), (0.3, 3.0))
CONTACT_BOXES = ((1e-5, 0.05), (1e-3, 1.0), (1e-2, 3.0))
#: Relative round-off allowed in the force-bound check: a bound evaluated at a box corner is the same
#: expression as the force there, up to the order of the operations (a few ulps).
BOUND_ROUNDING = 1e-12
#: Closed-form U against the quadrature of F(s, 0): scipy's quad is asked for 1e-12 relative; 1e-9 of the
#: scale |F(d, 0) d| + |U| leaves three orders for a law whose closed form is computed otherwise (expm1, log1p).
ENERGY_TOLERANCE = 1e-9
#: Closed-form tangent stiffness against the central difference of F(s, 0): its truncation error h^2 F''' / 6
#: with h = 6e-6 |d| and its round-off eps |F| / h are both ~1e-10 relative for the smooth laws; 1e-6 of
#: |k| + |F / d| leaves margin for the stiff ends of the gas spring.
STIFFNESS_TOLERANCE = 1e-6
#: Backends: the same law over math, numpy and Exudyn's symbolic C++ evaluation; power and tanh may round
#: differently in the last bits, 1e-12 of the force's scale is far above that and far below any modelling
#: difference.
BACKEND_TOLERANCE = 1e-12


def boxes(connector) -> tuple[tuple[float, float], ...]:
    """The (D, V) boxes to sample for ``connector``: D within its coordinate range (90 % of its reach)."""
    if connector.is_contact:
        return CONTACT_BOXES
    low, high = connector.coordinate_range
    reach = min(-low, high)
    return tuple((min(D, 0.9 * reach), V) for D, V in BOXES)


def states(connector, box, count: int = 64, seed: int = 0) -> list[tuple[float, float]]:
    """``(d, d')`` in the box: its corners, its edges' midpoints and random points (a contact's d is offset +
    p with p in [-D, D])."""
    D, V = box
    rng = np.random.default_rng(seed)
    unit = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0), (0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0),
            (0.0, 0.0)] + [tuple(rng.uniform(-1.0, 1.0, 2)) for _ in range(count)]
    offset = connector.offset if connector.is_contact else 0.0
    return [(offset + u * D, w * V) for u, w in unit]


def check_force_bound(connector, box) -> None:
    """``force_bound(D, V) >= |F(d, d')|`` at every sampled state of the box."""
    D, V = box
    bound = connector.force_bound(D, V, math.inf)
    for d, rate in states(connector, box):
        force = connector.python_force(d, rate)
        assert abs(force) <= bound * (1.0 + BOUND_ROUNDING), (
            f"{connector!r}: force_bound({D:g} m, {V:g} m/s) = {bound:.10g} N < |F({d:.6g}, {rate:.6g})| = "
            f"{abs(force):.10g} N")


def check_potential(connector, box) -> None:
    """A connector that stores no energy has ``F(d, 0) = 0``; one that does has U (closed form, float and numpy)
    equal to ``integral_0^d F(s, 0) ds`` (scipy quadrature of the law), and a quadratic one ``U = k d^2 / 2``."""
    ds = sorted({d for d, _ in states(connector, box)})
    if not connector.stores_energy:
        for d in ds:
            assert connector.python_force(d, 0.0) == 0.0, f"{connector!r}: stores no energy but F({d:g}, 0) != 0"
        return
    numpy_energy = np.asarray(connector.stored_energy(np.array(ds)), dtype=float)
    for d, from_array in zip(ds, numpy_energy):
        derived = Connector.derived_stored_energy(connector, d)
        closed = connector.python_stored_energy(d)
        scale = abs(connector.python_force(d, 0.0) * d) + abs(derived)
        for name, value in (("python_stored_energy", closed), ("stored_energy", from_array)):
            assert abs(value - derived) <= ENERGY_TOLERANCE * scale + 1e-300, (
                f"{connector!r}: {name}({d:.6g}) = {value:.12g} J but integral_0^d F(s, 0) ds = {derived:.12g} J")
        if connector.quadratic_potential:
            k = connector.quadratic_stiffness
            assert abs(0.5 * k * d * d - derived) <= ENERGY_TOLERANCE * scale + 1e-300, (
                f"{connector!r}: a quadratic potential k d^2 / 2 with k = {k:g} N/m is {0.5 * k * d * d:.12g} J at "
                f"d = {d:.6g}, but integral_0^d F(s, 0) ds = {derived:.12g} J")


def check_tangent_stiffness(connector, box) -> None:
    """A closed-form tangent stiffness equals the central difference of ``F(s, 0)`` (away from a contact's
    kink at its offset, where it has none)."""
    if type(connector).tangent_stiffness is Connector.tangent_stiffness:
        return
    for d, _ in states(connector, box):
        h = 6e-6 * max(abs(d), 1e-3)
        if connector.is_contact and abs(d - connector.offset) <= 2 * h:
            continue
        closed = connector.tangent_stiffness(d)
        derived = Connector.derived_tangent_stiffness(connector, d)
        scale = abs(derived) + abs(connector.python_force(d, 0.0)) / max(abs(d), 1e-3)
        assert abs(closed - derived) <= STIFFNESS_TOLERANCE * scale, (
            f"{connector!r}: tangent_stiffness({d:.6g}) = {closed:.10g} N/m, dF/dd = {derived:.10g} N/m")


def symbolic_force(connector, d: float, rate: float) -> float:
    """The law over Exudyn's symbolic backend, evaluated by its C++ expression tree."""
    import exudyn

    value = connector.law(exudyn.symbolic.Real(d), exudyn.symbolic.Real(rate), symbolic_ops())
    return float(value.Evaluate()) if hasattr(value, "Evaluate") else float(value)


def check_backends(connector, box) -> None:
    """The law over Python floats, numpy arrays and Exudyn symbolic expressions gives the same force."""
    sampled = states(connector, box, count=16)
    d = np.array([s[0] for s in sampled])
    rate = np.array([s[1] for s in sampled])
    numpy_forces = np.asarray(connector.law(d, rate, NUMPY_OPS), dtype=float) * np.ones_like(d)
    scale = max(float(np.max(np.abs(numpy_forces))), 1e-300)
    for (di, ri), from_numpy in zip(sampled, numpy_forces):
        python = connector.law(di, ri, PYTHON_OPS)
        symbolic = symbolic_force(connector, di, ri)
        for name, value in (("numpy", from_numpy), ("symbolic", symbolic)):
            assert abs(value - python) <= BACKEND_TOLERANCE * scale, (
                f"{connector!r}: F({di:.6g}, {ri:.6g}) = {python!r} N in Python, {value!r} N over {name}")


def check_item_offset(connector, box) -> None:
    """A connector whose Exudyn item holds its offset (``offset_in_item``): its user function given another offset
    o is, bit for bit, the law of the same connector with offset o -- over Python floats and Exudyn symbolic
    expressions, at the sampled states moved with the offset (so that the penetrations stay those of the box)."""
    if not connector.offset_in_item:
        return
    import copy

    import exudyn

    real = exudyn.symbolic.Real
    mine = copy.deepcopy(connector)  # (recording a capture's law gives the capture a variable: not the shared one)
    python_function, symbolic_function = mine.user_function_law(PYTHON_OPS), mine.user_function_law(symbolic_ops())
    for shift in (-0.013, 0.007):
        other = copy.deepcopy(connector)
        other.offset = connector.offset + shift
        for d, rate in states(connector, box, count=16):
            moved = d + shift
            expected = other.law(moved, rate, PYTHON_OPS)
            assert python_function(moved, rate, other.offset) == expected, (connector, moved, rate)
            recorded = symbolic_function(real(moved), real(rate), real(other.offset)).Evaluate()
            assert recorded == other.law(real(moved), real(rate), symbolic_ops()).Evaluate(), (connector, moved, rate)


def check_all(connector) -> None:
    """Every clause above on every box of the connector."""
    for box in boxes(connector):
        check_force_bound(connector, box)
        check_potential(connector, box)
        check_tangent_stiffness(connector, box)
        check_backends(connector, box)
        check_item_offset(connector, box)


#: The metric and the time of it that an early stop reports (names of Result fields).
TIMES = {"max_barrel_displacement": "time_of_max_barrel_displacement",
         "peak_contact_force": "time_of_peak_contact_force",
         "max_absorber_velocity": "time_of_max_absorber_velocity",
         "peak_support_force": "time_of_peak_support_force"}


#: The metrics an element's share of the energy bounds decides: its potential bounds the displacement and the
#: velocities, its force bound the force on the mount (``impacts`` and ``peak_contact_force`` wait for every
#: contact to open, which a weakly damped absorber may not do within the run).
EARLY_METRICS = ("max_barrel_displacement", "max_absorber_velocity", "peak_support_force")


def check_early_stop(scene, end_time: float = 10.0, requested=EARLY_METRICS) -> bool:
    """The metrics of a run stopped early (``requested`` proven final) equal those of the full run: bit for bit,
    since both runs take the same solver steps up to the stop.  Returns whether the run stopped early."""
    from mbs_models import simulate

    full = simulate(scene, end_time)
    early = simulate(scene, end_time, stop_when_final=requested)
    for name in early.final_metrics:
        if name == "impacts":
            assert early.impacts == full.impacts, "impacts"
            continue
        assert getattr(early, name) == getattr(full, name), (
            f"{scene.name}: early-stopped {name} = {getattr(early, name)!r}, full run {getattr(full, name)!r} "
            f"(stop reason {early.stop_reason}, at {early.end_time:g} s)")
        assert getattr(early, TIMES[name]) == getattr(full, TIMES[name]), TIMES[name]
    return early.end_time < end_time
