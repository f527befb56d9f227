"""Contact laws (mbs_models.elements.contact_laws): every law of the family, for every contact.

Oracles: for a free two-body impact (no springs, no dampers) the coefficient of restitution depends
only on lambda * v_in for Hunt-Crossley, and only on chi for the restitution laws (they are Hunt-Crossley
with lambda = chi / v-), whatever the stiffness, exponent or masses; the closed form
``validation.reference.closed_form.hunt_crossley_restitution`` (an independent implementation) gives it.
Measured worst error of e over the grids below: 2.8e-6 at `standard`, 1e-9 at `reference`.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mbs_models import (Absorber, Barrel, Contact, Conventions, RecoilDamper, RecoilSpring, Scene, SolverSettings,
                        load_scene, model_i, model_ii, simulate)
from mbs_models.scenes import list_scenes, scene_path
from mbs_models.elements.contact_laws import (CONTACT_LAWS, exact_restitution_factor, law_force, restitution_factor)
from mbs_models.elements.ops import NUMPY_OPS, PYTHON_OPS
from validation.reference.closed_form import hunt_crossley_restitution

IMPACT_VELOCITY = 0.69  # m/s
RESTITUTION_LAWS = ("lankarani-nikravesh", "flores", "gonthier", "exact-restitution")


def free_impact(contact: Contact, absorber_mass=1000.0, conventions=None, velocity=IMPACT_VELOCITY) -> Scene:
    """The barrel at ``velocity`` against an absorber at rest, no spring or damper anywhere."""
    return Scene(barrel=Barrel(mass=5600.0, initial_velocity=velocity), recoil_spring=RecoilSpring(0.0),
                 recoil_damper=RecoilDamper(0.0, 0.0),
                 absorber=Absorber(mass=absorber_mass, mount="ground", stiffness=0.0, damping=0.0), contact=contact,
                 conventions=conventions or Conventions(), name="free impact")


def hunt_crossley(damping_factor, exponent=1.3, stiffness=2.1e8) -> Contact:
    return Contact(gap=0.0, stiffness=stiffness, exponent=exponent, damping_factor=damping_factor)


def restitution_law(law, e, exponent=1.3, stiffness=2.1e8) -> Contact:
    return Contact(gap=0.0, stiffness=stiffness, exponent=exponent, law=law, restitution=e)


def engine_restitution(scene: Scene, accuracy="standard") -> float:
    result = simulate(scene, 1.5, accuracy)
    assert len(result.impacts) == 1 and result.impacts[0].end < 1.4, "one impact, over before the end"
    return (result.absorber_velocity[-1] - result.barrel_velocity[-1]) / scene.initial_velocity


# ------------------------------------------------------------------------------------------ Hunt-Crossley
@pytest.mark.parametrize("damping_factor", [0.0, 0.3, 0.6, 2.0])
@pytest.mark.parametrize("exponent", [1.0, 1.3, 1.5, 2.0])
@pytest.mark.parametrize("stiffness", [1e6, 2.1e8, 1e10])
def test_engine_restitution_matches_oracle(damping_factor, exponent, stiffness):
    e = engine_restitution(free_impact(hunt_crossley(damping_factor, exponent, stiffness)))
    assert e == pytest.approx(hunt_crossley_restitution(IMPACT_VELOCITY, damping_factor, exponent), abs=1e-5)


@pytest.mark.parametrize("absorber_mass", [10.0, 5600.0, 1e5])
def test_engine_restitution_does_not_depend_on_masses(absorber_mass):
    e = engine_restitution(free_impact(hunt_crossley(0.6), absorber_mass))
    assert e == pytest.approx(hunt_crossley_restitution(IMPACT_VELOCITY, 0.6, 1.3), abs=1e-5)


def test_reference_preset_meets_the_oracle_tighter():
    e = engine_restitution(free_impact(hunt_crossley(0.6)), "reference")
    assert e == pytest.approx(hunt_crossley_restitution(IMPACT_VELOCITY, 0.6, 1.3), abs=1e-8)


def test_literal_lambda_sign_gains_energy_as_the_oracle_predicts():
    e = engine_restitution(free_impact(hunt_crossley(0.6), conventions=Conventions(literal_lambda_sign=True)))
    assert e > 1.0
    assert e == pytest.approx(hunt_crossley_restitution(IMPACT_VELOCITY, -0.6, 1.3), abs=1e-5)


# ------------------------------------------------------------------------------------------ restitution laws
def test_restitution_factors_are_the_published_formulas():
    """chi of each law at e = 0.5, computed by hand: LN 3 (1 - 0.25)/4, Flores 8 (0.5)/(2.5), Gonthier 0.75/0.5."""
    assert restitution_factor("lankarani-nikravesh", 0.5) == pytest.approx(0.5625, rel=1e-15)
    assert restitution_factor("flores", 0.5) == pytest.approx(1.6, rel=1e-15)
    assert restitution_factor("gonthier", 0.5) == pytest.approx(1.5, rel=1e-15)
    with pytest.raises(ValueError):
        restitution_factor("hertz", 0.5)


@pytest.mark.parametrize("e", [1e-3, 0.05, 0.3, 0.5, 0.8, 0.99, 1 - 1e-9, 1.0])
def test_exact_restitution_factor_inverts_the_oracle(e):
    """The engine's chi, put into the reference's closed form (written independently), gives back e."""
    chi = exact_restitution_factor(e)
    achieved = 1.0 if chi == 0.0 else hunt_crossley_restitution(1.0, chi)
    assert achieved == pytest.approx(e, rel=1e-12, abs=1e-15)


def test_lankarani_nikravesh_gives_about_0_73_for_a_requested_0_5():
    assert hunt_crossley_restitution(1.0, restitution_factor("lankarani-nikravesh", 0.5)) == pytest.approx(0.7252, abs=1e-4)


@pytest.mark.parametrize("law", RESTITUTION_LAWS)
@pytest.mark.parametrize("e", [0.05, 0.3, 0.5, 0.8, 0.99])
def test_restitution_laws_rebound_as_the_oracle_says(law, e):
    """Free impact: the achieved e is the closed form's at chi (exactly e for exact-restitution)."""
    expected = hunt_crossley_restitution(1.0, restitution_factor(law, e))
    assert engine_restitution(free_impact(restitution_law(law, e))) == pytest.approx(expected, abs=2e-5)
    if law == "exact-restitution":
        assert expected == pytest.approx(e, rel=1e-12)


