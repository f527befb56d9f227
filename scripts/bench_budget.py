#!/usr/bin/env python
"""What the step budget costs a scene without contacts: ``python scripts/bench_budget.py [--repeats 21]``.

Every adaptive solve runs with the step budget as Exudyn's pre-step function (``engine/guard.py``): a Python
call per step that counts.  Scenes with a contact always had it; scenes without one (the paper's simplified
model, the brake, the cradle) got it with issue #20.  This script solves each shipped contact-free scene at
``standard`` to 10 s with and without that function, interleaved, and prints the median solve time, the steps,
and the cost per step of the budget.  Not a test: absolute times depend on the machine.
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from profile_solve import run  # noqa: E402

from mbs_models import load_scene  # noqa: E402
from mbs_models.engine.mechanism import Mechanism  # noqa: E402
from mbs_models.scenes import list_scenes, scene_path  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=21)
    args = parser.parse_args(argv)
    print("| scene | steps | solve without | with the budget | per step |")
    print("|---|---:|---:|---:|---:|")
    for name in list_scenes():
        scene = load_scene(scene_path(name))
        mechanism = Mechanism(scene)
        if mechanism.contacts or mechanism.breakpoints:  # one solve, no contact: the budget is all that is new
            continue
        times = {False: [], True: []}
        run(scene, "symbolic", True, True)  # warm-up
        for _ in range(args.repeats):
            for budget in (False, True):
                elapsed, steps = run(scene, "symbolic", budget, True)
                times[budget].append(elapsed)
        without, with_budget = statistics.median(times[False]), statistics.median(times[True])
        print(f"| {name} | {steps} | {1e3 * without:.2f} ms | {1e3 * with_budget:.2f} ms "
              f"(+{100 * (with_budget / without - 1):.0f} %) | {1e6 * (with_budget - without) / steps:.2f} us |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
