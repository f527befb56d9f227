"""Property-based tests (hypothesis) over the scene parameter space.

For any scene in the guaranteed ranges (see the README, "What is guaranteed"):

* the engine returns finite results (no NaN, no SimulationError at the presets);
* the contact force is never negative and is exactly 0 whenever Hunt-Crossley would pull;
* energy is never created: kinetic + stored energy never exceeds the initial energy, dissipated
  energies never decrease (both up to the preset's energy tolerance);
* the engine agrees with the scipy reference within the tolerances of tests/test_hard_cases.py.

The default run draws :data:`FAST_EXAMPLES` scenes at ``standard`` accuracy; ``-m slow`` draws more,
at every preset.  Both are derandomized (CI sees the same scenes every time).  Minimal failing
scenes found while developing are kept as ``@example`` regression cases.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from mbs_models import Scene, model_i, model_ii, simulate
from validation.studies.guarantee import (LIGHT_UNDAMPED_BOUNDS, TOLERANCES, errors_against_reference,
                                           light_undamped_absorber, physical_violations, reference_for, violations)

# random gaps may lie beyond the free-recoil travel (the warning is tested elsewhere)
pytestmark = pytest.mark.filterwarnings("ignore:absorber.*beyond the barrel's free-recoil travel:mbs_models.errors.UnitWarning")

#: Simulated time per example, s: covers the first impacts and the barrel's maximum.
END_TIME = 1.0
FAST_EXAMPLES = 25
SLOW_EXAMPLES = 40

#: The guaranteed ranges (the README states the same).
MASS_RANGE = (1.0, 20000.0)            # absorber mass, kg
GAP_RANGE = (0.0, 0.3)                 # m; beyond ~0.22 m nothing is ever touched
STIFFNESS_RANGE = (1e6, 1e12)          # k_c, N/m^n
EXPONENT_RANGE = (1.0, 2.0)            # n_c
LAMBDA_RANGE = (0.0, 100.0)            # s/m
MUZZLE_VELOCITY_RANGE = (56.4, 5640.0)  # m/s: 0.1x to 10x the paper's 564 m/s


def _log_uniform(low: float, high: float):
    return st.floats(math.log10(low), math.log10(high)).map(lambda x: 10.0 ** x)


@st.composite
def scenes(draw) -> Scene:
    """A model (i) or (ii) scene with every contact and absorber parameter drawn from its range."""
    factory = draw(st.sampled_from([model_i, model_ii]))
    mass = draw(_log_uniform(*MASS_RANGE))
    gap = draw(st.one_of(st.just(0.0), st.floats(*GAP_RANGE)))
    lam = draw(st.one_of(st.just(0.0), _log_uniform(0.01, LAMBDA_RANGE[1])))
    changes = {
        "contact.stiffness": draw(_log_uniform(*STIFFNESS_RANGE)),
        "contact.exponent": draw(st.floats(*EXPONENT_RANGE)),
        "contact.damping_factor": lam,
        "firing.muzzle_velocity": draw(_log_uniform(*MUZZLE_VELOCITY_RANGE)),
    }
    if draw(st.booleans()):
        changes["absorber.damping"] = draw(st.sampled_from([0.0, 367.5, 36750.0]))
    if draw(st.integers(0, 3)) == 0:
        changes["recoil_damper.recoil"] = changes["recoil_damper.counter_recoil"] = 0.0
    return factory(mass, gap).with_changes(**changes)


def check_scene(scene: Scene, accuracy: str, end_time: float = END_TIME) -> None:
    """The properties of the module docstring; a scene in the stated exception (a light undamped absorber) is held
    to the exception's bounds at the presets it names."""
    result = simulate(scene, end_time, accuracy)  # a SimulationError fails the property
    tolerance = TOLERANCES[accuracy]["energy"]
    problems = physical_violations(result, tolerance)
    assert not problems, problems
    e0 = result.kinetic_energy_history[0] + result.stored_energy_history[0]
    mechanical = result.kinetic_energy_history + result.stored_energy_history
    assert np.max(mechanical) <= e0 * (1.0 + tolerance), "energy created"
    ref = reference_for(scene, end_time, (), accuracy)
    bounds = LIGHT_UNDAMPED_BOUNDS.get(accuracy) if light_undamped_absorber(scene) else None
    problems = violations(errors_against_reference(result, ref, TOLERANCES[accuracy]["time"]), accuracy, bounds)
    assert not problems, (problems, scene)


FAST = settings(max_examples=FAST_EXAMPLES, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow])
SLOW = settings(max_examples=SLOW_EXAMPLES, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow])


