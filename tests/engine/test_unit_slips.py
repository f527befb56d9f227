"""mbs_models/engine/unit_slips.py: every unit slip of a scene (implausible magnitudes and contacts that can
never close) as a UnitWarning naming its key, from simulate, run_sweep and optimise; none for the shipped
scenes and the paper's models; nothing clamped."""

from __future__ import annotations

import warnings

import pytest

from mbs_models import load_scene, model_i, model_ii, simplified_model, simulate
from mbs_models.engine.unit_slips import grid_unit_slips, unit_slips, warn_unit_slips
from mbs_models.errors import UnitWarning
from mbs_models.scenes import list_scenes, scene_path


def test_both_sources_are_found_with_their_keys():
    tonnes_and_mm = model_ii(1000.0, 40.0).with_changes(**{"barrel.mass": 5.6})
    assert [f.key for f in unit_slips(tonnes_and_mm)] == ["barrel.mass", "absorber.contact.gap"]


def test_simulate_warns_naming_the_key_at_the_callers_line_and_clamps_nothing():
    scene = simplified_model().with_changes(**{"barrel.mass": 5.6})
    with pytest.warns(UnitWarning, match=r"^barrel\.mass = 5\.6 kg gives a recoil velocity") as caught:
        result = simulate(scene, 0.05, "draft")
    assert [w.filename for w in caught if w.category is UnitWarning] == [__file__]  # the caller's line
    assert result.scene.barrel.mass == 5.6
    assert result.barrel_velocity[0] == pytest.approx(6.86 * 564.0 / 5.6, rel=1e-12)  # as given, not clamped


def test_simulate_warns_of_a_gap_in_millimetres():
    with pytest.warns(UnitWarning, match=r"^absorber\.contact\.gap = 40 m is beyond"):
        result = simulate(model_ii(1000.0, 40.0), 0.5, "draft")
    assert result.peak_contact_force == 0.0


def test_the_shipped_scenes_and_the_papers_models_give_no_warning():
    scenes = [load_scene(scene_path(name)) for name in list_scenes()]
    scenes += [model(mass, gap) for model in (model_i, model_ii) for mass in (100.0, 500.0, 1000.0)
               for gap in (0.0, 0.01, 0.04, 0.08, 0.12)] + [simplified_model()]
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnitWarning)
        for scene in scenes:
            assert warn_unit_slips(scene) == [], scene.name


def test_a_grid_is_judged_at_its_corners():
    base = model_ii()
    [found] = grid_unit_slips(base, {"absorber.mass": [100.0, 1000.0], "contact.gap": [0.0, 0.02, 40.0]})
    assert found.key == "absorber.contact.gap" and "= 40 m" in found.message()
    assert grid_unit_slips(base, {"contact.gap": [0.0, 0.12]}) == []
    # a swept key overrides the base scene's slip at every point: nothing to warn of
    assert unit_slips(base.with_changes(**{"barrel.mass": 5.6}))
    assert grid_unit_slips(base.with_changes(**{"barrel.mass": 5.6}), {"barrel.mass": [5000.0, 6000.0]}) == []
    # a key without numbers: its first value
    assert grid_unit_slips(base, {"contact.law": ["hunt-crossley", "hertz"], "barrel.mass": [5.6, 5600.0]})


def test_run_sweep_warns_before_its_first_point(tmp_path, monkeypatch):
    from mbs_models import run_sweep
    import mbs_models.studies.point as point

    def refuse(*args, **kwargs):
        raise AssertionError("a point ran")

    monkeypatch.setattr(point, "evaluate_batch", refuse)
    with pytest.warns(UnitWarning, match=r"^absorber\.contact\.gap = 40 m"):
        with pytest.raises(AssertionError, match="a point ran"):
            run_sweep(model_ii(), {"contact.gap": [0.0, 40.0]}, workers=1, progress=False)


def test_optimise_warns_before_its_first_point(monkeypatch):
    from mbs_models import optimise
    import scipy.optimize

    def refuse(*args, **kwargs):
        raise AssertionError("the optimiser ran")

    monkeypatch.setattr(scipy.optimize, "differential_evolution", refuse)
    with pytest.warns(UnitWarning, match=r"^absorber\.contact\.gap = 40 m"):
        with pytest.raises(AssertionError, match="the optimiser ran"):
            optimise(model_ii(), {"contact.gap": (0.0, 40.0)}, "max_barrel_displacement", workers=1)


def test_kept_findings_equal_those_checked_anew_and_warn_at_every_call():
    """The findings kept per scene (``unit_slips``) are those computed anew (``_unit_slips``), for equal scenes
    built apart too, and every ``simulate`` of a kept scene still warns."""
    from mbs_models.engine import unit_slips as module

    scenes = [model_ii(1000.0, 40.0).with_changes(**{"barrel.mass": 5.6}), model_ii(1000.0, 0.04), model_i(100.0, 80.0)]
    for scene in scenes + [model_ii(1000.0, 40.0).with_changes(**{"barrel.mass": 5.6})]:  # the last: equal, not same
        first, again, fresh = unit_slips(scene), unit_slips(scene), module._unit_slips(scene)
        assert first == again == fresh
        assert [f.message() for f in again] == [f.message() for f in fresh]
    assert module._cached_unit_slips.cache_info().hits >= 4
    kept = unit_slips(scenes[0])
    kept.clear()  # a caller's list: the kept findings are not changed through it
    assert unit_slips(scenes[0]) == module._unit_slips(scenes[0])
    for _ in range(2):
        with pytest.warns(UnitWarning, match=r"^absorber\.contact\.gap = 80 m is beyond"):
            simulate(model_i(100.0, 80.0), 0.05, "draft")
