#!/usr/bin/env python
"""Record the version-1 results of the engine as they were before the elements restructuring.

The record is made at the commit before any engine code moved (a038411), in a checkout of that commit:

    git worktree add /tmp/v1 a038411
    git show cb32584:tests/data/v1_baseline.json > /tmp/v1_digests.json
    NPY_DISABLE_CPU_FEATURES=X86_V4 OPENBLAS_CORETYPE=Haswell \\
        .venv/bin/python scripts/record_v1_baseline.py tests/data/v1_baseline.json --tree /tmp/v1 \\
        --verify /tmp/v1_digests.json

``tests/engine/test_v1_recorded.py`` compares every later version against this file within the
tolerances of ``tests/recorded.py``.  Never re-run it at a later commit to make a failing comparison
pass: the file is the record of what version-1 scenes gave before the change, not an output of the code
under test.

Recorded per case (the 19 paper cases and the 36 hard cases) and per accuracy preset: every scalar of the
Result, the impacts, the dissipated energies, the step count, the solver label, a summary of every time
history (``tests/recorded.py``: size, 33 samples, extremes, means) and the run's scales; for the 19 paper
cases also the runs with ``stop_when_final`` (all metrics, and the maximum barrel displacement alone).

``--verify`` checks the runs against the first recording (commit cb32584, made on a machine whose numpy
kernels were AVX2: hence the environment above), which kept float.hex scalars and a SHA-256 of every
history: the script refuses to write unless every recorded scalar and digest is equal to the bit.  The
record thus holds the first recording's numbers, with the samples a tolerance needs.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent.parent
PRESETS = ("draft", "standard", "reference")
ARRAYS = ("time", "barrel_position", "barrel_velocity", "barrel_acceleration", "absorber_position",
          "absorber_velocity", "absorber_acceleration", "contact_force", "kinetic_energy_history",
          "stored_energy_history")
SCALARS = ("end_time", "requested_end_time", "max_barrel_displacement", "time_of_max_barrel_displacement",
           "peak_contact_force", "time_of_peak_contact_force", "max_absorber_velocity",
           "time_of_max_absorber_velocity")
EARLY_STOPS = (("all", ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "impacts")),
               ("x", ("max_barrel_displacement",)))


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


def _float(value):
    return None if value is None else float(value)


def _outputs(result, number, history) -> dict:
    """The recorded outputs of a run, floats (or None) through ``number``, histories through ``history``."""
    def value(x):
        return None if x is None else number(float(x))
    out = {name: value(getattr(result, name)) for name in SCALARS}
    out["arrays"] = {name: history(getattr(result, name)) for name in ARRAYS}
    out["dissipated_energy"] = {k: value(v) for k, v in result.dissipated_energy.items()}
    out["dissipated_energy_history"] = {k: history(v) for k, v in result.dissipated_energy_history.items()}
    out["impacts"] = None if result.impacts is None else [
        [value(i.start), value(i.end), value(i.peak_force), value(i.time_of_peak_force)] for i in result.impacts]
    out["steps"] = result.steps
    out["solver"] = result.settings.label()
    out["max_step"] = value(result.settings.max_step)
    out["stop_reason"] = result.stop_reason
    out["final_metrics"] = list(result.final_metrics)
    return out


def record(result, scene, accuracy: str) -> dict:
    """One run as the record keeps it (floats exact in JSON, histories as summaries, the run's scales)."""
    out = _outputs(result, float, recorded.summary)
    out["accuracy"] = accuracy
    mechanical = result.kinetic_energy_history + result.stored_energy_history
    out["scales"] = recorded.scales(
        length=[result.barrel_position, result.absorber_position],
        velocity=[result.barrel_velocity, result.absorber_velocity],
        acceleration=[result.barrel_acceleration, result.absorber_acceleration],
        force=[result.contact_force, scene.barrel.mass * np.asarray(result.barrel_acceleration)],
        energy=[mechanical, *result.dissipated_energy_history.values()])
    return out


def first_format(result) -> dict:
    """The run as the first recording (cb32584) kept it: float.hex scalars, SHA-256 of every history."""
    return _outputs(result, float.hex, recorded.digest)


def main() -> None:
    args = recorded.recorder_arguments(__doc__, HERE)
    tree = Path(args.tree).resolve()
    sys.path[:0] = [str(tree), str(tree / "tests")]
    from mbs_models import model_i, model_ii, simplified_model, simulate
    try:
        from validation.studies.hard_cases import HARD_CASES
    except ImportError:  # before the hard cases moved into validation
        from test_hard_cases import HARD_CASES
    import mbs_models
    assert Path(mbs_models.__file__).resolve().is_relative_to(tree), mbs_models.__file__
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=tree, capture_output=True, text=True).stdout.strip()
    first = json.loads(Path(args.verify).read_text()) if args.verify else None
    data = {"recorded_from_commit": commit, "generated_by": "scripts/record_v1_baseline.py",
            "machine": recorded.machine(), "paper": {}, "paper_early_stop": {}, "hard": {}}
    mismatches = []

    def keep(section: str, key: str, result, scene, accuracy: str) -> None:
        data[section][key] = record(result, scene, accuracy)
        if first is not None:
            old = first[section][key]
            new = first_format(result)
            mismatches.extend(f"{section}/{key}/{name}" for name in new if new[name] != old.get(name))

    start = time.perf_counter()
    for name, scene in paper_cases((simplified_model, model_i, model_ii)):
        for preset in PRESETS:
            keep("paper", f"{name}/{preset}", simulate(scene, 10.0, preset), scene, preset)
            data["paper"][f"{name}/{preset}"]["scene"] = scene.name
        for label, metrics in EARLY_STOPS:
            keep("paper_early_stop", f"{name}/{label}", simulate(scene, 10.0, "standard", stop_when_final=metrics),
                 scene, "standard")
        print(f"{name}: {time.perf_counter() - start:.1f} s", flush=True)
    for case in HARD_CASES:
        for preset in PRESETS:
            keep("hard", f"{case.name}/{preset}", simulate(case.scene, case.end_time, preset), case.scene, preset)
        print(f"{case.name}: {time.perf_counter() - start:.1f} s", flush=True)
    if first is not None:
        missing = [f"{s}/{k}" for s in ("paper", "paper_early_stop", "hard") for k in first[s] if k not in data[s]]
        if mismatches or missing:
            sys.exit(f"not the first recording: {len(mismatches)} differences, {len(missing)} runs missing: "
                     f"{(mismatches + missing)[:10]}")
        data["verified"] = (f"every scalar (float.hex) and every history (SHA-256) equal to the first recording "
                            f"({first['recorded_from_commit']}, tests/data/v1_baseline.json of commit cb32584)")
    Path(args.out).write_text(recorded.dumps(data))
    print(f"written {args.out}")


if __name__ == "__main__":
    main()
