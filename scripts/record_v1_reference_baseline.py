#!/usr/bin/env python
"""Record the scipy reference's version-1 metrics for the 19 paper cases, as they were before the restructuring.

Made at the commit before the restructuring (a038411), in a checkout of it; ``--verify`` checks the first
recording (commit cb32584) to the bit and adds the machine's CPU kernels to it:

    git worktree add /tmp/v1 a038411
    NPY_DISABLE_CPU_FEATURES=X86_V4 OPENBLAS_CORETYPE=Haswell .venv/bin/python \\
        scripts/record_v1_reference_baseline.py tests/data/v1_reference_baseline.json --tree /tmp/v1 \\
        --verify tests/data/v1_reference_baseline.json

``tests/validation/reference/test_v1_baseline.py`` compares the reference with it (100x its tolerance).
"""
from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(HERE / "tests"))
import recorded  # noqa: E402  (tests/recorded.py: the machine record)

METRICS = ("max_barrel_displacement", "time_of_max_barrel_displacement", "peak_contact_force",
           "time_of_peak_contact_force", "max_absorber_velocity", "time_of_max_absorber_velocity")


def _hexed(value):
    return None if value is None else float(value).hex()


def main() -> None:
    args = recorded.recorder_arguments(__doc__, HERE)
    tree = Path(args.tree).resolve()
    sys.path.insert(0, str(tree))
    from mbs_models import model_i, model_ii, simplified_model
    from validation.reference import solve_reference
    first = json.loads(Path(args.verify).read_text()) if args.verify else None
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=tree, capture_output=True, text=True).stdout.strip()
    out = {"recorded_from_commit": commit, "rtol": 1e-10, "atol": 1e-12, "machine": recorded.machine(), "cases": {}}
    cases = [("simplified", simplified_model())]
    for label, factory in (("i", model_i), ("ii", model_ii)):
        for mass in (100.0, 500.0, 1000.0):
            for gap in (0.0, 0.04, 0.08):
                cases.append((f"{label}-m{mass:g}-gap{gap * 1000:g}", factory(mass, gap)))
    start = time.perf_counter()
    for name, scene in cases:
        metrics = solve_reference(scene, 10.0).metrics()
        case = {k: _hexed(metrics[k]) for k in METRICS}
        case["impacts"] = [[_hexed(i["start"]), _hexed(i["end"]), _hexed(i["peak_force"]), _hexed(i["time_of_peak"])]
                           for i in metrics["impacts"]]
        case["dissipated_energy"] = {k: _hexed(v) for k, v in metrics["dissipated_energy"].items()}
        out["cases"][name] = case
        print(name, f"{time.perf_counter() - start:.1f} s", flush=True)
    if first is not None:
        if first["cases"] != out["cases"]:
            sys.exit("not the first recording: " + str([k for k in out["cases"] if out["cases"][k] != first["cases"].get(k)]))
        out["verified"] = "every metric (float.hex) equal to the first recording (commit cb32584)"
    Path(args.out).write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()
