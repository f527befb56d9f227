"""Which contact episodes are impacts (mbs_models/results/postprocess.py: ``impact_mask``; DESIGN.md "Outputs every
scene gets"): an episode is an impact when its peak force rises above the force the contact held at rest when it
began by more than the impact threshold -- 0 for an episode that begins inside the window, the static force of the
initial penetration for one going on at t = 0.  A preload's hold on its stop (no impact) and the landings on it are
tested with the recuperator (tests/elements/test_recuperator.py), the rule on hand-made episodes in
test_refinement.py, engine against reference on every shipped scene in tests/validation/studies/test_compare.py.
"""

from __future__ import annotations

from mbs_models import simulate
from validation.studies.hard_cases import HARD_CASES_BY_NAME

THRESHOLD = 1000.0  # N, the default impact threshold


def test_an_initial_interference_approached_at_t0_stays_an_impact():
    """The hard case ``ii-interference`` (the paper's literal gap sign): the barrel starts 1 mm into the absorber
    at v0 = 0.69 m/s towards it.  At t = 0 Hunt-Crossley's force ``k p^n (1 + lambda v0)`` already exceeds the
    static ``k p^n`` (26.4 kN) by ``k p^n lambda v0`` = 10.9 kN, more than the threshold: an impact from t = 0."""
    case = HARD_CASES_BY_NAME["ii-interference"]
    scene = case.scene
    result = simulate(scene, case.end_time)
    law, v0 = scene.contact, scene.initial_velocity
    static = law.stiffness * law.gap ** law.exponent
    assert static * law.damping_factor * v0 > 10 * THRESHOLD
    first = result.impacts[0]
    assert first.start == 0.0 and first.peak_force - static > 10 * THRESHOLD


def test_samples_whose_energies_overflow_are_a_simulation_error_without_warnings():
    """Finite samples of a diverged solve: the barrel at 1e200 m/s (x = v t).  Its kinetic energy
    M v^2 / 2 = 2800 x 1e400 J is beyond double precision: a SimulationError naming it, no numpy warning, never an
    inf in the results.  At 1e100 m/s (2.8e203 J) the same samples are analysed."""
    import warnings

    import numpy as np
    import pytest

    from mbs_models import SimulationError, simplified_model
    from mbs_models.engine.mechanism import Mechanism
    from mbs_models.results.postprocess import analyse
    from mbs_models.results.samples import Samples

    mechanism = Mechanism(simplified_model())
    t = np.array([0.0, 1e-3, 2e-3])

    def samples(speed: float) -> Samples:
        return Samples(t, {"barrel": speed * t}, {"barrel": np.full(3, speed)}, {"barrel": np.zeros(3)})

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(SimulationError, match="kinetic energy of barrel is beyond double precision") as info:
            analyse(mechanism, samples(1e200), THRESHOLD)
        assert "\n" not in str(info.value)
        metrics = analyse(mechanism, samples(1e100), THRESHOLD)
    assert np.isclose(metrics.energies.kinetic["barrel"][-1], 2.8e203, rtol=1e-15, atol=0.0)


def test_a_non_finite_quantity_is_named_and_finite_ones_pass():
    """check_representable looks at every quantity in one pass and names the first one that is not finite, in its
    order: a contact's force before the energies; and the energy balance's sum, which overflows although every
    history in it is finite (kinetic 1e308 J + stored 1e308 J)."""
    from dataclasses import replace

    import numpy as np
    import pytest

    from mbs_models import SimulationError, model_ii
    from mbs_models.results.energies import Energies
    from mbs_models.results.postprocess import analyse, check_representable

    result = simulate(model_ii(), 0.05)
    metrics = analyse(result.mechanism, result.samples, THRESHOLD)
    check_representable(metrics, result.samples)  # all finite: passes
    n = len(result.samples.time)
    contact = next(iter(metrics.contacts.values()))
    broken = replace(metrics, contacts={contact.name: replace(contact, force=np.full(n, np.inf))},
                     energies=replace(metrics.energies, kinetic={"barrel": np.full(n, np.nan)}))
    with pytest.raises(SimulationError, match=f"the force of {contact.name} is beyond double precision"):
        check_representable(broken, result.samples)
    huge = Energies(kinetic={"barrel": np.full(n, 1e308)}, stored={"recoil_spring": np.full(n, 1e308)},
                    dissipated={}, work={})
    with pytest.raises(SimulationError, match=r"the sum of the energies \(kinetic \+ stored"):
        check_representable(replace(metrics, energies=huge), result.samples)
