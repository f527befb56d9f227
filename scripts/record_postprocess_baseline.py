#!/usr/bin/env python
"""Record every post-processed output as it was before the post-processing was vectorised (issue #11).

The record is made at the commit before ``mbs_models/results`` changed (b542f33), in a checkout of it:

    git worktree add /tmp/pp b542f33
    git show a5f098b:tests/data/postprocess_baseline.json > /tmp/pp_digests.json
    NPY_DISABLE_CPU_FEATURES=X86_V4 OPENBLAS_CORETYPE=Haswell \\
        .venv/bin/python scripts/record_postprocess_baseline.py tests/data/postprocess_baseline.json \\
        --tree /tmp/pp --verify /tmp/pp_digests.json

``tests/results/test_postprocess_recorded.py`` compares later versions against this file within the
tolerances of ``tests/recorded.py``.  Never re-run it at a later commit to make a failing comparison
pass: the file is the record of what the post-processing gave before the change, not an output of the
code under test.

``tests/data/v1_baseline.json`` already holds the version-1 metrics, impacts and dissipated energies;
this file adds what it does not: the peak support force and its time, every contact's impacts, peak,
episode count and onsets (end stops, two absorbers), the per-body maximum velocities, the per-element
energies and work, the per-shot outputs of a burst, and a summary of every energy, work, force and
support-force history (``tests/recorded.py``), with the run's scales.  Cases: the 19 paper cases (``draft``
and ``standard``), the 36 hard cases (``standard``, their own end times) and every shipped scene
(``standard``, 10 s; version 2 included), each at the default impact threshold (1 kN) and the shipped
scenes also at 50 kN (most episodes below the threshold: the other branch of the impact search).

``--verify`` checks every run against the first recording (commit a5f098b, float.hex and a SHA-256 of
every history, made on a machine whose numpy kernels were AVX2: hence the environment above) and refuses
to write unless all are equal to the bit.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent.parent


sys.path.insert(0, str(HERE / "tests"))
import recorded  # noqa: E402  (tests/recorded.py: the summaries and the machine record)


def paper_cases(factories):
    simplified_model, model_i, model_ii = factories
    cases = [("simplified", simplified_model())]
    for label, factory in (("i", model_i), ("ii", model_ii)):
        for mass in (100.0, 500.0, 1000.0):
            for gap in (0.0, 0.04, 0.08):
                cases.append((f"{label}-m{mass:g}-gap{gap * 1000:g}", factory(mass, gap)))
    return cases


def cases(api, hard_cases):
    """``(key, scene, end_time, accuracy, impact_threshold)`` of every recorded run."""
    out = []
    for name, scene in paper_cases((api.simplified_model, api.model_i, api.model_ii)):
        for preset in ("draft", "standard"):
            out.append((f"paper/{name}/{preset}", scene, 10.0, preset, 1000.0))
    for case in hard_cases:
        out.append((f"hard/{case.name}/standard", case.scene, case.end_time, "standard", 1000.0))
    for name in api.list_scenes():
        scene = api.load_scene(api.scene_path(name))
        for threshold in (1000.0, 50000.0):
            out.append((f"scene/{name}/standard/{threshold:g}", scene, 10.0, "standard", threshold))
    return out


def _plain(value, convert):
    """Floats through ``convert``, recursively; everything else as it is."""
    if isinstance(value, bool) or value is None or isinstance(value, (int, str)):
        return value
    if isinstance(value, (float, np.floating)):
        return convert(float(value))
    if isinstance(value, dict):
        return {str(k): _plain(v, convert) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v, convert) for v in value]
    raise TypeError(f"cannot record {type(value).__name__}")


def _outputs(result, number, history) -> dict:
    """The recorded outputs of a run, floats through ``number``, histories through ``history``."""
    metrics = result.metrics()
    metrics.pop("wall_time")
    out = {"metrics": _plain(metrics, number)}
    out["contacts"] = {name: {"peak_force": _plain(c.peak_force, number),
                              "time_of_peak_force": _plain(c.time_of_peak_force, number),
                              "impacts": None if c.impacts is None else [_plain(i.to_dict(), number) for i in c.impacts],
                              "episodes": c.episodes,
                              "onsets": None if c.onsets is None else _plain([list(o) for o in c.onsets], number),
                              "force": history(c.force)}
                       for name, c in result.contacts.items()}
    out["max_velocities"] = _plain({k: list(v) for k, v in result.max_velocities.items()}, number)
    out["support_force"] = history(result.support_force)
    out["histories"] = {kind: {k: history(v) for k, v in histories.items()} for kind, histories in (
        ("dissipated", result.dissipated_energy_history), ("stored", result.stored_energy_histories),
        ("kinetic", result.kinetic_energy_histories), ("work", result.work_histories))}
    out["time"] = history(result.time)
    return out


def record(result, accuracy: str) -> dict:
    """One run as the record keeps it (floats exact in JSON, histories as summaries, the run's scales)."""
    out = _outputs(result, float, recorded.summary)
    out["accuracy"] = accuracy
    mechanical = sum(result.kinetic_energy_histories.values()) + sum(result.stored_energy_histories.values(), 0.0)
    out["scales"] = recorded.scales(
        length=list(result.positions.values()), velocity=list(result.velocities.values()),
        acceleration=list(result.accelerations.values()),
        force=[result.support_force, *(c.force for c in result.contacts.values())],
        energy=[mechanical, *result.dissipated_energy_history.values(), *result.work_histories.values()])
    return out


def first_format(result) -> dict:
    """The run as the first recording (a5f098b) kept it: float.hex, SHA-256 of every history."""
    return _outputs(result, float.hex, recorded.digest)


def main() -> None:
    args = recorded.recorder_arguments(__doc__, HERE)
    tree = Path(args.tree).resolve()
    sys.path.insert(0, str(tree))
    import mbs_models
    from mbs_models import load_scene, model_i, model_ii, simplified_model, simulate
    from mbs_models.scenes import list_scenes, scene_path
    from validation.studies.hard_cases import HARD_CASES
    assert Path(mbs_models.__file__).resolve().is_relative_to(tree), mbs_models.__file__
    api = argparse.Namespace(load_scene=load_scene, model_i=model_i, model_ii=model_ii,
                             simplified_model=simplified_model, list_scenes=list_scenes, scene_path=scene_path)
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=tree, capture_output=True, text=True).stdout.strip()
    first = json.loads(Path(args.verify).read_text())["runs"] if args.verify else None
    start = time.perf_counter()
    runs, mismatches = {}, []
    for key, scene, end_time, accuracy, threshold in cases(api, HARD_CASES):
        result = simulate(scene, end_time, accuracy, impact_threshold=threshold)
        runs[key] = record(result, accuracy)
        if first is not None and first_format(result) != first.get(key):
            mismatches.append(key)
        print(key, flush=True)
    data = {"recorded_from_commit": commit, "generated_by": "scripts/record_postprocess_baseline.py",
            "machine": recorded.machine(), "runs": runs}
    if first is not None:
        missing = sorted(set(first) - set(runs))
        if mismatches or missing:
            sys.exit(f"not the first recording: {len(mismatches)} runs differ, {len(missing)} missing: "
                     f"{(mismatches + missing)[:10]}")
        data["verified"] = ("every output equal to the first recording (float.hex, SHA-256 of every history; "
                            "tests/data/postprocess_baseline.json of commit a5f098b)")
    Path(args.out).write_text(recorded.dumps(data))
    print(f"{len(runs)} runs recorded at {commit} in {time.perf_counter() - start:.1f} s -> {args.out}")


if __name__ == "__main__":
    main()