@pytest.mark.parametrize("law", RESTITUTION_LAWS)
def test_restitution_laws_at_the_reference_preset(law):
    expected = hunt_crossley_restitution(1.0, restitution_factor(law, 0.5))
    assert engine_restitution(free_impact(restitution_law(law, 0.5)), "reference") == pytest.approx(expected, abs=1e-8)


@pytest.mark.parametrize("law", RESTITUTION_LAWS)
@pytest.mark.parametrize("case", ["stiffness", "exponent", "mass", "speed"])
def test_restitution_does_not_depend_on_stiffness_exponent_mass_or_speed(law, case):
    contact = restitution_law(law, 0.3, **({"stiffness": 1e10} if case == "stiffness" else
                                           {"exponent": 1.0} if case == "exponent" else {}))
    scene = free_impact(contact, absorber_mass=50.0 if case == "mass" else 1000.0,
                        velocity=5.0 if case == "speed" else IMPACT_VELOCITY)
    expected = hunt_crossley_restitution(1.0, restitution_factor(law, 0.3))
    assert engine_restitution(scene) == pytest.approx(expected, abs=2e-5)


def test_the_onset_velocity_is_captured_with_a_gap():
    """A free impact after a gap of 20 mm: the onset falls inside a step; the captured v- is the speed."""
    contact = Contact(gap=0.02, stiffness=2.1e8, exponent=1.3, law="exact-restitution", restitution=0.5)
    result = simulate(free_impact(contact), 1.5)
    (t_onset, v_onset), = result.contacts["contact"].onsets
    assert v_onset == pytest.approx(IMPACT_VELOCITY, rel=1e-12)
    assert t_onset == pytest.approx(0.02 / IMPACT_VELOCITY, rel=1e-9)
    e = (result.absorber_velocity[-1] - result.barrel_velocity[-1]) / IMPACT_VELOCITY
    assert e == pytest.approx(0.5, abs=2e-5)


