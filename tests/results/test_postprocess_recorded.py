"""The post-processing gives the outputs it gave before it was vectorised (issue #11), on any machine.

``tests/data/postprocess_baseline.json`` was recorded by ``scripts/record_postprocess_baseline.py`` at the
commit before ``mbs_models/results`` changed (named in the file), and checked there bit for bit against the
first recording: for the 19 paper cases (draft, standard), the 36 hard cases and every shipped scene, the
peak support force, every contact's impacts, peak, episodes and onsets, the per-body maximum velocities,
the per-element energies and work, the per-shot outputs, and a summary of every energy, force and
support-force history.  Nothing here is computed by the code under test but the results compared.

The record was made on another machine than the one running this test: numbers are compared within the
tolerances of ``tests/recorded.py`` (each preset's guarantee; counts, names and steps exactly), not to the
bit.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import recorded

from mbs_models import load_scene, model_i, model_ii, simplified_model, simulate
from mbs_models.scenes import scene_path
from validation.studies.hard_cases import FAST_CASES, HARD_CASES_BY_NAME

ROOT = Path(__file__).resolve().parents[2]


_recorder = recorded.load_script("record_postprocess_baseline")

RECORD = json.loads((ROOT / "tests" / "data" / "postprocess_baseline.json").read_text())
BASELINE = RECORD["runs"]

pytestmark = pytest.mark.recorded

#: Shipped scenes whose file changed since the recording: the run uses the file as it was then.
SCENES_AS_RECORDED = {"realistic": ROOT / "tests" / "data" / "scenes_as_recorded" / "realistic.toml"}
#: Shipped scenes whose solve changed by design since the recording, and why: their step sequence differs, so
#: their step counts and histories (sampled by index) are not compared; every post-processed metric still is.
SOLVE_CHANGED = {
    "breech_pulse": "issue #19: the solve is split at every point of the pulse's table (the presets' accuracy "
                    "with tables whose points fall between steps)",
    "realistic": "issue #19: its pulse, as breech_pulse",
}
#: Runs in which a contact held at rest from t = 0 was counted as an impact before issue #19 redefined
#: impacts (DESIGN.md: an episode going on at t = 0 is an impact only if its peak rises above the force it
#: held by the threshold): the runs whose one recorded "impact" starting at t = 0 (on one contact) is dropped.
HELD_AT_START = {"scene/realistic/standard/1000"}


def scene_of(key: str):
    """``(scene, end_time, accuracy, impact_threshold)`` of a recorded run's key."""
    kind, name, accuracy, *rest = key.split("/")
    if kind == "paper":
        if name == "simplified":
            return simplified_model(), 10.0, accuracy, 1000.0
        model, mass, gap = name.split("-")
        factory = model_i if model == "i" else model_ii
        return factory(float(mass[1:]), float(gap[3:]) / 1000.0), 10.0, accuracy, 1000.0
    if kind == "hard":
        case = HARD_CASES_BY_NAME[name]
        return case.scene, case.end_time, accuracy, 1000.0
    return load_scene(SCENES_AS_RECORDED.get(name) or scene_path(name)), 10.0, accuracy, float(rest[0])


def metrics_only(run: dict) -> dict:
    """A run's record without its step count, histories and the largest samples of its histories (its scales:
    the tolerances still use the recorded ones) (:data:`SOLVE_CHANGED`)."""
    def keep(value):
        if isinstance(value, dict):
            return {k: keep(v) for k, v in value.items()
                    if k not in ("steps", "scales") and not recorded.is_summary(v)}
        if isinstance(value, list):
            return [keep(v) for v in value]
        return value
    return keep(run)


def _marks(key: str):
    kind, name, *_ = key.split("/")
    slow = kind == "hard" and name not in FAST_CASES
    return pytest.param(key, marks=pytest.mark.slow) if slow else key