# Minimal failing scenes found by the slow run, kept as regression cases:
#: a 4.4 kg absorber bouncing to rest on the barrel: the reference separates its last bounce from the
#: following persistent contact by 2 us, which no preset resolves (episodes closer than the time
#: tolerance count as one)
BOUNCING_TO_REST = model_ii(4.367332460522914, 0.21501808279806872).with_changes(**{
    "firing.muzzle_velocity": 822.0226934082997, "contact.stiffness": 58095350520.579124,
    "contact.exponent": 1.134897281128901, "contact.damping_factor": 0.1})
#: the same pressed on with n = 1, lambda = 1: Exudyn's DOPRI5 stalled at t = 0.5707 s (standard and
#: reference), where the velocities pass -atol/rtol = -0.01 m/s and Exudyn's error scale vanishes;
#: simulate() now re-solves such stalls with absolute error control
STALLING = BOUNCING_TO_REST.with_changes(**{"contact.exponent": 1.0, "contact.damping_factor": 1.0})
#: a 1 kg absorber on a soft linear contact, nothing damped but the absorber: the same stall at the
#: reference preset (t = 0.5762 s), and the last bounce's maximum velocity drew the reference's
#: attention to v tolerances
LIGHT_UNDAMPED = model_ii(1.0, 0.0).with_changes(**{
    "recoil_damper.recoil": 0.0, "recoil_damper.counter_recoil": 0.0, "firing.muzzle_velocity": 100.0,
    "contact.stiffness": 1e8, "contact.exponent": 1.0, "contact.damping_factor": 0.0, "absorber.damping": 0.0})

#: an undamped 1-kg absorber chattering 351 times in 1 s, the last impact cut off by the window's end on its
#: rise (its force there is no peak: compared on its start only)
CHATTERING = model_ii(1.0, 0.0).with_changes(**{
    "recoil_damper.recoil": 0.0, "recoil_damper.counter_recoil": 0.0, "firing.muzzle_velocity": 100.0,
    "contact.stiffness": 1e9, "contact.exponent": 1.5, "contact.damping_factor": 0.0, "absorber.damping": 0.0})


#: Found by hypothesis (only when the set of imported modules changed its draws, see conftest.py): an undamped
#: 1-kg absorber on a stiff quadratic contact chatters ~30 times in 1 s with penetrations of ~0.4 mm: at `standard`
#: its peak contact force is off by 3.5e-5 (the guarantee for peak forces: 2e-5).  A scan of its neighbours (model
#: (ii), 1 kg, absorber and contact undamped, recoil damper off and on, k_c 1e8 to 1e12, n_c 1 to 2, 56 to 564 m/s:
#: 45 scenes) found worse: peak forces 4.8e-4, impact peaks 4.9e-4, impact times 3.6e-4 s (k_c 1e12, n_c 1.5, 564
#: m/s, the paper's recoil damper), absorber velocities 5.9e-5 (the same at 56.4 m/s, no damper); ten kilograms
#: undamped stay within the guarantee.  The stated exception (validation.studies.guarantee.LIGHT_UNDAMPED_BOUNDS;
#: docs/validation/checks.md), pinned below on the scan's worst scenes.
STIFF_CHATTER = CHATTERING.with_changes(**{"contact.stiffness": 1e10, "contact.exponent": 2.0})
#: (STIFF_CHATTER itself meets the guarantee since issue #24's maximum steps: the scan at those steps, the same 45
#: scenes, found the same worst errors, 4.8e-4 / 4.9e-4 / 3.6e-4 s / 5.0e-5, and every scene within the stated bounds.)
LIGHT_UNDAMPED_WORST = {
    "k1e12-n1.5-v56": CHATTERING.with_changes(**{"contact.stiffness": 1e12, "firing.muzzle_velocity": 56.4}),
    "k1e10-n1.5-v564": CHATTERING.with_changes(**{"contact.stiffness": 1e10, "firing.muzzle_velocity": 564.0}),
    "damped-recoil-k1e12-n1.5-v564": model_ii(1.0, 0.0).with_changes(**{
        "firing.muzzle_velocity": 564.0, "contact.stiffness": 1e12, "contact.exponent": 1.5,
        "contact.damping_factor": 0.0, "absorber.damping": 0.0}),
    "damped-recoil-k1e10-n1.5-v56": model_ii(1.0, 0.0).with_changes(**{
        "firing.muzzle_velocity": 56.4, "contact.stiffness": 1e10, "contact.exponent": 1.5,
        "contact.damping_factor": 0.0, "absorber.damping": 0.0}),
}


def _outside_the_stated_exception(scene) -> bool:
    """The random scenes leave out the stated exception (its own tests below hold it to its stated bounds)."""
    return not light_undamped_absorber(scene)


@FAST
@given(scene=scenes().filter(_outside_the_stated_exception))
@example(scene=CHATTERING)
@example(scene=BOUNCING_TO_REST)
@example(scene=LIGHT_UNDAMPED)
def test_random_scenes_standard(scene):
    check_scene(scene, "standard")