# ------------------------------------------------------------------------------------------ exact equivalences
def test_hertz_is_hunt_crossley_with_lambda_zero():
    scene = model_ii(1000.0, 0.0)
    hertz = simulate(scene.with_changes(contact=Contact(gap=0.0, stiffness=2.1e8, exponent=1.3, law="hertz")), 3.0)
    zero = simulate(scene.with_changes(contact=hunt_crossley(0.0)), 3.0)
    np.testing.assert_array_equal(hertz.time, zero.time)
    np.testing.assert_array_equal(hertz.barrel_position, zero.barrel_position)
    np.testing.assert_array_equal(hertz.contact_force, zero.contact_force)
    assert hertz.peak_contact_force == zero.peak_contact_force


@pytest.mark.parametrize("law", RESTITUTION_LAWS)
def test_a_first_impact_at_gap_0_is_hunt_crossley_with_lambda_chi_over_v0(law):
    """Model (ii) at gap 0, over the first impact: the restitution law is Hunt-Crossley with
    lambda = chi / v0 (its formula at the onset velocity v0), step for step."""
    scene = model_ii(1000.0, 0.0)
    v0 = scene.initial_velocity
    chi = restitution_factor(law, 0.5)
    ours = simulate(scene.with_changes(contact=restitution_law(law, 0.5)), 0.03)
    theirs = simulate(scene.with_changes(contact=hunt_crossley(chi / v0)), 0.03)
    assert len(ours.impacts) == len(theirs.impacts) == 1
    np.testing.assert_array_equal(ours.time, theirs.time)
    np.testing.assert_array_equal(ours.barrel_position, theirs.barrel_position)
    np.testing.assert_array_equal(ours.contact_force, theirs.contact_force)


# ------------------------------------------------------------------------------------------ the force itself
@pytest.mark.parametrize("law", sorted(CONTACT_LAWS))
def test_backends_agree_and_the_force_never_pulls(law):
    fields = {"hunt-crossley": dict(exponent=1.3, damping_factor=0.6), "hertz": dict(exponent=1.3),
              "kelvin-voigt": dict(damping=8e4)}.get(law, dict(exponent=1.3))
    d = np.linspace(-0.01, 0.02, 31)
    rate = np.linspace(-5.0, 5.0, 41)
    D, R = np.meshgrid(d, rate)
    lam = 0.8 if law in RESTITUTION_LAWS else None
    numpy_force = law_force(D, R, law, 2.1e8 if law != "kelvin-voigt" else 4e7, fields.get("exponent"), 0.002,
                            NUMPY_OPS, damping_factor=fields.get("damping_factor"), damping=fields.get("damping"),
                            lam=lam)
    python_force = np.vectorize(lambda a, b: law_force(a, b, law, 2.1e8 if law != "kelvin-voigt" else 4e7,
                                                       fields.get("exponent"), 0.002, PYTHON_OPS,
                                                       damping_factor=fields.get("damping_factor"),
                                                       damping=fields.get("damping"), lam=lam))(D, R)
    np.testing.assert_allclose(numpy_force, python_force, rtol=1e-14, atol=0.0)
    assert np.all(numpy_force >= 0.0)
    assert np.all(numpy_force[D <= 0.002] == 0.0)  # apart: no force


@pytest.mark.parametrize("law", sorted(CONTACT_LAWS))
def test_python_and_symbolic_user_functions_agree(law):
    contact = {"hunt-crossley": hunt_crossley(0.6), "hertz": Contact(gap=0.0, stiffness=2.1e8, exponent=1.3, law="hertz"),
               "kelvin-voigt": Contact(gap=0.0, stiffness=4e7, law="kelvin-voigt", damping=8e4)}.get(
        law, restitution_law(law, 0.5) if law in RESTITUTION_LAWS else None)
    scene = model_ii(500.0, 0.02).with_changes(contact=contact)
    symbolic = simulate(scene, 2.0, user_functions="symbolic")
    python = simulate(scene, 2.0, user_functions="python")
    assert python.max_barrel_displacement == pytest.approx(symbolic.max_barrel_displacement, rel=1e-9)
    assert python.peak_contact_force == pytest.approx(symbolic.peak_contact_force, rel=1e-9)
    assert len(python.impacts) == len(symbolic.impacts)


