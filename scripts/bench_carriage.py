#!/usr/bin/env python
"""The cost of the planar model: a carriage scene against the 1-D scene of the same hardware, per simulated second.

    python scripts/bench_carriage.py                  # towed_howitzer and towed_howitzer_45, 10 s, standard
    python scripts/bench_carriage.py --repeats 9 --end-time 5

For each carriage scene, its 1-D twin is the same scene without ``[carriage]`` (the cradle is then the ground,
gravity acts along the axis on the barrel: DESIGN.md).  Both are run ``repeats`` times, interleaved, in this
process (``simulate`` at each accuracy preset); the ratio of the median wall times of complete runs (and of the
solves alone) is the planar model's cost per simulated second (issue #22's target: at most 3x at ``standard``).
Absolute times are printed in brackets only.  :func:`carriage_costs` is also section 8 of ``scripts/bench.py``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

SCENES = ("towed_howitzer", "towed_howitzer_45")
#: Issue #22's target: a carriage scene costs at most this many times its 1-D twin per simulated second.
TARGET_RATIO = 3.0


def one_d_twin(scene):
    """The scene without its carriage (the same hardware on a fixed cradle)."""
    from mbs_models.scene.io import scene_from_dict, scene_to_dict

    data = scene_to_dict(scene)
    data.pop("carriage")
    return scene_from_dict(data)


def carriage_costs(names=SCENES, end_time: float = 10.0, repeats: int = 5, presets=("standard",)) -> list[dict]:
    """Per scene and preset: medians of complete-run and solve wall times (s) and steps, carriage and 1-D."""
    from mbs_models import simulate
    from mbs_models.cli import _resolve_scene

    rows = []
    for name in names:
        planar = _resolve_scene(name)
        flat = one_d_twin(planar)
        for preset in presets:
            runs: dict[str, list] = {"carriage": [], "1-D": []}
            for _ in range(repeats):
                for key, scene in (("carriage", planar), ("1-D", flat)):
                    result = simulate(scene, end_time, preset)
                    runs[key].append((result.wall_time, result.timings["solve"], result.steps))
            med = {key: tuple(statistics.median(r[i] for r in rows_) for i in range(3)) for key, rows_ in runs.items()}
            rows.append({"scene": name, "preset": preset, "carriage": med["carriage"], "1-D": med["1-D"],
                         "run_ratio": med["carriage"][0] / med["1-D"][0],
                         "solve_ratio": med["carriage"][1] / med["1-D"][1],
                         "step_ratio": med["carriage"][2] / med["1-D"][2]})
    return rows


def print_costs(rows: list[dict], end_time: float) -> None:
    print(f"carriage scene / its 1-D twin, {end_time:g} s simulated (medians; same process, interleaved)")
    for row in rows:
        (run_c, solve_c, steps_c), (run_1, solve_1, steps_1) = row["carriage"], row["1-D"]
        met = "met" if row["preset"] != "standard" or row["run_ratio"] <= TARGET_RATIO else "NOT met"
        print(f"   {row['scene']:20s} {row['preset']:9s} complete run {row['run_ratio']:5.2f}x "
              f"[{run_c * 1e3:.0f} / {run_1 * 1e3:.0f} ms], solve {row['solve_ratio']:5.2f}x, steps "
              f"{row['step_ratio']:5.2f}x [{steps_c:.0f} / {steps_1:.0f}]"
              + (f"   target <= {TARGET_RATIO:g}x: {met}" if row["preset"] == "standard" else ""))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time", type=float, default=10.0)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--presets", default="draft,standard,reference")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    rows = carriage_costs(end_time=args.end_time, repeats=args.repeats, presets=args.presets.split(","))
    with open("/proc/loadavg") as handle:
        load = handle.read().split()[0]
    print(f"(machine load {load})")
    print_costs(rows, args.end_time)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