@pytest.mark.slow
@pytest.mark.parametrize("accuracy", list(TOLERANCES))
def test_random_scenes_every_preset(accuracy):
    @SLOW
    @given(scene=scenes().filter(_outside_the_stated_exception))
    def run(scene):
        check_scene(scene, accuracy)

    run()


#: The regression scenes at every preset.  Their references are the expensive part (a stiff persistent
#: contact makes scipy's explicit DOP853 take 3-60 s per simulated second), so the two scenes whose
#: rtol 1e-12 reference takes minutes are checked at draft and standard only; the stall itself is
#: covered at the reference preset by tests/test_stability.py::test_stalled_step_size_is_re_solved.
REGRESSIONS = {"bouncing-to-rest": (BOUNCING_TO_REST, ("draft", "standard")),
               "stalling": (STALLING, ("draft", "standard")),
               "light-undamped": (LIGHT_UNDAMPED, ("draft", "standard", "reference"))}


@pytest.mark.slow
@pytest.mark.parametrize("name, accuracy", [(name, accuracy) for name, (_, presets) in REGRESSIONS.items()
                                            for accuracy in presets])
def test_regression_scenes_every_preset(name, accuracy):
    check_scene(REGRESSIONS[name][0], accuracy)




@pytest.mark.parametrize("name", list(LIGHT_UNDAMPED_WORST))
def test_light_undamped_absorbers_are_the_stated_exception(name):
    """The worst scenes measured of the stated exception are within its bounds at `standard`, and everything else
    within the guarantee; the scene is in the exception (its predicate) and the guarantee alone would refuse it."""
    scene = LIGHT_UNDAMPED_WORST[name]
    assert light_undamped_absorber(scene)
    result = simulate(scene, END_TIME, "standard")
    errors = errors_against_reference(result, reference_for(scene, END_TIME, accuracy="standard"),
                                      TOLERANCES["standard"]["time"])
    assert violations(errors, "standard", LIGHT_UNDAMPED_BOUNDS["standard"]) == [], errors
    assert violations(errors, "standard") != [], errors  # an exception indeed (else the statement is stale)
    assert physical_violations(result, TOLERANCES["standard"]["energy"]) == []


#: The draft scan's worst scenes (validation.studies.guarantee.LIGHT_UNDAMPED_BOUNDS["draft"]).
LIGHT_UNDAMPED_WORST_DRAFT = {
    "k1e12-n1.5-v56": LIGHT_UNDAMPED_WORST["k1e12-n1.5-v56"],
    "k1e12-n1.5-v564": CHATTERING.with_changes(**{"contact.stiffness": 1e12, "firing.muzzle_velocity": 564.0}),
    "k1e12-n1.5-v100": CHATTERING.with_changes(**{"contact.stiffness": 1e12}),  # an impact on one side only
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(LIGHT_UNDAMPED_WORST_DRAFT))
def test_light_undamped_absorbers_are_the_stated_exception_at_draft(name):
    """The draft scan's worst scenes of the exception are within its draft bounds, and beyond the plain guarantee."""
    scene = LIGHT_UNDAMPED_WORST_DRAFT[name]
    assert light_undamped_absorber(scene)
    errors = errors_against_reference(simulate(scene, END_TIME, "draft"), reference_for(scene, END_TIME, accuracy="draft"),
                                      TOLERANCES["draft"]["time"])
    assert violations(errors, "draft", LIGHT_UNDAMPED_BOUNDS["draft"]) == [], errors
    assert violations(errors, "draft") != [], errors


def test_the_exception_is_a_light_undamped_absorber_on_the_ground():
    assert light_undamped_absorber(CHATTERING) and light_undamped_absorber(LIGHT_UNDAMPED)
    assert not light_undamped_absorber(CHATTERING.with_changes(**{"contact.damping_factor": 0.1}))
    assert not light_undamped_absorber(CHATTERING.with_changes(**{"absorber.damping": 1.0}))
    assert light_undamped_absorber(CHATTERING.with_changes(**{"recoil_damper.counter_recoil": 1.0}))
    assert not light_undamped_absorber(model_ii(10.0, 0.0).with_changes(**{
        "recoil_damper.recoil": 0.0, "recoil_damper.counter_recoil": 0.0, "contact.damping_factor": 0.0,
        "absorber.damping": 0.0}))
    assert not light_undamped_absorber(model_i(1.0, 0.0).with_changes(**{
        "recoil_damper.recoil": 0.0, "recoil_damper.counter_recoil": 0.0, "contact.damping_factor": 0.0,
        "absorber.damping": 0.0}))


@pytest.mark.slow
def test_light_chattering_absorber_at_reference_is_within_the_guarantee():
    result = simulate(STIFF_CHATTER, END_TIME, "reference")
    errors = errors_against_reference(result, reference_for(STIFF_CHATTER, END_TIME, accuracy="reference"))
    assert violations(errors, "reference") == [], errors