@pytest.mark.parametrize("law", sorted(CONTACT_LAWS))
def test_the_symbolic_user_function_is_the_law_in_contact_and_zero_when_open(law):
    """The recorded user function selects 0 while the contact is open (p <= 0) and the law's own expression
    otherwise: the same float as the symbolic law in contact (one expression tree, bit for bit), 0 at and before
    the offset, where the law's force is 0 too (a test above) -- at rates of either sign."""
    import exudyn

    from mbs_models.elements.ops import symbolic_ops
    from mbs_models.engine.mechanism import Mechanism

    contact = {"hunt-crossley": hunt_crossley(0.6), "hertz": Contact(gap=0.02, stiffness=2.1e8, exponent=1.3, law="hertz"),
               "kelvin-voigt": Contact(gap=0.02, stiffness=4e7, law="kelvin-voigt", damping=8e4)}.get(
        law, restitution_law(law, 0.5) if law in RESTITUTION_LAWS else None)
    connector = Mechanism(model_ii(500.0, 0.0).with_changes(contact=contact)).connector["contact"]
    if connector.capture is not None:
        connector.capture.start(0.0, 0.7)
    ops = symbolic_ops()
    recorded = connector.user_function_law(ops)
    offset = connector.offset
    for p in (-0.01, -1e-9, 0.0, 1e-9, 1e-4, 0.01):
        for rate in (-3.0, -0.2, 0.0, 0.5, 4.0):
            d, v = exudyn.symbolic.Real(offset + p), exudyn.symbolic.Real(rate)
            value = recorded(d, v, exudyn.symbolic.Real(offset)).Evaluate()
            if offset + p > offset:
                assert value == connector.law(d, v, ops).Evaluate(), (p, rate)
            else:
                assert value == 0.0 and connector.python_force(offset + p, rate) == 0.0, (p, rate)


def test_kelvin_voigt_jumps_at_the_onset_and_never_pulls():
    contact = Contact(gap=0.01, stiffness=4e7, law="kelvin-voigt", damping=8e4)
    result = simulate(free_impact(contact), 0.2, "reference")
    impact = result.impacts[0]
    force = result.contact_force
    first = int(np.argmax(force > 0))
    # within the first step of contact the force is already ~ c v- (the damper's jump), not ~ 0
    assert force[first] > 0.5 * 8e4 * IMPACT_VELOCITY
    assert np.all(force >= 0.0) and impact.start == pytest.approx(0.01 / IMPACT_VELOCITY, abs=1e-9)


@pytest.mark.parametrize("law", RESTITUTION_LAWS)
def test_a_resting_contact_with_onset_velocity_near_zero_stays_finite(law):
    """Model (ii) at gap 0 settles on the contact boundary: micro-contacts with onset rates v- down to
    ~1e-13 m/s, far below the 1 mm/s floor, where the law is Hunt-Crossley with lambda = chi / 1e-3.
    The force stays finite and non-negative, and the energy balance closes."""
    scene = model_ii(1000.0, 0.0).with_changes(contact=restitution_law(law, 0.5))
    result = simulate(scene, 30.0)
    onsets = [v for _, v in result.contacts["contact"].onsets]
    assert min(onsets) < 1e-9 and sum(v < 1e-3 for v in onsets) >= 5, onsets
    assert np.all(np.isfinite(result.contact_force)) and np.all(result.contact_force >= 0.0)
    assert np.max(np.abs(result.energy_error())) < 5e-6 * result.kinetic_energy_history[0]


