"""The element contract, checked on every connector of every shipped scene (mbs_models/scenes/*.toml) and on
every law of every contact (the ``contact_*`` scenes hold one law each): the clauses of
``tests/conformance.py`` -- force bound >= |F|, closed-form U = integral of F(s, 0), closed-form tangent
stiffness = dF/dd, Python = numpy = symbolic, a user function given its item's offset is the law at that offset
(``offset_in_item``) -- and the early stop on a weak-damper variant of each scene.

Deliberately broken elements (a progressive spring whose author wrote a wrong closed-form force bound, or a
wrong closed-form potential: the two omissions of issue #21) must fail the same checks.
"""

from __future__ import annotations

import math

import pytest

import conformance
from mbs_models.elements import ELEMENT_TABLES, GROUND, Connector, LinearSpringDamper
from mbs_models.elements.contact_laws import CONTACT_LAWS
from mbs_models.engine.energy_bounds import dissipative

SCENES = conformance.shipped_scenes()
CONNECTORS = conformance.shipped_connectors(SCENES)


def test_the_shipped_scenes_hold_every_element_and_every_contact_law():
    """The suite covers the registry: a table or a contact law no shipped scene uses would go unchecked."""
    tables = {name for scene in SCENES.values() for name, _ in scene.tables()}
    tables = {name.split(".")[0] for name in tables}
    assert set(ELEMENT_TABLES) <= tables, set(ELEMENT_TABLES) - tables
    laws = {c.law_name for c in CONNECTORS.values() if c.is_contact}
    assert set(CONTACT_LAWS) <= laws, set(CONTACT_LAWS) - laws


@pytest.mark.parametrize("key", list(CONNECTORS))
def test_force_bound(key):
    connector = CONNECTORS[key]
    for box in conformance.boxes(connector):
        conformance.check_force_bound(connector, box)


@pytest.mark.parametrize("key", list(CONNECTORS))
def test_stored_energy_is_the_integral_of_the_force_at_rest(key):
    connector = CONNECTORS[key]
    for box in conformance.boxes(connector):
        conformance.check_potential(connector, box)
        conformance.check_tangent_stiffness(connector, box)


@pytest.mark.parametrize("key", list(CONNECTORS))
def test_python_numpy_and_symbolic_backends_agree(key):
    connector = CONNECTORS[key]
    for box in conformance.boxes(connector):
        conformance.check_backends(connector, box)


@pytest.mark.parametrize("key", [key for key, connector in CONNECTORS.items() if connector.offset_in_item])
def test_a_user_function_given_another_offset_is_the_law_at_that_offset(key):
    connector = CONNECTORS[key]
    for box in conformance.boxes(connector):
        conformance.check_item_offset(connector, box)


def _weak_damper(scene):
    """The scene with its recoil damper and absorber dampers 10x weaker: the energy decays slowly, so that
    the early stop's bounds decide late and from states far from rest."""
    changes = {}
    if getattr(scene, "recoil_damper", None) is not None:
        changes["recoil_damper.recoil"] = scene.recoil_damper.recoil / 10.0
        changes["recoil_damper.counter_recoil"] = scene.recoil_damper.counter_recoil / 10.0
    for i, absorber in enumerate(scene.absorbers):
        if absorber.damping > 0:
            key = "absorber" if len(scene.absorbers) == 1 else f"absorber.{i}"
            changes[f"{key}.damping"] = absorber.damping / 10.0
    return scene.with_changes(**changes) if changes else scene


@pytest.mark.parametrize("key", list(SCENES))
def test_early_stop_equals_the_full_run_on_a_weak_damper_variant(key):
    """Every dissipative scene stops early (the bounds decide within 10 s even with weak dampers) with the full
    run's metrics; one with a load that never ends (gravity on an inclined cradle) has no bound and runs on."""
    scene = _weak_damper(SCENES[key])
    assert conformance.check_early_stop(scene, end_time=10.0) == dissipative(scene)


# ------------------------------------------------------------------------------------------ deliberately broken
class Progressive(Connector):
    """``F = k1 d + k3 d^3`` (N): only the law, as the contract asks."""

    def __init__(self, k1: float = 2.0e4, k3: float = 2.0e6):
        super().__init__("progressive", "progressive", GROUND, "barrel")
        self.k1, self.k3 = k1, k3

    def law(self, d, rate, ops):
        return self.k1 * d + self.k3 * d * d * d


class WrongForceBound(Progressive):
    """The author's closed-form bound forgot the cubic term: ``k1 D``."""

    def force_bound(self, d_bound, rate_bound, energy):
        return self.k1 * d_bound


class WrongPotential(Progressive):
    """The author declared the potential quadratic, ``k1 d^2 / 2``: the cubic term's energy is lost."""

    quadratic_potential = True

    @property
    def quadratic_stiffness(self):
        return self.k1

    def stored_energy(self, d):
        return 0.5 * self.k1 * d ** 2

    def python_stored_energy(self, d):
        return 0.5 * self.k1 * d * d


def test_a_law_alone_passes_every_clause():
    conformance.check_all(Progressive())


def test_a_wrong_closed_form_force_bound_fails():
    connector = WrongForceBound()
    with pytest.raises(AssertionError, match="force_bound"):
        conformance.check_force_bound(connector, conformance.boxes(connector)[-1])


def test_a_wrong_closed_form_potential_fails():
    connector = WrongPotential()
    with pytest.raises(AssertionError, match="integral_0"):
        conformance.check_potential(connector, conformance.boxes(connector)[-1])


def test_a_connector_without_a_law_cannot_be_made():
    class NoLaw(Connector):
        pass

    with pytest.raises(TypeError, match="law"):
        NoLaw("x", "x", GROUND, "barrel")


def test_the_derived_pieces_of_a_law_alone():
    """Hand-derived: U = k1 d^2/2 + k3 d^4/4, k_t = k1 + 3 k3 d^2, max |F| over |d| <= D = k1 D + k3 D^3 (odd,
    increasing), the dissipated power 0; the linear spring-damper's closed forms are the same functions."""
    c = Progressive()
    for d in (-0.3, -0.01, 0.0, 0.02, 0.25):
        assert c.python_stored_energy(d) == pytest.approx(0.5 * c.k1 * d * d + 0.25 * c.k3 * d ** 4, rel=1e-12,
                                                          abs=1e-300)
        assert c.tangent_stiffness(d) == pytest.approx(c.k1 + 3 * c.k3 * d * d, rel=1e-8)
    import numpy as np
    ds = np.array([0.25, -0.3, 0.0, 0.1, 0.1])
    np.testing.assert_allclose(c.stored_energy(ds), 0.5 * c.k1 * ds ** 2 + 0.25 * c.k3 * ds ** 4, rtol=1e-13)
    # not declared monotone: the sampled bound is the corner value plus one grid cell's change (>= the max)
    D = 0.3
    exact = c.k1 * D + c.k3 * D ** 3
    assert exact <= c.force_bound(D, 1.0, math.inf) <= exact * 1.2
    spring = LinearSpringDamper("s", "s", GROUND, "barrel", stiffness=3e4, damping=5e3)
    assert spring.force_bound(0.2, 1.5, math.inf) == pytest.approx(Connector.derived_force_bound(spring, 0.2, 1.5),
                                                                   rel=1e-14)
