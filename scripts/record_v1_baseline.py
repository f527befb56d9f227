"""Record the version-1 results of the engine before the elements restructuring (issue: effects as elements).

Run ONCE, at the commit named in the output file, before any engine code moved:

    .venv/bin/python scripts/record_v1_baseline.py tests/data/v1_baseline.json

``tests/engine/test_v1_bit_identical.py`` compares every later version against this file, bit for
bit.  Never re-run it to make a failing comparison pass: the file is the record of what version-1
scenes gave before the change, not an output of the code under test.

Recorded per case (the 19 paper cases and the 38 hard cases of tests/test_hard_cases.py) and per
accuracy preset: every scalar of the Result (float.hex), the impacts, the dissipated energies, the
step count, the solver label, and a SHA-256 of each time-history array; for the 19 paper cases also
the runs with ``stop_when_final`` (all metrics, and the maximum barrel displacement alone), which
record where the early stop happened.
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
sys.path.insert(0, str(ROOT / "tests"))

from mbs_models import model_i, model_ii, simplified_model, simulate  # noqa: E402
from test_hard_cases import HARD_CASES  # noqa: E402

PRESETS = ("draft", "standard", "reference")
ARRAYS = ("time", "barrel_position", "barrel_velocity", "barrel_acceleration", "absorber_position",
          "absorber_velocity", "absorber_acceleration", "contact_force", "kinetic_energy_history",
          "stored_energy_history")
SCALARS = ("end_time", "requested_end_time", "max_barrel_displacement", "time_of_max_barrel_displacement",
           "peak_contact_force", "time_of_peak_contact_force", "max_absorber_velocity",
           "time_of_max_absorber_velocity")


def paper_cases():
    cases = [("simplified", simplified_model())]
    for label, factory in (("i", model_i), ("ii", model_ii)):
        for mass in (100.0, 500.0, 1000.0):
            for gap in (0.0, 0.04, 0.08):
                cases.append((f"{label}-m{mass:g}-gap{gap * 1000:g}", factory(mass, gap)))
    return cases


def digest(array) -> str | None:
    if array is None:
        return None
    array = np.ascontiguousarray(np.asarray(array, dtype=float))
    return f"{array.size}:" + hashlib.sha256(array.tobytes()).hexdigest()


def hexed(value):
    return None if value is None else float(value).hex()


def record(result) -> dict:
    out = {name: hexed(getattr(result, name)) for name in SCALARS}
    out["arrays"] = {name: digest(getattr(result, name)) for name in ARRAYS}
    out["dissipated_energy"] = {k: hexed(v) for k, v in result.dissipated_energy.items()}
    out["dissipated_energy_history"] = {k: digest(v) for k, v in result.dissipated_energy_history.items()}
    out["impacts"] = None if result.impacts is None else [
        [hexed(i.start), hexed(i.end), hexed(i.peak_force), hexed(i.time_of_peak_force)] for i in result.impacts]
    out["steps"] = result.steps
    out["solver"] = result.settings.label()
    out["max_step"] = hexed(result.settings.max_step)
    out["stop_reason"] = result.stop_reason
    out["final_metrics"] = list(result.final_metrics)
    return out


def main(path: str) -> None:
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    import exudyn
    import scipy
    data = {"recorded_from_commit": commit, "exudyn": exudyn.__version__, "numpy": np.__version__,
            "scipy": scipy.__version__, "python": platform.python_version(), "machine": platform.machine(),
            "paper": {}, "paper_early_stop": {}, "hard": {}}
    start = time.perf_counter()
    for name, scene in paper_cases():
        for preset in PRESETS:
            data["paper"][f"{name}/{preset}"] = record(simulate(scene, 10.0, preset))
            data["paper"][f"{name}/{preset}"]["scene"] = scene.name
        for label, metrics in (("all", ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity",
                                        "impacts")), ("x", ("max_barrel_displacement",))):
            data["paper_early_stop"][f"{name}/{label}"] = record(simulate(scene, 10.0, "standard",
                                                                          stop_when_final=metrics))
        print(f"{name}: {time.perf_counter() - start:.1f} s", flush=True)
    for case in HARD_CASES:
        for preset in PRESETS:
            data["hard"][f"{case.name}/{preset}"] = record(simulate(case.scene, case.end_time, preset))
        print(f"{case.name}: {time.perf_counter() - start:.1f} s", flush=True)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    main(sys.argv[1])