# ------------------------------------------------------------------------------------------ engine = reference
LAW_SCENES = sorted(n for n in list_scenes() if n.startswith("contact_"))
HARD_LAW_SCENES = {
    "i-flores-e0.05-gap20mm": model_i(1000.0, 0.02).with_changes(
        contact=Contact(gap=0.02, stiffness=2.1e8, exponent=1.3, law="flores", restitution=0.05)),
    "i-exact-e0.99": model_i(1000.0, 0.0).with_changes(contact=restitution_law("exact-restitution", 0.99)),
    "ii-gonthier-e0.05-m100": model_ii(100.0, 0.0).with_changes(contact=restitution_law("gonthier", 0.05)),
    "ii-lankarani-e0.99-10x": model_ii(1000.0, 0.0).with_changes(contact=restitution_law("lankarani-nikravesh", 0.99),
                                                                  **{"firing.muzzle_velocity": 5640.0}),
}


@pytest.mark.parametrize("name", LAW_SCENES)
def test_every_law_agrees_with_the_reference(agrees_with_reference, name):
    """Model (ii), m = 1000 kg, gap 0, with each law (the shipped examples): the README's guarantee."""
    agrees_with_reference(load_scene(scene_path(name)), 3.0, "standard")


@pytest.mark.parametrize("name", list(HARD_LAW_SCENES))
def test_hard_restitution_cases_agree_with_the_reference(agrees_with_reference, name):
    """Restitution 0.05 and 0.99, a light absorber, ten times the firing velocity."""
    agrees_with_reference(HARD_LAW_SCENES[name], 3.0, "standard")


@pytest.mark.slow
@pytest.mark.parametrize("accuracy", ["draft", "standard", "reference"])
@pytest.mark.parametrize("name", LAW_SCENES + list(HARD_LAW_SCENES))
def test_every_law_agrees_with_the_reference_at_every_preset(agrees_with_reference, name, accuracy):
    scene = HARD_LAW_SCENES[name] if name in HARD_LAW_SCENES else load_scene(scene_path(name))
    agrees_with_reference(scene, 10.0, accuracy)


# ------------------------------------------------------------------------------------------ bad input
BAD_CONTACTS = [
    ("unknown-law", "absorber.0.contact.law", "hertzian", "absorber.0.contact.law", "did you mean 'hertz'"),
    ("missing-restitution", "absorber.1.contact.restitution", "<delete>", "absorber.1.contact.restitution", "missing"),
    ("field-of-another-law", "absorber.1.contact.damping_factor", 0.6, "absorber.1.contact.damping_factor",
     "not a field of law 'flores'"),
    ("kelvin-voigt-exponent", "absorber.1.contact.law", "kelvin-voigt", "absorber.1.contact.exponent",
     "not a field of law 'kelvin-voigt'"),
    ("restitution-zero", "absorber.1.contact.restitution", 0.0, "absorber.1.contact.restitution", "in (0, 1]"),
    ("restitution-above-one", "absorber.1.contact.restitution", 1.5, "absorber.1.contact.restitution",
     "in (0, 1]"),
    ("restitution-string", "absorber.1.contact.restitution", "half", "absorber.1.contact.restitution",
     "must be a number"),
    ("negative-floor", "absorber.1.contact.minimum_impact_velocity", -1.0,
     "absorber.1.contact.minimum_impact_velocity", "> 0 m/s"),
    ("floor-of-hunt-crossley", "absorber.0.contact.minimum_impact_velocity", 0.01,
     "absorber.0.contact.minimum_impact_velocity", "not a field of law 'hunt-crossley'"),
    ("negative-damping", "absorber.1.contact.damping", -1.0, "absorber.1.contact.damping", ">= 0 N s/m"),
    ("zero-stiffness", "absorber.0.contact.stiffness", 0.0, "absorber.0.contact.stiffness", "> 0"),
    ("unknown-key", "absorber.1.contact.restitusion", 0.5, "absorber.1.contact.restitusion",
     "did you mean 'restitution'"),
    # beyond double precision (DESIGN.md, "Bad input beyond the ranges"), flores: chi = 8 (1 - e) / (5 e)
    ("chi-overflows", "absorber.1.contact.restitution", 5e-324, "absorber.1.contact.restitution",
     "restitution factor chi = inf"),
    # chi = 1.6e306 is finite, chi / 1e-3 m/s = 1.6e309 is not
    ("chi-over-floor-overflows", "absorber.1.contact.restitution", 1e-306, "absorber.1.contact.restitution",
     "chi / minimum_impact_velocity"),
    # chi = 1.6 at e = 0.5: 1.6 / 1e-320 overflows
    ("floor-underflows", "absorber.1.contact.minimum_impact_velocity", 1e-320,
     "absorber.1.contact.minimum_impact_velocity", "chi / minimum_impact_velocity"),
    ("exact-restitution-bracket", "absorber.1.contact", {"gap": 0.02, "law": "exact-restitution", "stiffness": 2.1e8,
                                                        "exponent": 1.3, "restitution": 5e-324},
     "absorber.1.contact.restitution", "1 / restitution"),
    ("kelvin-voigt-relaxation-time", "absorber.1.contact", {"gap": 0.02, "law": "kelvin-voigt",
                                                           "stiffness": 5e-324, "damping": 1e3},
     "absorber.1.contact.stiffness", "relaxation time c / k"),
]


