"""The reference's side of the element contract (validation.reference.model.Connector), on every reference term
of every shipped scene (mbs_models/scenes/*.toml).

* the law is mandatory: a connector without it cannot be made, so a term without it fails while the reference
  model is built (never a silent zero force);
* what a term gives in closed form equals what the contract derives from its law: the stored energy (the
  quadrature of F(s, 0), on floats and on arrays), the force at rest F(d, 0), no energy stored where the term
  says so (F(d, 0) = 0), none dissipated where it says so (F(d, d') = F(d, 0)), a force bound >= |F|;
* the law of a mode as compiled for the solver (``equations``) is the law, and its dissipated power is
  ``(F(d, d') - F(d, 0)) d'``;
* per element, the engine's connector and the reference's term give the same force on sampled states (d, d'):
  a law written differently on the two sides is caught here, before any solve.  This test imports both
  packages (it is a test, not validation/ code).

Expectations come from the law alone (integrals and evaluations of ``law``), never from the closed form under
test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import conformance

from mbs_models.elements.ops import PYTHON_OPS
from validation.reference import terms
from validation.reference.assembly import build_model
from validation.reference.model import BARREL, GROUND, Connector, Mode
from validation.reference.terms.contact_laws import ON, RESTITUTION_LAWS, ContactMode

SCENES = conformance.shipped_scenes()
MODELS = {key: build_model(scene) for key, scene in SCENES.items()}
TERMS = {f"{key}:{c.name}": (key, c) for key, model in MODELS.items() for c in model.connectors}

#: (D m, V m/s) boxes |d| <= D, |d'| <= V; a contact's d is its offset + p with |p| <= D.
BOXES = ((1e-3, 0.05), (0.05, 1.0), (0.3, 3.0))
CONTACT_BOXES = ((1e-5, 0.05), (1e-3, 1.0), (1e-2, 3.0))
#: Closed-form U against scipy's quad of F(s, 0) (asked for 1e-12 relative): 1e-9 of the scale |F(d, 0) d| + |U|
#: leaves three orders for closed forms computed otherwise (expm1, log1p, the tabulated spring's trapezoids).
ENERGY_TOLERANCE = 1e-9
#: The same law written twice (compiled equations and ``law``; the engine's and the reference's): the same
#: arithmetic up to the order of the operations, a few ulps of the force's scale; 1e-12 is far above that and far
#: below any difference of modelling.
FORCE_TOLERANCE = 1e-12
#: Onset rates v- (m/s) of the restitution laws' episodes compared: below the floor, typical, fast.
ONSET_RATES = (0.0, 0.3, 2.0)


def boxes(connector) -> tuple[tuple[float, float], ...]:
    if connector.is_contact:
        return CONTACT_BOXES
    return tuple((min(D, 0.9 * connector.d_limit), V) for D, V in BOXES)


def states(connector, box, count: int = 48, seed: int = 0) -> list[tuple[float, float]]:
    """(d, d') in the box: its corners, edge midpoints, the centre and random points (tests/conformance.py's)."""
    return conformance.states(connector, box, count, seed)


def close(a: float, b: float, scale: float, tolerance: float = FORCE_TOLERANCE) -> bool:
    return a == b or abs(a - b) <= tolerance * scale


def test_every_shipped_table_has_a_term_here():
    """The parametrisation covers the terms: every connector table of the shipped scenes gives a connector."""
    tables = {key.split(".")[0] for scene in SCENES.values() for key, _ in scene.tables()}
    assert {"recoil_spring", "recoil_damper", "absorber", "recoil_stop", "battery_stop", "recuperator",
            "recoil_brake", "cradle", "tabulated_spring", "tabulated_damper"} <= tables
    assert {type(c).__name__ for _, c in TERMS.values()} >= {
        "LinearSpringDamper", "RecoilDamper", "ContactConnector", "GasSpring", "RecoilBrake", "CoulombFriction",
        "TabulatedSpring", "TabulatedDamper"}


# ------------------------------------------------------------------------------------------ the law is mandatory
class _NoLaw(Connector):
    """A term's connector whose author forgot the law (it has everything else)."""

    def stored_energy(self, d):
        return 0.5 * 1e4 * d ** 2