@pytest.mark.parametrize("key", [_marks(k) for k in sorted(BASELINE)])
def test_matches_the_recorded_outputs(key):
    scene, end_time, accuracy, threshold = scene_of(key)
    record = BASELINE[key]
    new = _recorder.record(simulate(scene, end_time, recorded.preset_as_recorded(accuracy), impact_threshold=threshold), accuracy)
    scales = record["scales"]
    if key.split("/")[0] == "scene" and key.split("/")[1] in SOLVE_CHANGED:
        new, record = metrics_only(new), metrics_only(record)
    if key in HELD_AT_START:
        record = without_the_hold(record)
    problems = recorded.differences(new, record, recorded.kind_of_output, accuracy, scales)
    assert not problems, problems[:10]


def without_the_hold(run: dict) -> dict:
    """The record with the impact that starts at t = 0 removed (:data:`HELD_AT_START`): exactly one contact has
    one, in its list and in its element's list of the metrics."""
    import copy

    run = copy.deepcopy(run)
    held = [name for name, contact in run["contacts"].items() if any(i["start"] == 0.0 for i in contact["impacts"])]
    assert len(held) == 1, held
    lists = [run["contacts"][held[0]]["impacts"]]
    lists += [part["impacts"] for table in ("stops", "absorbers") for part in run["metrics"][table]
              if part["name"] == held[0]]
    for impacts in lists:
        at_start = [i for i in impacts if i["start"] == 0.0]
        assert len(at_start) == 1, at_start
        impacts.remove(at_start[0])
    assert len(lists) == 2
    return run


def test_what_changed_since_the_recording_is_named():
    """The exceptions above name recorded scenes, and still compare most of their record."""
    shipped = {key.split("/")[1] for key in BASELINE if key.startswith("scene/")}
    assert set(SOLVE_CHANGED) <= shipped and set(SCENES_AS_RECORDED) <= shipped
    assert all(path.is_file() for path in SCENES_AS_RECORDED.values())
    kept = metrics_only(BASELINE["scene/realistic/standard/1000"])
    assert "steps" not in kept["metrics"] and "support_force" not in kept and kept["metrics"]["shots"]


def test_the_record_covers_what_the_issue_names():
    """Impacts of several contacts, onsets, shots with a return to battery, sub-threshold episodes."""
    runs = BASELINE.values()
    assert sum(len(r["contacts"]) > 1 for r in runs) >= 4  # end stops, two absorbers
    assert any(r["contacts"][c]["onsets"] for r in runs for c in r["contacts"])  # restitution laws
    assert any(s["time_to_battery"] is not None for r in runs for s in (r["metrics"].get("shots") or []))
    assert any(c["episodes"] > len(c["impacts"] or []) for r in runs for c in r["contacts"].values())
    assert all(r["metrics"]["peak_support_force"] is not None for r in runs)


def test_the_record_is_the_first_recording():
    assert RECORD["recorded_from_commit"] == "b542f33bfd2e05c54ab9e92c8c7c7140e2779854"
    assert "equal to the first recording" in RECORD["verified"]
    assert RECORD["machine"]["numpy_dispatch"] and len(BASELINE) == 110


def test_the_comparison_catches_a_change():
    """Ten times a preset's guarantee in one sample of the support force, one energy or one impact's start is
    reported."""
    import copy

    key = "paper/ii-m1000-gap0/standard"
    scene, end_time, accuracy, threshold = scene_of(key)
    record = BASELINE[key]
    new = _recorder.record(simulate(scene, end_time, recorded.preset_as_recorded(accuracy), impact_threshold=threshold), accuracy)
    assert not recorded.differences(new, record, recorded.kind_of_output, accuracy, record["scales"])
    claim = __import__("validation.studies.guarantee", fromlist=["TOLERANCES"]).TOLERANCES[accuracy]
    for change in ("support force", "energy", "impact start"):
        changed = copy.deepcopy(new)
        if change == "support force":
            changed["support_force"]["samples"][5] += 10 * claim["force"] * record["scales"]["force"]
        elif change == "energy":
            stop = next(iter(changed["metrics"]["dissipated_energy"]))
            changed["metrics"]["dissipated_energy"][stop] += 10 * claim["metric"] * record["scales"]["energy"]
        else:
            contact = next(c for c in changed["contacts"].values() if c["impacts"])
            contact["impacts"][0]["start"] += 10 * claim["time"]
        assert recorded.differences(changed, record, recorded.kind_of_output, accuracy, record["scales"]), change
