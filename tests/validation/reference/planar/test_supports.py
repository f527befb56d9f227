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
                horizontal_damping=None, anchor="rest")
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


def test_a_dug_in_spade_holds_while_the_point_is_in_the_ground_whatever_n():
    """DESIGN.md: -(k_h (x - x0) + c_h u) while p > 0, also where the normal law is clipped to N = 0; none off it."""
    s = Support(table(horizontal_stiffness=2.0e8, horizontal_damping=1.0e6), anchor=0.5)
    assert s.anchored
    held = -(2.0e8 * 1e-5 + 1.0e6 * 0.01)
    acting = SupportMode(ACTING.contact, 0, 0.5)
    clipped = SupportMode(ContactMode(OFF, True, True), 0, 0.5)
    off = SupportMode(ContactMode(OFF), 0, 0.5)
    assert s.tangential(acting, 1000.0, 0.5 + 1e-5, 0.01) == pytest.approx(held)
    assert s.normal(clipped, 1e-6, -1.0) == 0.0
    assert s.tangential(clipped, 0.0, 0.5 + 1e-5, 0.01) == pytest.approx(held)
    assert s.tangential(off, 0.0, 0.6, 0.01) == 0.0
    assert s.stored_energy(acting, 0.0, 0.5 + 1e-5) == pytest.approx(0.5 * 2.0e8 * 1e-10)
    assert s.stored_energy(clipped, 0.0, 0.5 + 1e-5) == pytest.approx(0.5 * 2.0e8 * 1e-10)
    assert s.stored_energy(off, 0.0, 0.6) == 0.0
    # clipped: N = 0 and the power is the spade damper's c_h u^2 alone
    assert s.dissipated_power(clipped, 1e-6, -1.0, 0.0, held, 0.01, 0.5 + 1e-5) == pytest.approx(
        1.0e6 * 0.01 ** 2 + 1.0e8 * 1e-6 * 1.0)


def test_a_spade_is_anchored_at_rest_or_where_it_touched_down():
    """``rest``: x0 stays the static x through a jump; ``touchdown``: x0 is the point's x when it enters the
    ground again (hint p rising), kept while it stays in, and not moved by a restart in the ground."""
    rest = Support(table(horizontal_stiffness=2.0e8), anchor=0.5)
    down = Support(table(horizontal_stiffness=2.0e8, anchor="touchdown"), anchor=0.5)
    assert rest.provisional(1e-4, 0.0).anchor == 0.5 and down.provisional(1e-4, 0.0).anchor == 0.5
    flying = SupportMode(ContactMode(OFF), 0, 0.5)
    assert rest.classify(0.0, 0.3, 0.0, 0.0, 0.0, {"p": True}, flying, x=0.51).anchor == 0.5
    landed = down.classify(0.0, 0.3, 0.0, 0.0, 0.0, {"p": True}, flying, x=0.51)
    assert landed.in_ground and landed.anchor == 0.51
    assert down.tangential(landed, 0.0, 0.51, 0.0) == 0.0
    # a restart in the ground (another element's event) keeps it
    assert down.classify(1e-4, 0.0, 0.0, 0.0, 0.0, {}, landed, x=0.52).anchor == 0.51
    assert down.tangential(landed, 0.0, 0.52, 0.0) == pytest.approx(-2.0e8 * 0.01)
    # leaving the ground keeps the last anchor (no force, no stored energy off the ground)
    left = down.classify(0.0, -0.3, 0.0, 0.0, 0.0, {"p": False}, landed, x=0.53)
    assert not left.in_ground and left.anchor == 0.51 and down.stored_energy(left, 0.0, 0.53) == 0.0
    # a support without a spade has none
    assert Support(table()).provisional(1e-4, 0.0).anchor is None


def test_the_contact_is_classified_by_side_and_heading():
    s = Support(table())
    assert s.classify(1e-4, 0.0, 0.0, 0.0, 0.0, {}, None).holding
    assert not s.classify(-1e-4, 0.0, 0.0, 0.0, 0.0, {}, None).contact.penetrated
    assert s.classify(0.0, 0.0, 1.0, 0.0, 0.0, {}, None).contact.penetrated       # pressed onto the ground
    # penetrated but leaving faster than k/c allows: below the clipping surface p + (c/k) p' = 0
    clipped = s.classify(1e-6, -1.0, 0.0, 0.0, 0.0, {}, None)
    assert clipped.contact.penetrated and clipped.contact.clipped and not clipped.holding