class _LawOnly(Connector):
    """A progressive spring given by its law alone: ``F = k1 d + k3 d^3 + c d'`` (N)."""

    def __init__(self, name, a, b, k1=2e4, k3=5e6, c=300.0):
        super().__init__(name, a, b)
        self.k1, self.k3, self.c = k1, k3, c

    def law(self, d, rate, state=None):
        return self.k1 * d + self.k3 * d * d * d + self.c * rate


class _Term:
    TABLES = ("recoil_spring",)
    connector = _NoLaw

    @classmethod
    def build(cls, builder, key, table):
        builder.add_connector(cls.connector("recoil_spring", GROUND, BARREL))


def test_a_connector_without_its_law_cannot_be_made():
    with pytest.raises(TypeError, match="law"):
        _NoLaw("spring", GROUND, BARREL)


def test_a_term_missing_its_law_fails_when_the_reference_model_is_built(monkeypatch):
    monkeypatch.setitem(terms.TERMS, "recoil_spring", _Term)
    with pytest.raises(TypeError, match="law"):
        build_model(SCENES["simplified"])


def test_a_term_with_its_law_alone_gets_everything_else_from_it(monkeypatch):
    """The default equations call the law (force and dissipated power), the stored energy is its integral
    ``k1 d^2 / 2 + k3 d^4 / 4`` (closed form written here), the force at rest ``k1 d + k3 d^3``."""
    monkeypatch.setattr(_Term, "connector", _LawOnly)
    monkeypatch.setitem(terms.TERMS, "recoil_spring", _Term)
    model = build_model(SCENES["simplified"])
    spring = model.connector("recoil_spring")
    k1, k3, c = spring.k1, spring.k3, spring.c
    for d in (-0.2, -1e-3, 0.0, 0.05, 0.3):
        expected = k1 * d * d / 2 + k3 * d ** 4 / 4
        assert close(spring.stored_energy(d), expected, abs(expected) + 1e-300, 1e-12)
        assert spring.static_force(d) == pytest.approx(k1 * d + k3 * d ** 3, rel=1e-15, abs=0.0)
    d = np.linspace(-0.3, 0.3, 41)
    np.testing.assert_allclose(spring.stored_energy(d), k1 * d * d / 2 + k3 * d ** 4 / 4, rtol=1e-12, atol=1e-9)
    y = model.initial_state()
    y[0], y[1] = 0.1, -2.0
    mode = Mode(model.names, tuple(x.provisional(y.tolist() + [0.0, 0.0], None) for x in model.connectors))
    evaluation = model.evaluate(mode, y)
    assert evaluation.forces[spring.index] == pytest.approx(k1 * 0.1 + k3 * 1e-3 + c * -2.0, rel=1e-14)
    assert model.rhs(mode)(0.0, y)[spring.di] == pytest.approx(c * 4.0, rel=1e-14)
    # the derived force bound: at least the law's largest |F| on the box, k1 D + k3 D^3 + c V at its corner
    # (the law increases in d and d'), and at most that plus the largest change over one grid cell
    D, V = 0.2, 3.0
    largest = k1 * D + k3 * D ** 3 + c * V
    cell_d, cell_v = 2 * D / (spring.BOUND_SAMPLES - 1), 2 * V / (spring.BOUND_SAMPLES - 1)
    step = max(k1 * cell_d + k3 * (D ** 3 - (D - cell_d) ** 3), c * cell_v)
    assert largest * (1 - 1e-12) <= spring.force_bound(D, V, math.inf) <= (largest + step) * (1 + 1e-12)


