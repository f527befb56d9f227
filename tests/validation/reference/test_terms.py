"""The reference's terms: the right-hand side is DESIGN.md's equations, every scene table has a term, and
equivalences between scenes that must move alike (split absorbers, laws that coincide, idle parts)."""

from __future__ import annotations

import functools
import math
from types import SimpleNamespace

import numpy as np
import pytest

from mbs_models.elements import ELEMENT_TABLES
from mbs_models.scene import (Absorber, Barrel, Contact, Conventions, Firing, RecoilDamper, RecoilSpring, Scene,
                              model_i, model_ii, simplified_model)
from mbs_models.scene import load_scene
from mbs_models.scenes import scene_path
from validation.reference import ReferenceModelError, solve_reference
from validation.reference.assembly import build_model
from validation.reference.model import Mode
from validation.reference.switching import Restart
from validation.reference.terms import TERMS
from validation.reference.terms.contact_laws import ContactMode

HC = dict(stiffness=1.05e8, exponent=1.3, damping_factor=0.6)


def two_absorbers(front_contact=None, rear_contact=None, **tables) -> Scene:
    front = Absorber(500.0, "ground", 6750.0, 1837.5, name="front",
                     contact=front_contact or Contact(gap=0.0, **HC))
    rear = Absorber(400.0, "barrel", 5000.0, 1000.0, name="rear",
                    contact=rear_contact or Contact(gap=0.02, law="kelvin-voigt", stiffness=4e7, damping=3e4))
    return Scene(barrel=Barrel(5600.0), firing=Firing(6.86, 564.0), recoil_spring=RecoilSpring(27500.0),
                 recoil_damper=RecoilDamper(6239.0, 14050.0), absorbers=(front, rear), **tables)


# ------------------------------------------------------------------ DESIGN.md's equations, written out here
def design_rhs(scene, y, states, law_force):
    """dy/dt of DESIGN.md's equations for ``scene`` in the mode ``states`` (connector name -> state): the
    barrel, the recoil spring and damper, the absorbers and their contacts (``law_force``: DESIGN.md's
    contact laws, the ``design`` fixture); another element's part is written out in its own test file."""
    absorbers, names = scene.absorbers, scene.absorber_names()
    several = len(absorbers) > 1
    nb = 1 + len(absorbers)
    x, v = list(y[0:2 * nb:2]), list(y[1:2 * nb:2])
    masses = [scene.barrel.mass] + [a.mass for a in absorbers]
    f = [0.0] * nb
    power = {}
    lam_sign = -1.0 if scene.conventions.literal_lambda_sign else 1.0
    if scene.recoil_spring is not None and scene.recoil_spring.stiffness > 0:
        f[0] -= scene.recoil_spring.stiffness * x[0]
    damper = scene.recoil_damper
    if damper is not None and (damper.recoil > 0 or damper.counter_recoil > 0):
        c = damper.recoil if states.get("recoil_damper", True) is not False else damper.counter_recoil
        f[0] -= c * v[0]
        power["recoil_damper"] = c * v[0] ** 2
    sticking = []
    for i, (a, name) in enumerate(zip(absorbers, names), start=1):
        actuator, contact = (f"{name}_damper", f"{name}_contact") if several else ("absorber_damper", "contact")
        if a.stiffness > 0 or a.damping > 0:
            on_barrel = a.mount == "barrel"
            rel_x, rel_v = (x[i] - x[0], v[i] - v[0]) if on_barrel else (x[i], v[i])
            F = a.stiffness * rel_x + a.damping * rel_v
            f[i] -= F
            if on_barrel:
                f[0] += F
            if a.damping > 0:
                power[actuator] = a.damping * rel_v ** 2
        gap = -a.contact.gap if scene.conventions.literal_gap_sign else a.contact.gap
        p, rate = x[0] - x[i] - gap, v[0] - v[i]
        if states[contact].phase == "stick":
            sticking.append((i, contact, p, rate, a.contact))
            continue
        F, elastic = law_force(a.contact, p, rate, states[contact], lam_sign)
        f[i] += F
        f[0] -= F
        power[contact] = (F - elastic) * rate
    for i, contact, p, rate, table in sticking:
        m_red = masses[0] * masses[i] / (masses[0] + masses[i])
        F = m_red * (f[0] / masses[0] - f[i] / masses[i])
        f[i] += F
        f[0] -= F
        power[contact] = (F - table.stiffness * math.copysign(abs(p) ** table.exponent, p)) * rate
    out = []
    for i in range(nb):
        out += [v[i], f[i] / masses[i]]
    return out, power


