"""Hard corners of the scene space: the engine at every accuracy preset against the scipy reference.

Each case checks: finite results; a contact force that is never negative and is exactly 0 whenever the
Hunt-Crossley term would pull (restitution with ``1 + lambda p' < 0``); the energy balance (kinetic +
stored + dissipated = initial energy) within :data:`TOLERANCES`; the metrics and the dissipated
energies against :func:`validation.reference.solve_reference`; and the impacts list against the
reference's contact episodes (no contact missed, none invented).

The fast subset (:data:`FAST_CASES`, ``standard`` accuracy) runs by default; the full grid at the three
presets is marked ``slow``.  The tolerances are what the grid measured, with a margin (the README's
"What is guaranteed" section states them); tests/test_properties.py checks the same tolerances on
random scenes.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from mbs_models import model_ii, simulate
from mbs_models.engine.accuracy import ACCURACY_PRESETS
from validation.studies.hard_cases import FAST_CASES, FAST_END_TIME, HARD_CASES, HARD_CASES_BY_NAME, HardCase
from validation.studies.guarantee import (TOLERANCES, errors_against_reference, physical_violations, reference_for,
                                           violations)

def assert_physical(result, energy_tolerance: float = 1e-3) -> None:
    """No unphysical result (see :func:`validation.studies.guarantee.physical_violations`)."""
    problems = physical_violations(result, energy_tolerance)
    assert not problems, problems


def assert_within(errors: dict, accuracy: str, context=None) -> None:
    """Every error of :func:`errors_against_reference` within the preset's :data:`TOLERANCES`."""
    problems = violations(errors, accuracy)
    assert not problems, (problems, errors, context)


def check_case(case: HardCase, accuracy: str, end_time: float | None = None) -> dict:
    end_time = case.end_time if end_time is None else end_time
    result = simulate(case.scene, end_time, accuracy)
    assert_physical(result, TOLERANCES[accuracy]["energy"])
    reference_end = min(end_time, case.reference_end_time or end_time)
    ref = reference_for(case.scene, reference_end, tuple(sorted(case.reference_options.items())), accuracy)
    errors = errors_against_reference(result, ref, TOLERANCES[accuracy]["time"])
    assert_within(errors, accuracy, (result.impacts, ref.impacts))
    return errors


@pytest.mark.parametrize("name", FAST_CASES)
def test_hard_case_standard(name):
    check_case(HARD_CASES_BY_NAME[name], "standard", min(FAST_END_TIME, HARD_CASES_BY_NAME[name].end_time))


@pytest.mark.slow
@pytest.mark.parametrize("accuracy", list(TOLERANCES))
@pytest.mark.parametrize("case", HARD_CASES, ids=[case.name for case in HARD_CASES])
def test_hard_case_grid(case, accuracy):
    check_case(case, accuracy)


def test_no_contact_scene_never_reports_a_force():
    result = simulate(model_ii(1000.0, 0.3), 3.0)
    assert result.peak_contact_force == 0.0 and result.impacts == []
    assert result.dissipated_energy["contact"] == 0.0
    assert np.all(result.contact_force == 0.0)


def test_grazing_contact_stepped_over_by_draft_is_resolved():
    """draft's tolerances with a 10 ms max step (the preset's before issue #24) step over a 0.6 ms grazing touch in
    the first solve; simulate re-solves it.  (At the preset's own max step the first solve feels the touch and the
    grazing rule re-solves it: tests/engine/test_stability.py.)"""
    case = HARD_CASES_BY_NAME["graze-stiff"]
    result = simulate(case.scene, case.end_time, replace(ACCURACY_PRESETS["draft"], max_step=1e-2))
    assert result.settings.max_step < 1e-2 / 4, "the re-solve used a smaller max_step"
    ref = reference_for(case.scene, case.end_time, tuple(sorted(case.reference_options.items())))
    assert ref.peak_contact_force > 100.0
    assert result.peak_contact_force == pytest.approx(ref.peak_contact_force, rel=1e-2)


def test_force_clipped_in_restitution_never_pulls():
    """lambda = 100 s/m, model (i): late in restitution 1 + lambda p' < 0 while still penetrated (a few
    samples per impact fall there); the force is then exactly 0, never negative."""
    scene = HARD_CASES_BY_NAME["i-lambda100"].scene
    result = simulate(scene, 3.0)
    lam = scene.contact.damping_factor
    penetration = result.barrel_position - result.absorber_position - scene.contact.gap
    rate = result.barrel_velocity - result.absorber_velocity
    clipped = (penetration > 0) & (1.0 + lam * rate < 0)
    assert clipped.sum() >= 5, "the case must exercise the clipping"
    assert np.all(result.contact_force[clipped] == 0.0)
    assert np.all(result.contact_force >= 0.0)


def test_undamped_scene_conserves_energy():
    scene = HARD_CASES_BY_NAME["ii-undamped"].scene
    result = simulate(scene, 10.0, "reference")
    e0 = scene.initial_kinetic_energy
    total = result.kinetic_energy_history + result.stored_energy_history
    assert np.max(np.abs(total - e0)) < 1e-8 * e0
    assert result.total_dissipated_energy == pytest.approx(0.0, abs=1e-8 * e0)


# ------------------------------------------------------------------------------------------------
# Bad input not covered by tests/test_scene.py and tests/test_cli.py: one line, exit code 2, no
# traceback, nothing written

def _cli(argv, capsys):
    from mbs_models.cli import main

    code = main(argv)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.mark.parametrize("kind", ["invalid-utf8", "directory", "empty", "binary"])
def test_unreadable_scene_files(tmp_path, capsys, kind):
    """Tests run as root, so chmod cannot make a file unreadable: undecodable or wrong kinds instead."""
    path = tmp_path / "scene.toml"
    if kind == "invalid-utf8":
        path.write_bytes(b'name = "caf\xe9"\n[barrel]\nmass = 5600.0\n')
    elif kind == "directory":
        path.mkdir()
    elif kind == "empty":
        path.write_text("")
    else:
        path.write_bytes(bytes(range(256)))
    from mbs_models import SceneError, load_scene

    with pytest.raises(SceneError):
        load_scene(path)
    code, out, err = _cli(["run", str(path)], capsys)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err


@pytest.mark.parametrize("value", ["1e12", "inf", "-inf", "1e-400", "-0.5", "ten"])
def test_absurd_end_times_on_the_command_line(capsys, value):
    code, out, err = _cli(["run", "model_ii", "--end-time", value], capsys)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and "--end-time" in err and "Traceback" not in err


@pytest.mark.parametrize("where", ["file", "under-a-file"])
def test_paper_into_an_unwritable_place_writes_nothing(tmp_path, capsys, where):
    blocker = tmp_path / "blocker"
    blocker.write_text("not a directory")
    out_dir = blocker if where == "file" else blocker / "out"
    before = sorted(p.name for p in tmp_path.iterdir())
    code, out, err = _cli(["paper", "--out", str(out_dir)], capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and "--out" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert blocker.read_text() == "not a directory"


def test_failed_write_leaves_nothing_half_written(tmp_path, monkeypatch):
    """A report that fails while being written (here: the rename, or non-finite JSON) leaves neither the
    target nor a temporary file behind, and an existing target untouched."""
    import os

    from mbs_models import outputs

    target = tmp_path / "table2.json"
    target.write_text("old")

    def broken_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError):
        outputs.atomic_write_text(target, "new")
    monkeypatch.undo()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table2.json"] and target.read_text() == "old"
    with pytest.raises(ValueError):
        outputs.atomic_write_json(tmp_path / "metrics.json", {"peak_contact_force": math.nan})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table2.json"]
