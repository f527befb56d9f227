"""The run policy (mbs_models.engine.run_policy): the arguments of a run and why it ended."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from mbs_models import SceneError, StopReason, model_ii, simulate
from mbs_models.engine.run_policy import RunPolicy, stop_reason


def _solve(final: bool, rest: bool):
    tracker = SimpleNamespace(done=True) if final else None
    return SimpleNamespace(tracker=tracker, rest=SimpleNamespace(time=12.5) if rest else None)


#: (re-solved, proven final, at rest, early stop asked for, bounds exist) -> the reason, as simulate's docstring
#: and the README say: a re-solve is the energy check's; an early stop that stood is "metrics_final"; a run that
#: came to rest says so even where the early stop had no bound; asked for without bounds: "no energy bound".
CASES = [((True, False, False, False, True), StopReason.ENERGY_CHECK),
         ((True, False, True, False, True), StopReason.ENERGY_CHECK),
         ((False, True, False, True, True), StopReason.METRICS_FINAL),
         ((False, False, True, True, False), StopReason.AT_REST),
         ((False, False, True, False, True), StopReason.AT_REST),
         ((False, False, False, True, False), StopReason.NO_ENERGY_BOUND),
         ((False, False, False, True, True), StopReason.END_TIME),
         ((False, False, False, False, True), StopReason.END_TIME)]


@pytest.mark.parametrize("case, expected", CASES)
def test_why_a_run_ended(case, expected):
    re_solved, final, rest, asked, bounded = case
    policy = SimpleNamespace(requested=("impacts",) if asked else (), early_stop=asked and bounded)
    assert stop_reason(policy, _solve(final, rest), re_solved) is expected


def test_the_policy_of_the_arguments():
    policy = RunPolicy.of(model_ii(), 10, "standard", None, 1000, ["impacts"], True)
    assert policy.end_time == 10.0 and type(policy.end_time) is float and policy.impact_threshold == 1000.0
    assert policy.requested == ("impacts",) and policy.early_stop  # model (ii) dissipates: bounds exist
    assert policy.rest_tolerance == policy.settings.absolute_tolerance
    assert RunPolicy.of(model_ii(), 10.0, "standard", None, 1000.0, (), False).rest_tolerance is None
    with pytest.raises(SceneError) as info:
        RunPolicy.of(model_ii(), 10.0, "standard", None, 1000.0, (), "yes")
    assert info.value.key == "stop_at_rest"


def test_too_many_absorbers_are_refused_before_anything_else(tmp_path, recwarn):
    from mbs_models import load_scene
    from mbs_models.engine.simulation import MAX_ABSORBERS

    absorbers = "".join(f'[[absorber]]\nname = "a{i}"\nmass = 10.0\nmount = "ground"\nstiffness = 8100.0\n'
                        f'damping = 2205.0\n[absorber.contact]\ngap = 5.0\nstiffness = 2.1e8\nexponent = 1.3\n'
                        f'damping_factor = 0.6\n' for i in range(MAX_ABSORBERS + 1))
    (tmp_path / "many.toml").write_text('version = 2\n[barrel]\nmass = 5600.0\n[firing]\nprojectile_mass = 6.86\n'
                                        'muzzle_velocity = 564.0\n[recoil_spring]\nstiffness = 27500.0\n' + absorbers)
    scene = load_scene(tmp_path / "many.toml")
    with pytest.raises(SceneError) as info:
        simulate(scene, 1.0)
    assert info.value.key == "absorber" and f"{MAX_ABSORBERS + 1} absorbers" in info.value.message
    assert not recwarn.list  # refused before the unit-slip warnings (5 m gaps never close) are worked out


@pytest.mark.parametrize("name, key", [("breech_pulse", "firing.pulse.times"), ("burst", "burst.shots")])
def test_a_run_split_into_too_many_segments_is_refused_naming_the_key(name, key, monkeypatch):
    import mbs_models.engine.run_policy as engine
    from mbs_models import load_scene
    from mbs_models.scenes import scene_path

    monkeypatch.setattr(engine, "MAX_SEGMENTS", 2)  # the pulse has 4 points, the burst 3 shots
    with pytest.raises(SceneError) as info:
        simulate(load_scene(scene_path(name)), 3.0)
    assert info.value.key == key and "segments" in info.value.message
