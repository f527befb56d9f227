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