# ------------------------------------------------------------------------------------------ closed form = derived
@pytest.mark.parametrize("key", list(TERMS))
def test_closed_form_energy_and_force_at_rest_equal_the_derived_ones(key):
    _, c = TERMS[key]
    for box in boxes(c):
        samples = states(c, box)
        d_values = np.array([d for d, _ in samples])
        for d, rate in samples:
            at_rest = c.law(d, 0.0)
            assert c.static_force(d) == pytest.approx(at_rest, rel=FORCE_TOLERANCE, abs=0.0), (key, d)
            if not c.stores_energy:
                assert at_rest == 0.0, f"{key}: stores_energy is False but F({d:g}, 0) = {at_rest:g} N"
            if not c.dissipates:
                assert c.law(d, rate) == at_rest, f"{key}: dissipates is False but F depends on d' at {d:g}"
            if not c.stores_energy:
                continue
            derived = c.derived_stored_energy(d)
            closed = c.stored_energy(d)
            scale = abs(at_rest * d) + abs(derived)
            assert close(closed, derived, scale, ENERGY_TOLERANCE), (
                f"{key}: U({d:.6g}) = {closed!r} J in closed form, {derived!r} J by quadrature of the law")
        if c.stores_energy:  # on arrays: closed form and derived both against the float quadrature
            expected = np.array([c.derived_stored_energy(float(d)) for d in d_values])
            scale = np.abs(np.array([c.law(float(d), 0.0) for d in d_values]) * d_values) + np.abs(expected)
            for name, values in (("closed form", c.stored_energy(d_values)),
                                 ("derived on the array", c.derived_stored_energy(d_values))):
                assert np.all(np.abs(values - expected) <= ENERGY_TOLERANCE * scale), (key, name)


@pytest.mark.parametrize("key", list(TERMS))
def test_force_bound_bounds_the_law(key):
    _, c = TERMS[key]
    for D, V in boxes(c):
        penetration = D if c.is_contact else math.inf
        d_bound = D + c.offset if c.is_contact else D
        bound = c.force_bound(d_bound, V, penetration)
        for d, rate in states(c, (D, V)):
            force = c.law(d, rate)
            assert abs(force) <= bound * (1 + 1e-12), f"{key}: bound {bound:g} N < |F({d:g}, {rate:g})| = {force:g}"


# ------------------------------------------------------------------------------------------ equations = law
def _state_vector(model, c, d: float, rate: float) -> np.ndarray:
    """A state of ``model`` where connector ``c`` has coordinate d and rate d' (its non-ground end moved)."""
    y = model.initial_state() * 0.0
    if c.body_b is not None:
        y[2 * c.body_b], y[2 * c.body_b + 1] = d, rate
    else:
        y[2 * c.body_a], y[2 * c.body_a + 1] = -d, -rate
    return y


@pytest.mark.parametrize("key", list(TERMS))
def test_the_compiled_equations_are_the_law_and_its_dissipated_power(key):
    scene_key, c = TERMS[key]
    model = MODELS[scene_key]
    checked = 0
    for box in boxes(c):
        for d, rate in states(c, box):
            y = _state_vector(model, c, d, rate)
            state = c.provisional(y.tolist() + [0.0, 0.0], None)  # the ground's x, v last
            equations = c.equations(state)
            if equations is not None and equations.constraint:
                continue  # a held state (friction stuck at d' = 0): the force is a constraint, not F(d, d')
            if getattr(c, "compression_only", False) and rate <= 0:
                continue  # the force-free phase is decided at a restart (classify), not provisionally
            mode = Mode(model.names, tuple(x.provisional(y.tolist() + [0.0, 0.0], None) for x in model.connectors),
                        model.load_pieces(0.0))
            raw = model.evaluate(mode, y, t=0.0).forces[c.index]
            force = float(c.reported(raw))
            expected = c.law(d, rate, state)
            assert close(force, expected, abs(expected) + abs(c.law(d, 0.0, state))), (key, d, rate, force, expected)
            if c.dissipates and raw == force:  # unclipped: the compiled power is the law's
                power = model.rhs(mode)(0.0, y)[c.di]
                expected_power = (c.law(d, rate, state) - c.law(d, 0.0, state)) * rate
                assert expected_power == c.dissipated_power(d, rate, state)
                assert close(power, expected_power, (abs(expected) + abs(c.law(d, 0.0, state))) * abs(rate)), (
                    key, d, rate, power, expected_power)
            checked += 1
    assert checked > 50