RHS_SCENES = {
    "simplified": simplified_model(),
    "i": model_i(500.0, 0.01),
    "ii": model_ii(100.0, 0.0),
    "ii-literal": model_ii(1000.0, 0.02, Conventions(literal_gap_sign=True, literal_lambda_sign=True)),
    "ii-compression-only": model_ii(1000.0, 0.0, Conventions(compression_only=True)),
    "two-absorbers-gonthier": two_absorbers(Contact(gap=0.0, law="gonthier", stiffness=1e8, exponent=1.5,
                                                    restitution=0.5, minimum_impact_velocity=0.01)),
    "hertz-exact": two_absorbers(Contact(gap=0.0, law="hertz", stiffness=1e8, exponent=1.5),
                                 Contact(gap=0.0, law="exact-restitution", stiffness=1e8, exponent=1.2, restitution=0.3)),
}


@pytest.mark.parametrize("key", list(RHS_SCENES))
def test_rhs_is_the_design_equations(key, design):
    """The fast right-hand side (and its numpy twin, used in post-processing) equals DESIGN.md's equations
    written out here, in every mode, on random states."""
    design.check_rhs(RHS_SCENES[key], functools.partial(design_rhs, law_force=design.law_force), key)


def test_state_layout_and_connector_names(every_element, design_connectors):
    model = build_model(two_absorbers())
    assert [b.name for b in model.bodies] == ["barrel", "front", "rear"]
    assert model.names == ("recoil_spring", "recoil_damper", "front_damper", "front_contact", "rear_damper",
                           "rear_contact")
    assert [c.name for c in model.dissipating] == ["recoil_damper", "front_damper", "front_contact", "rear_damper",
                                                   "rear_contact"]
    assert model.n_states == 2 * 3 + 5  # positions and velocities, then one dissipated energy per dissipating connector
    every = build_model(every_element(two_absorbers()))  # every other element: its connectors after the absorbers'
    assert every.names == design_connectors(every_element(two_absorbers())) and every.names[:6] == model.names
    assert [b.name for b in every.bodies] == ["barrel", "front", "rear"]
    # then one work per external input (a burst's shots, a breech force), after the dissipated energies
    inputs = [i.name for i in every.loads + every.impulses]
    assert every.n_states == 2 * 3 + len(every.dissipating) + len(inputs)
    assert [every.work_slot[name] for name in inputs] == list(range(2 * 3 + len(every.dissipating), every.n_states))
    one = build_model(model_ii())
    assert [b.name for b in one.bodies] == ["barrel", "absorber"]
    assert one.names == ("recoil_spring", "recoil_damper", "absorber_damper", "contact")
    named = build_model(model_ii().with_changes(**{"absorber.name": "buffer"}))
    assert [b.name for b in named.bodies] == ["barrel", "buffer"] and named.names[-2:] == ("absorber_damper", "contact")


def test_zero_coefficients_add_no_connector():
    scene = Scene(barrel=Barrel(5600.0, initial_velocity=0.7), recoil_spring=RecoilSpring(0.0),
                  recoil_damper=RecoilDamper(0.0, 0.0),
                  absorber=Absorber(1000.0, "ground", 0.0, 0.0), contact=Contact(gap=0.0, **HC))
    assert build_model(scene).names == ("contact",)
    half = scene.with_changes(**{"recoil_damper.counter_recoil": 100.0, "absorber.stiffness": 10.0})
    assert build_model(half).names == ("recoil_damper", "absorber_damper", "contact")
    assert [c.name for c in build_model(half).dissipating] == ["recoil_damper", "contact"]  # a pure spring does not


def test_initial_velocity_follows_design():
    v0 = 6.86 * 564.0 / 5600.0
    assert build_model(model_ii()).bodies[0].initial_velocity == v0
    assert build_model(model_i(1000.0, 0.0, Conventions(v0_includes_absorber=True))).bodies[0].initial_velocity == \
        6.86 * 564.0 / 6600.0
    assert build_model(model_ii(1000.0, 0.0, Conventions(v0_includes_absorber=True))).bodies[0].initial_velocity == v0
    assert build_model(model_ii(1000.0, 0.0, Conventions(rounded_initial_velocity=True))).bodies[0].initial_velocity == 0.7
    assert build_model(Scene(barrel=Barrel(10.0, initial_velocity=-2.5))).bodies[0].initial_velocity == -2.5


# ------------------------------------------------------------------ every table has a term
def test_every_scene_table_has_a_reference_term():
    assert set(ELEMENT_TABLES) <= set(TERMS), set(ELEMENT_TABLES) - set(TERMS)


def test_the_shipped_examples_together_have_every_element(every_element):
    """The scene of every element (tests/conftest.py, composed from the shipped examples) that the generic
    tests use has every element table of the library: a new effect ships an example scene."""
    tables = {key.split(".")[0] for key, _ in every_element().tables()}
    # a table whose example does not go with the others is left out of the composite (see every_element):
    # it is in the composite without the one it conflicts with
    missing = set(ELEMENT_TABLES) - tables - {"carriage"}  # the planar model: never composed in (its own tests)
    assert len(missing) <= 1
    for table in missing:
        others = [key for key in tables if key not in ("barrel", "absorber")]
        assert any(table in {k.split(".")[0] for k, _ in every_element(without=(other,)).tables()} for other in others)
    assert len(every_element().absorbers) > 1


