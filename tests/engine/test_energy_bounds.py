"""Energy bounds of a dissipative scene (mbs_models.engine.energy_bounds): their closed forms on the paper's
models, the energy summed term by term, the contact forces the tracker evaluates, a potential given as a
function.  That the bounds bound a simulated run's future is checked along the full runs of
tests/engine/test_finality.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mbs_models import Conventions, load_scene, model_i, model_ii
from mbs_models.elements import Connector, LinearSpringDamper
from mbs_models.engine import energy_bounds as eb
from mbs_models.scenes import scene_path


def test_the_bound_coefficients_are_the_closed_forms_of_the_paper_models():
    """The quadratic form of the springs gives x_M <= sqrt(2E/k), x_M - x_m <= sqrt(2E/k_r) (absorber on
    the barrel) and sqrt(2E (1/k + 1/k_r)) (on the ground)."""
    k, kr, energy = 27500.0, 13500.0, 1336.0
    for factory, relative in ((model_i, 2 * energy / kr), (model_ii, 2 * energy * (1 / k + 1 / kr))):
        b = eb.EnergyBounds(factory(1000.0, 0.1))
        assert b.barrel_displacement(energy) == pytest.approx(math.sqrt(2 * energy / k), rel=1e-12)
        assert b.contact_coordinate(0, energy) == pytest.approx(math.sqrt(relative), rel=1e-12)
    free = eb.EnergyBounds(model_ii(1000.0, 0.0).with_changes(**{"absorber.stiffness": 0.0}))
    assert free.contact_coordinate(0, energy) == math.inf  # no spring holds the absorber


def test_mechanisms_with_the_same_springs_share_one_quadratic_form_with_a_fresh_one_s_numbers():
    """A sweep's points (other gaps, other absorber masses) keep their springs: one form, computed once, whose
    coefficients are a fresh form's bit for bit; other springs give another form."""
    from mbs_models.engine.mechanism import Mechanism

    mechanisms = [Mechanism(model_ii(mass, gap)) for mass, gap in ((1000.0, 0.0), (100.0, 0.08), (500.0, 0.12))]
    forms = [eb._QuadraticForm.of(m) for m in mechanisms]
    assert forms[0] is forms[1] is forms[2]
    for mechanism in mechanisms:
        fresh = eb._QuadraticForm(mechanism)
        for connector in mechanism.connectors:
            g = mechanism.direction(connector)
            assert forms[0].coefficient(g) == fresh.coefficient(g)
    stiffer = Mechanism(model_ii(1000.0, 0.0).with_changes(**{"absorber.stiffness": 2e4}))
    assert eb._QuadraticForm.of(stiffer) is not forms[0]


def test_the_tracker_evaluates_each_contact_with_its_law():
    for scene in (model_ii(), model_ii(100.0, 0.04, Conventions(literal_gap_sign=True)),
                  model_i(500.0, 0.0, Conventions(compression_only=True)),
                  model_ii(500.0, 0.0, Conventions(literal_lambda_sign=True))):
        b = eb.EnergyBounds(scene)
        contact = b.contacts[0]
        for rel in (-0.01, 0.0, 1e-4, 0.003, 0.05):
            for rate in (-3.0, -1.0, -0.1, 0.0, 0.2, 2.0):
                expected = float(contact.force(np.array([rel]), np.array([rate]))[0])  # the numpy backend
                assert b.contact_force(contact, [rel, 0.0], [rate, 0.0]) == pytest.approx(expected, rel=1e-14, abs=0.0)


def test_largest_energy_rise():
    assert eb.largest_energy_rise([3.0, 2.0, 2.0, 1.0]) == 0.0
    assert eb.largest_energy_rise([4.0, 1.0, 2.0, 1.5]) == pytest.approx(1.0)  # 1 -> 2 later
    assert eb.largest_energy_rise([0.0, 1.0]) == math.inf


def _stored_scene_names():
    from mbs_models.scenes import list_scenes
    return list_scenes()


@pytest.mark.parametrize("name", _stored_scene_names())
def test_energy_is_summed_element_by_element_in_the_documented_order(name):
    """EnergyBounds.energy looks its terms up once: the same float as the sum written out term by term
    (every early stop's decision depends on it to the last bit), on every stored scene (every element)."""
    from mbs_models import load_scene
    from mbs_models.scenes import scene_path

    b = eb.EnergyBounds(load_scene(scene_path(name)))
    m = b.mechanism
    rng = np.random.default_rng(7)
    for _ in range(200):
        x = [float(value) for value in rng.normal(0.0, 0.05, len(m.bodies))]
        v = [float(value) for value in rng.normal(0.0, 2.0, len(m.bodies))]
        expected = 0.0
        for element in m.elements:
            part = None
            for body in element.bodies:
                term = 0.5 * body.mass * v[m.body_index[body.name]] * v[m.body_index[body.name]]
                part = term if part is None else part + term
            for c in element.connectors:
                if c.stores_energy and not c.is_contact and c.quadratic_potential:
                    d = m.relative_at(c, x)
                    term = 0.5 * c.stiffness * d * d
                    part = term if part is None else part + term
            if part is not None:
                expected += part
            for c in element.connectors:
                if c.is_contact:
                    expected += c.python_elastic(m.relative_at(c, x))
            for c in element.connectors:
                if c.stores_energy and not c.is_contact and not c.quadratic_potential:
                    expected += c.python_stored_energy(m.relative_at(c, x))
        assert b.energy(x, v) == expected


class _ProgressiveActuator(Connector):
    """The absorber's actuator made progressive, given by its law alone: ``F = k d + k3 d^3 + c d'`` (N)."""

    def __init__(self, linear, cubic_stiffness: float):
        super().__init__(linear.name, linear.element, linear.a, linear.b)
        self.k, self.c, self.k3 = linear.stiffness, linear.damping, cubic_stiffness

    def law(self, d, rate, ops):
        return self.k * d + self.k3 * d * d * d + self.c * rate


@pytest.mark.parametrize("name", ["model_i", "model_ii"])
def test_a_potential_given_as_a_function_anywhere_keeps_the_early_stop(monkeypatch, name):
    """A nonlinear potential between two bodies (model (i): barrel -> absorber, a loose well) or from the ground
    to an absorber (model (ii): the absorber's well) neither loses nor breaks the early stop: it stops with the
    full run's metrics."""
    import conformance
    from mbs_models.elements.absorber import Absorber

    original = Absorber.connectors

    def progressive(self, scene, element):
        return [_ProgressiveActuator(c, 1e8) if isinstance(c, LinearSpringDamper) else c
                for c in original(self, scene, element)]

    monkeypatch.setattr(Absorber, "connectors", progressive)
    scene = load_scene(scene_path(name))
    bounds = eb.EnergyBounds(scene)
    actuator = next(c for c in bounds.mechanism.connectors if isinstance(c, _ProgressiveActuator))
    assert (bounds.well is not None and actuator in bounds.well) or any(actuator in w for w in bounds.loose)
    assert bounds.energy_floor == 0.0  # U = k d^2/2 + k3 d^4/4 >= 0, its minimum 0 at d = 0
    assert conformance.check_early_stop(scene, 10.0)