# ------------------------------------------------------------------------------------------ engine = reference
ENGINE = conformance.shipped_connectors(SCENES)


def test_the_engine_and_the_reference_have_the_same_connectors():
    assert set(ENGINE) == set(TERMS)
    for key, (_, c) in TERMS.items():
        assert (ENGINE[key].a, ENGINE[key].b) == (c.a, c.b), key


def _pairs(engine, reference, rate: float):
    """(engine force function, reference state) pairs to compare at one state: one per onset rate v- for a
    restitution law (each side computes its damping factor chi / max(v-, floor) from its own numbers)."""
    capture = getattr(engine, "capture", None)
    if capture is None:
        return [(lambda d, r: engine.python_force(d, r), None)]
    assert reference.contact_law.name in RESTITUTION_LAWS
    return [(lambda d, r, v=v: engine.law(d, r, PYTHON_OPS, lam=capture.chi / max(v, capture.floor)),
             ContactMode(ON, True, False, reference.contact_law.episode_factor(v), v)) for v in ONSET_RATES]


def check_same_law(key: str, engine, reference) -> int:
    """Assert that ``engine`` (an engine connector) and ``reference`` (a reference term's connector) give the same
    force on the sampled states; return how many states were compared."""
    # the engine regularises Coulomb friction below friction_velocity (DESIGN.md, "Inclined cradle"); beyond it
    # both laws are mu N sign(d')
    band = getattr(engine, "friction_velocity", 0.0)
    compared = 0
    for box in boxes(reference):
        for d, rate in states(reference, box):
            if band and abs(rate) < band:
                continue
            for force, state in _pairs(engine, reference, rate):
                a, b = force(d, rate), reference.law(d, rate, state)
                assert close(a, b, abs(a) + abs(b)), f"{key}: engine F({d:.6g}, {rate:.6g}) = {a!r} N, reference {b!r} N"
                compared += 1
    return compared


@pytest.mark.parametrize("key", list(TERMS))
def test_the_engine_connector_and_the_reference_term_have_the_same_law(key):
    assert check_same_law(key, ENGINE[key], TERMS[key][1]) > 50


@pytest.mark.parametrize("key", ["simplified:recoil_spring", "simplified:recoil_damper", "recuperator:recuperator"])
def test_a_law_written_differently_is_caught(key):
    """The comparison fails for a reference term whose author wrote a law 1e-9 off (a constant mistyped)."""
    _, reference = TERMS[key]

    class Off(type(reference)):
        def law(self, d, rate, state=None):
            return (1.0 + 1e-9) * super().law(d, rate, state)

    wrong = Off.__new__(Off)
    wrong.__dict__.update(reference.__dict__)
    with pytest.raises(AssertionError, match="engine F"):
        check_same_law(key, ENGINE[key], wrong)


def test_a_potential_is_in_the_early_stops_bounds_unless_declared_otherwise(monkeypatch):
    """The reference's share of the energy bounds is derived: a law-only progressive spring is a nonlinear
    potential (the potential well bounds it) without saying so; a linear spring (k d^2 / 2), a contact and a
    damper are not."""
    monkeypatch.setattr(_Term, "connector", _LawOnly)
    monkeypatch.setitem(terms.TERMS, "recoil_spring", _Term)
    spring = build_model(SCENES["simplified"]).connector("recoil_spring")
    assert spring.linear_stiffness == 0.0 and spring.nonlinear_potential is True
    monkeypatch.undo()
    model = build_model(SCENES["model_ii"])
    assert [c.name for c in model.connectors if c.nonlinear_potential] == []
    assert model.connector("recoil_spring").linear_stiffness > 0.0
