"""A support's laws (normal, friction, spade), energies and the choice of its friction branch, by hand."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from validation.reference.planar.supports import Support, SupportMode
from validation.reference.terms.contact_laws import OFF, ON, ContactMode


def table(**fields):
    base = dict(name="s", position=(1.0, 0.0), law="kelvin-voigt", stiffness=1.0e8, exponent=None,
                damping_factor=None, restitution=None, damping=1.0e5, minimum_impact_velocity=None,
                friction_coefficient=None, friction_velocity=1.0e-4, horizontal_stiffness=None,
                horizontal_damping=None)
    base.update(fields)
    return SimpleNamespace(**base)


ACTING = SupportMode(ContactMode(ON, True, False, 0.0, 0.0))


def test_kelvin_voigt_normal_force_and_its_power():
    s = Support(table())
    assert s.normal(ACTING, 1e-4, 0.01) == pytest.approx(1.0e8 * 1e-4 + 1.0e5 * 0.01)
    assert s.normal(SupportMode(ContactMode(OFF)), 1e-4, 0.01) == 0.0
    N = s.normal(ACTING, 1e-4, 0.01)
    assert s.dissipated_power(ACTING, 1e-4, 0.01, N, 0.0, 0.0, 0.0) == pytest.approx(1.0e5 * 0.01 ** 2)
    assert s.stored_energy(ACTING, 1e-4, 0.0) == pytest.approx(0.5 * 1.0e8 * 1e-8)


def test_hunt_crossley_normal_force():
    s = Support(table(law="hunt-crossley", exponent=1.5, damping_factor=0.5, damping=None))
    mode = SupportMode(ContactMode(ON, True, False, 0.5, 0.0))
    assert s.normal(mode, 4e-4, -0.2) == pytest.approx(1.0e8 * 4e-4 ** 1.5 * (1 - 0.1))


def test_regularised_coulomb_friction_on_its_three_branches():
    s = Support(table(friction_coefficient=0.3))
    N = 1000.0
    assert s.tangential(ACTING, N, 0.0, 0.5e-4) == pytest.approx(-0.3 * N * 0.5)
    assert s.tangential(SupportMode(ACTING.contact, 1), N, 0.0, 0.1) == pytest.approx(-0.3 * N)
    assert s.tangential(SupportMode(ACTING.contact, -1), N, 0.0, -0.1) == pytest.approx(0.3 * N)
    # the branch at a restart: by the velocity, on a boundary by where it is heading, or by the event's hint
    assert s._branch(2e-4, 0.0, {}) == 1 and s._branch(-2e-4, 0.0, {}) == -1 and s._branch(0.0, 5.0, {}) == 0
    assert s._branch(1e-4, 1.0, {}) == 1 and s._branch(1e-4, -1.0, {}) == 0
    assert s._branch(1e-4, 1.0, {"u+": False}) == 0 and s._branch(-1e-4, 0.0, {"u-": False}) == -1


def test_a_dug_in_spade_holds_only_while_the_law_acts():
    s = Support(table(horizontal_stiffness=2.0e8, horizontal_damping=1.0e6), anchor=0.5)
    assert s.anchored
    assert s.tangential(ACTING, 1000.0, 0.5 + 1e-5, 0.01) == pytest.approx(-(2.0e8 * 1e-5 + 1.0e6 * 0.01))
    assert s.tangential(SupportMode(ContactMode(OFF, True, True)), 0.0, 0.6, 0.01) == 0.0
    assert s.stored_energy(ACTING, 0.0, 0.5 + 1e-5) == pytest.approx(0.5 * 2.0e8 * 1e-10)
    assert s.stored_energy(SupportMode(ContactMode(OFF)), 0.0, 0.6) == 0.0


def test_the_contact_is_classified_by_side_and_heading():
    s = Support(table())
    assert s.classify(1e-4, 0.0, 0.0, 0.0, 0.0, {}, None).holding
    assert not s.classify(-1e-4, 0.0, 0.0, 0.0, 0.0, {}, None).contact.penetrated
    assert s.classify(0.0, 0.0, 1.0, 0.0, 0.0, {}, None).contact.penetrated       # pressed onto the ground
    # penetrated but leaving faster than k/c allows: below the clipping surface p + (c/k) p' = 0
    clipped = s.classify(1e-6, -1.0, 0.0, 0.0, 0.0, {}, None)
    assert clipped.contact.penetrated and clipped.contact.clipped and not clipped.holding


def test_a_spade_on_its_clipping_surface_slides_where_both_sides_push_onto_it():
    """p + (c/k) p' = 0 (N = 0): let go, p'' = 1e3 makes the surface's rate p' + (c/k) p'' > 0; holding, p'' = -50
    makes it < 0: the spade slides (N = 0, a share of its force).  Where both agree it goes their way; the events
    of the share (a0, a1) end the slide."""
    s = Support(table(horizontal_stiffness=2.0e8, horizontal_damping=1.0e6))
    c_over_k = 1.0e5 / 1.0e8
    p, rate = 1e-6, -1e-6 / c_over_k                                  # on the surface
    assert s.surface(p, rate, 0.0) == pytest.approx(0.0, abs=1e-18)
    slide = s.classify(p, rate, 1e3, 0.0, 0.0, {"s": False}, None, free_holding=-50.0)
    # rates by hand: let go 1e3 -> -1e-3 + 1e-3 * 1e3 = 0.999 > 0; holding -50 -> -1e-3 - 0.05 < 0: slides
    assert slide.sliding and not slide.holding and slide.anchored
    assert not s.classify(p, rate, -10.0, 0.0, 0.0, {"s": False}, None, free_holding=-50.0).sliding
    assert s.classify(p, rate, 1e3, 0.0, 0.0, {"s": True}, None, free_holding=1e3).holding
    assert s.classify(p, rate, 1e3, 0.0, 0.0, {"a1": True}, None, free_holding=-50.0).holding
    assert not s.classify(p, rate, 1e3, 0.0, 0.0, {"a0": False}, None, free_holding=-50.0).anchored
    names = [e[0] for e in s.events(slide, lambda y: (0.0, 0.0, 0.0, 0.0), lambda t, y: 0.5)]
    assert names == ["p", "a0", "a1"]
    assert s.tangential(slide, 0.0, s.anchor + 1e-5, 0.0, share=0.25) == pytest.approx(-0.25 * 2.0e8 * 1e-5)