def test_a_table_without_a_term_is_an_error():
    scene = model_ii()
    fake = SimpleNamespace(name="fake", conventions=scene.conventions, absorbers=scene.absorbers,
                           absorber_names=scene.absorber_names, barrel=scene.barrel, firing=scene.firing,
                           tables=lambda: scene.tables() + [("muzzle_brake", object())])
    with pytest.raises(ReferenceModelError, match=r"no reference term for \[muzzle_brake\]"):
        build_model(fake)
    build_model(SimpleNamespace(**{**vars(fake), "tables": scene.tables}))  # the same scene without it is fine


def test_rhs_overflow_gives_inf_like_numpy():
    """A rejected trial step can visit absurd states: the right-hand side must give inf there (so the
    integrator shrinks the step), as numpy arithmetic does, not raise OverflowError."""
    model = build_model(model_ii(1.0, 0.0).with_changes(**{"contact.stiffness": 1e12}))
    mode = Mode(model.names, (None, True, None, ContactMode("on", True, False, 0.6, 0.69)))
    dy = model.rhs(mode)(0.0, np.array([1e200, 1e200, -1e200, 0.0, 0.0, 0.0, 0.0]))
    assert dy.shape == (7,) and not np.all(np.isfinite(dy))


def test_a_gas_spring_beyond_its_volume_gives_inf_not_a_complex_force():
    """A rejected trial step can also push a gas spring beyond its gas volume (V0 - A d <= 0): the power of
    the negative ratio would be complex (Python floats) and its real part a finite, wrong force that the
    integrator might accept; the right-hand side gives inf there (so the step shrinks), and the ordinary
    state is untouched."""
    import warnings

    scene = load_scene(scene_path("recuperator"))
    model = build_model(scene)
    gas = next(c for c in model.connectors if c.name == "recuperator")
    y = model.initial_state()
    mode = Restart(model, 0.0, y, {}, None).mode  # the battery stop holding the preloaded barrel
    barrel = model.body_index["barrel"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        beyond = y.copy()
        beyond[2 * barrel] = 1.5 * gas.d_limit
        dy = model.rhs(mode)(0.0, beyond)
        assert dy.dtype == float and not np.all(np.isfinite(dy))
        inside = y.copy()
        inside[2 * barrel] = 0.5 * gas.d_limit
        force = model.evaluate(mode, inside).forces[gas.index]
        assert force == gas.static_force(0.5 * gas.d_limit)  # the same arithmetic as the term's own law
        batch = model.evaluate(mode, np.stack([inside, beyond], axis=1)).forces[gas.index]
        assert batch[0] == force and batch[1] == math.inf


# ------------------------------------------------------------------ equivalences
def _close(a, b, rel):
    assert a == pytest.approx(b, rel=rel, abs=1e-12)


def _split(absorber: Absorber, name: str) -> Absorber:
    """The same absorber at half mass, half actuator and half contact stiffness (and damping)."""
    c = absorber.contact
    contact = Contact(gap=c.gap, law=c.law, stiffness=c.stiffness / 2, exponent=c.exponent,
                      damping_factor=c.damping_factor, restitution=c.restitution,
                      damping=None if c.damping is None else c.damping / 2,
                      minimum_impact_velocity=c.minimum_impact_velocity)
    return Absorber(absorber.mass / 2, absorber.mount, absorber.stiffness / 2, absorber.damping / 2,
                    contact=contact, name=name)


SPLIT_CONTACTS = {
    "hunt-crossley": Contact(gap=0.01, **HC),
    "gonthier": Contact(gap=0.01, law="gonthier", stiffness=1.05e8, exponent=1.3, restitution=0.5),
    "kelvin-voigt": Contact(gap=0.01, law="kelvin-voigt", stiffness=4e7, damping=3e4),
}


@pytest.mark.parametrize("law", list(SPLIT_CONTACTS))
@pytest.mark.parametrize("mount", ["ground", "barrel"])
def test_two_half_absorbers_move_like_one(law, mount):
    one = Absorber(1000.0, mount, 13500.0, 3675.0, contact=SPLIT_CONTACTS[law], name="whole")
    base = dict(barrel=Barrel(5600.0), firing=Firing(6.86, 564.0), recoil_spring=RecoilSpring(27500.0),
                recoil_damper=RecoilDamper(6239.0, 14050.0))
    whole = solve_reference(Scene(absorbers=(one,), **base), 1.5)
    halves = solve_reference(Scene(absorbers=(_split(one, "left"), _split(one, "right")), **base), 1.5)
    t = np.linspace(0.0, 1.5, 3001)
    np.testing.assert_allclose(halves.position("barrel", t), whole.position("barrel", t), rtol=1e-8, atol=2e-9)
    for half in ("left", "right"):
        np.testing.assert_allclose(halves.position(half, t), whole.position("whole", t), rtol=1e-8, atol=2e-9)
        np.testing.assert_allclose(halves.connector_force(f"{half}_contact", t), whole.connector_force("contact", t) / 2,
                                   rtol=1e-6, atol=1e-6 * whole.peak_contact_force)
    _close(halves.max_barrel_displacement, whole.max_barrel_displacement, 1e-9)
    _close(halves.peak_contact_force, whole.peak_contact_force / 2, 1e-8)
    _close(halves.max_absorber_velocity, whole.max_absorber_velocity, 1e-8)
    _close(halves.peak_support_force, whole.peak_support_force, 1e-8)
    assert len(halves.impacts) == 2 * len(whole.impacts)
    np.testing.assert_allclose(sorted(i.start for i in halves.impacts),
                               sorted(i.start for i in whole.impacts for _ in range(2)), rtol=1e-7, atol=1e-9)


def test_hertz_is_hunt_crossley_without_damping():
    hertz = solve_reference(model_ii(500.0, 0.0).with_changes(contact=Contact(gap=0.0, law="hertz", stiffness=2.1e8,
                                                                              exponent=1.3)), 3.0)
    hc = solve_reference(model_ii(500.0, 0.0).with_changes(**{"contact.damping_factor": 0.0}), 3.0)
    for name in ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "peak_support_force"):
        _close(getattr(hertz, name), getattr(hc, name), 1e-12)
    np.testing.assert_allclose([(i.start, i.end) for i in hertz.impacts], [(i.start, i.end) for i in hc.impacts],
                               rtol=1e-12)
    assert hertz.dissipated_energy["contact"] == pytest.approx(0.0, abs=1e-9 * hertz.initial_energy)