def test_a_spade_clipped_in_the_ground_is_not_a_switch_of_its_force():
    """On the clipping surface p + (c/k) p' = 0 only N switches: the events are p and s, no other."""
    s = Support(table(horizontal_stiffness=2.0e8, horizontal_damping=1.0e6), anchor=0.0)
    c_over_k = 1.0e5 / 1.0e8
    p, rate = 1e-6, -1e-6 / c_over_k                                  # on the surface
    below = s.classify(p, rate, 1e3, 0.0, 0.0, {"s": False}, None)
    above = s.classify(p, rate, 1e3, 0.0, 0.0, {"s": True}, None)
    assert below.contact.clipped and below.in_ground and not below.holding
    assert above.holding and above.in_ground
    names = [e[0] for e in s.events(below, lambda y: (0.0, 0.0, 0.0, 0.0))]
    assert names == ["p", "s"]
    assert s.tangential(below, 0.0, 1e-5, 0.0) == s.tangential(above, 0.0, 1e-5, 0.0) == pytest.approx(-2.0e3)


def test_a_spade_on_the_ground_slides_where_both_sides_push_onto_it():
    """At p = p' = 0 (within GROUND_POSITION, and p' within GROUND_TIME of the accelerations): off the ground
    p'' = 6.5 > 0 (the weight presses it in), in it with N = 0 p'' = -5.3 < 0 (its spring lifts it out): it slides
    (N = 0, a share of its force).  Where both agree it goes their way; the events of the share (a0, a1) end the
    slide and no p event is watched on it."""
    s = Support(table(horizontal_stiffness=2.0e8, horizontal_damping=1.0e6), anchor=0.0)
    off = SupportMode(ContactMode(OFF), 0, 0.0)
    slide = s.classify(6.6e-15, -1.6e-12, 6.5, 0.0, 0.0, {"p": True}, off, x=1e-5, free_holding=-5.3)
    assert slide.sliding and not slide.holding and not slide.in_ground and slide.spring_stored
    assert slide.anchor == 0.0                                          # rest: the anchor stays
    assert s.classify(6.6e-15, -1.6e-12, 6.5, 0.0, 0.0, {"p": True}, off, x=1e-5, free_holding=2.0).holding
    assert not s.classify(6.6e-15, -1.6e-12, -1.0, 0.0, 0.0, {}, off, x=1e-5, free_holding=-5.3).spring_stored
    # crossing with a rate that carries it across in more than GROUND_TIME: a touch-down, not a slide
    assert s.classify(0.0, 1e-3, 6.5, 0.0, 0.0, {"p": True}, off, x=1e-5, free_holding=-5.3).in_ground
    assert s.classify(0.0, 0.0, 6.5, 0.0, 0.0, {"a1": True}, slide, x=1e-5, free_holding=-5.3).holding
    assert not s.classify(0.0, 0.0, 6.5, 0.0, 0.0, {"a0": False}, slide, x=1e-5, free_holding=-5.3).spring_stored
    names = [e[0] for e in s.events(slide, lambda y: (0.0, 0.0, 0.0, 0.0), lambda t, y: 0.5)]
    assert names == ["a0", "a1"]
    assert s.tangential(slide, 0.0, 1e-5, 0.0, share=0.25) == pytest.approx(-0.25 * 2.0e8 * 1e-5)
    assert s.stored_energy(slide, 0.0, 1e-5) == pytest.approx(0.5 * 2.0e8 * 1e-10)
    # touchdown: a slide is a touch-down too
    down = Support(table(horizontal_stiffness=2.0e8, anchor="touchdown"), anchor=0.0)
    assert down.classify(6.6e-15, -1.6e-12, 6.5, 0.0, 0.0, {"p": True}, off, x=1e-5, free_holding=-5.3).anchor == 1e-5