@pytest.mark.parametrize("path, value, key, text", [c[1:] for c in BAD_CONTACTS], ids=[c[0] for c in BAD_CONTACTS])
def test_bad_contact_fields_are_one_line_errors_naming_the_key(bad_input, v2_mapping, changed, path, value, key, text):
    bad_input(changed(v2_mapping, path, value), key, text)


def test_a_law_of_version_2_in_a_version_1_file_says_so(bad_input, v1_mapping, changed):
    bad_input(changed(v1_mapping, "contact.law", "flores"), "contact.law", "needs a version-2 scene")


def test_python_tables_are_checked_like_files():
    from mbs_models import SceneError

    with pytest.raises(SceneError, match=r"contact\.restitution: missing: law 'gonthier' needs it"):
        Contact(gap=0.0, stiffness=1e8, exponent=1.3, law="gonthier")
    with pytest.raises(SceneError, match=r"conventions\.literal_lambda_sign"):
        model_ii().with_changes(contact=restitution_law("flores", 0.5), conventions=Conventions(literal_lambda_sign=True))
    assert math.isfinite(restitution_law("exact-restitution", 0.5).restitution_factor)


def test_fixed_step_solvers_accept_restitution_laws():
    result = simulate(free_impact(restitution_law("exact-restitution", 0.5)), 0.1,
                      SolverSettings(solver="RK44", step=2e-5))
    e = (result.absorber_velocity[-1] - result.barrel_velocity[-1]) / IMPACT_VELOCITY
    assert e == pytest.approx(0.5, abs=1e-3)


@pytest.mark.parametrize("law, conventions", [(law, None) for law in sorted(CONTACT_LAWS)] + [
    ("hunt-crossley", Conventions(compression_only=True)), ("hunt-crossley", Conventions(literal_lambda_sign=True))])
def test_python_force_function_is_python_force(law, conventions):
    """The early stop's tracker evaluates contacts through python_force_function: the same float as
    python_force at every state, also after the onset capture changed v-."""
    from mbs_models.engine.mechanism import Mechanism

    contact = {"hunt-crossley": hunt_crossley(0.6), "hertz": Contact(gap=0.0, stiffness=2.1e8, exponent=1.3, law="hertz"),
               "kelvin-voigt": Contact(gap=0.0, stiffness=4e7, law="kelvin-voigt", damping=8e4)}.get(
        law, restitution_law(law, 0.5) if law in RESTITUTION_LAWS else None)
    scene = model_ii(500.0, 0.002).with_changes(contact=contact, conventions=conventions or Conventions())
    connector = Mechanism(scene).contacts[0]
    force = connector.python_force_function()
    for lam_rate in (0.3, 0.01):
        if connector.capture is not None:
            connector.capture.observe(0.0, 0.0, lam_rate)  # apart, approaching at lam_rate: v- changes
        for d in np.linspace(-0.01, 0.02, 31):
            for rate in np.linspace(-5.0, 5.0, 41):
                assert force(float(d), float(rate)) == connector.python_force(float(d), float(rate))
    assert any(force(0.012, r) > 0.0 for r in (-1.0, 0.0, 1.0))  # the states include contact
