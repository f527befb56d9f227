#!/usr/bin/env python
"""Record every post-processed output before the post-processing is vectorised (issue #11).

Run ONCE, at the commit named in the output file, before ``mbs_models/results`` changes:

    .venv/bin/python scripts/record_postprocess_baseline.py tests/data/postprocess_baseline.json

``tests/results/test_postprocess_recorded.py`` compares later versions against this file.  Never re-run
it to make a failing comparison pass: the file is the record of what the post-processing gave before
the change, not an output of the code under test.

``tests/data/v1_baseline.json`` already holds the version-1 metrics, impacts and dissipated energies;
this file adds what it does not: the peak support force and its time, every contact's impacts, peak,
episode count and onsets (end stops, two absorbers), the per-body maximum velocities, the per-element
energies and work, the per-shot outputs of a burst, and a SHA-256 of every energy, work, force and
support-force history.  Cases: the 19 paper cases (``draft`` and ``standard``), the 38 hard cases
(``standard``, their own end times) and every shipped scene (``standard``, 10 s; version 2 included),
each at the default impact threshold (1 kN) and the shipped scenes also at 50 kN (most episodes below
the threshold: the other branch of the impact search).
"""

from __future__ import annotations

import hashlib
import json
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from mbs_models import load_scene, model_i, model_ii, simplified_model, simulate  # noqa: E402
from mbs_models.scenes import list_scenes, scene_path  # noqa: E402
from validation.studies.hard_cases import HARD_CASES  # noqa: E402


def paper_cases():
    cases = [("simplified", simplified_model())]
    for label, factory in (("i", model_i), ("ii", model_ii)):
        for mass in (100.0, 500.0, 1000.0):
            for gap in (0.0, 0.04, 0.08):
                cases.append((f"{label}-m{mass:g}-gap{gap * 1000:g}", factory(mass, gap)))
    return cases


def cases():
    """``(key, scene, end_time, accuracy, impact_threshold)`` of every recorded run."""
    out = []
    for name, scene in paper_cases():
        for preset in ("draft", "standard"):
            out.append((f"paper/{name}/{preset}", scene, 10.0, preset, 1000.0))
    for case in HARD_CASES:
        out.append((f"hard/{case.name}/standard", case.scene, case.end_time, "standard", 1000.0))
    for name in list_scenes():
        scene = load_scene(scene_path(name))
        for threshold in (1000.0, 50000.0):
            out.append((f"scene/{name}/standard/{threshold:g}", scene, 10.0, "standard", threshold))
    return out


def digest(array) -> str | None:
    """``"size:sha256"`` of an array's float64 bytes (as scripts/record_v1_baseline.py; this file is also loaded by
    tests/results/test_postprocess_recorded.py, where the scripts directory is not importable)."""
    if array is None:
        return None
    array = np.ascontiguousarray(np.asarray(array, dtype=float))
    return f"{array.size}:" + hashlib.sha256(array.tobytes()).hexdigest()


def hexed(value):
    """Floats as float.hex (exact), recursively; everything else as it is."""
    if isinstance(value, bool) or value is None or isinstance(value, (int, str)):
        return value
    if isinstance(value, (float, np.floating)):
        return float(value).hex()
    if isinstance(value, dict):
        return {str(k): hexed(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [hexed(v) for v in value]
    raise TypeError(f"cannot record {type(value).__name__}")


def record(result) -> dict:
    metrics = result.metrics()
    for volatile in ("wall_time",):
        metrics.pop(volatile)
    out = {"metrics": hexed(metrics)}
    out["contacts"] = {name: {"peak_force": hexed(c.peak_force), "time_of_peak_force": hexed(c.time_of_peak_force),
                              "impacts": None if c.impacts is None else [hexed(i.to_dict()) for i in c.impacts],
                              "episodes": c.episodes,
                              "onsets": None if c.onsets is None else hexed([list(o) for o in c.onsets]),
                              "force": digest(c.force)}
                       for name, c in result.contacts.items()}
    out["max_velocities"] = hexed({k: list(v) for k, v in result.max_velocities.items()})
    out["support_force"] = digest(result.support_force)
    out["histories"] = {kind: {k: digest(v) for k, v in histories.items()} for kind, histories in (
        ("dissipated", result.dissipated_energy_history), ("stored", result.stored_energy_histories),
        ("kinetic", result.kinetic_energy_histories), ("work", result.work_histories))}
    out["time"] = digest(result.time)
    return out


def main(path: str) -> None:
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "--", "mbs_models"], cwd=ROOT, capture_output=True,
                           text=True).stdout.strip()
    if dirty:
        sys.exit(f"mbs_models has uncommitted changes; record at a clean commit:\n{dirty}")
    start = time.perf_counter()
    runs = {}
    for key, scene, end_time, accuracy, threshold in cases():
        print(key, flush=True)
        runs[key] = record(simulate(scene, end_time, accuracy, impact_threshold=threshold))
    data = {"commit": commit, "generated_by": "scripts/record_postprocess_baseline.py",
            "python": platform.python_version(), "numpy": np.__version__, "machine": platform.machine(),
            "seconds": round(time.perf_counter() - start, 1), "runs": runs}
    Path(path).write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    print(f"{len(runs)} runs recorded at {commit} in {data['seconds']} s -> {path}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "tests" / "data" / "postprocess_baseline.json"))