def test_an_absorber_whose_gap_never_closes_changes_nothing():
    alone = model_ii(1000.0, 0.0)
    idle = Absorber(300.0, "ground", 5000.0, 500.0, name="idle", contact=Contact(gap=1.0, **HC))
    busy = Absorber(1000.0, "ground", 13500.0, 3675.0, name="busy", contact=alone.contact)
    both = alone.with_changes(absorbers=(busy, idle))
    a, b = solve_reference(alone, 5.0), solve_reference(both, 5.0)
    t = np.linspace(0.0, 5.0, 2001)
    np.testing.assert_allclose(b.position("barrel", t), a.position("barrel", t), rtol=1e-8, atol=2e-9)
    np.testing.assert_allclose(b.position("busy", t), a.position("absorber", t), rtol=1e-8, atol=2e-9)
    assert np.all(b.position("idle", t) == 0.0) and np.all(b.connector_force("idle_contact", t) == 0.0)
    for name in ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "peak_support_force"):
        _close(getattr(b, name), getattr(a, name), 1e-9)
    assert b.contacts["idle_contact"].episodes == [] and b.contacts["idle_contact"].onsets == []
    assert len(b.impacts) == len(a.impacts) and all(i.contact == "busy_contact" for i in b.impacts)


@pytest.mark.parametrize("law", ["lankarani-nikravesh", "flores", "gonthier", "exact-restitution"])
def test_first_impact_of_a_restitution_law_is_hunt_crossley_with_chi_over_v0(law, design):
    """At gap 0 the first episode starts at t = 0 with v- = v0, so the law is Hunt-Crossley with
    lambda = chi / v0 until that episode ends."""
    scene = model_ii(500.0, 0.0)
    v0 = scene.initial_velocity
    chi = design.chi(law, 0.6)
    ours = solve_reference(scene.with_changes(contact=Contact(gap=0.0, law=law, stiffness=2.1e8, exponent=1.3,
                                                              restitution=0.6)), 0.2)
    hc = solve_reference(scene.with_changes(contact=Contact(gap=0.0, stiffness=2.1e8, exponent=1.3,
                                                            damping_factor=chi / v0)), 0.2)
    first, theirs = ours.contact_episodes[0], hc.contact_episodes[0]
    assert ours.contacts["contact"].onsets[0] == (0.0, v0)
    assert (first.start, first.end, first.time_of_peak) == pytest.approx((theirs.start, theirs.end, theirs.time_of_peak),
                                                                         rel=1e-9)
    _close(first.peak_force, theirs.peak_force, 1e-9)
    t = np.linspace(0.0, first.end, 501)
    np.testing.assert_allclose(ours.state(t)[:4], hc.state(t)[:4], rtol=1e-8, atol=1e-12)
