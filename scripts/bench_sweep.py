#!/usr/bin/env python
"""Benchmark of ``run_sweep``: what the sweep machinery costs and what the process pool buys, as ratios
measured in the same run (not a timed test: absolute numbers depend on the machine and its load).

    python scripts/bench_sweep.py                     # the Figs 4/5 grid of model (ii), reduced, 10 s runs
    python scripts/bench_sweep.py --gaps 25 --workers 4

On one grid (masses x gaps of ``--scene``), after one untimed serial sweep (imports), alternating the
variants ``--repeats`` times:

1. **bare loop**: ``[simulate(scene_i) for scene_i in grid]`` in this process (the floor);
2. **serial sweep**: ``run_sweep(..., workers=1, out=FILE.csv)``: overrides, rows, the typed table and the
   CSV written row by row -- its time over the bare loop's is the machinery's overhead;
3. **pool, 1 point per task** and 4. **pool, batched** (the default: about four tasks per worker):
   ``run_sweep(..., workers=N)`` -- the pool's speed-up over the serial sweep, and what batching adds.

The tables of every variant are checked equal (wall times aside).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default="model_ii", help="shipped scene or TOML file (default model_ii)")
    parser.add_argument("--masses", default="100,500,1000", help="absorber masses in kg (default 100,500,1000)")
    parser.add_argument("--gaps", type=int, default=7, help="gaps from 0 to 0.12 m, both included (default 7)")
    parser.add_argument("--end-time", type=float, default=10.0, help="simulated time in s (default 10)")
    parser.add_argument("--workers", type=int, default=2, help="pool size (default 2)")
    parser.add_argument("--repeats", type=int, default=3, help="alternating rounds, median taken (default 3)")
    args = parser.parse_args(argv)

    from mbs_models import apply_overrides, simulate
    from mbs_models.cli import _resolve_scene
    from mbs_models.studies.sweep import run_sweep

    scene = _resolve_scene(args.scene)
    params = {"absorber.mass": args.masses, "contact.gap": f"0:0.12:{args.gaps}"}
    from mbs_models.studies.grid import make_grid
    points = list(make_grid(scene, params).points())
    print(f"{len(points)} points of {args.scene}, {args.end_time:g} s each, pool of {args.workers}; "
          f"{args.repeats} alternating rounds, medians")

    def bare():
        for point in points:
            simulate(apply_overrides(scene, point), args.end_time)

    def sweep(**kwargs):
        def run():
            with tempfile.TemporaryDirectory() as directory:
                return run_sweep(scene, params, end_time=args.end_time, progress=False,
                                 out=Path(directory) / "s.csv", **kwargs)
        return run

    variants = {"bare loop": bare, "serial sweep": sweep(workers=1),
                "pool, 1 point per task": sweep(workers=args.workers, batch_size=1),
                "pool, batched": sweep(workers=args.workers)}
    sweep(workers=1)()  # warm-up: imports (pandas, ...) and Exudyn's first model are not a sweep's cost
    times: dict[str, list[float]] = {name: [] for name in variants}
    tables = {}
    for _ in range(args.repeats):
        for name, run in variants.items():
            start = time.perf_counter()
            out = run()
            times[name].append(time.perf_counter() - start)
            if out is not None:
                tables[name] = out.drop(columns="wall_time")
    reference = tables["serial sweep"]
    for name, table in tables.items():
        if not table.equals(reference):
            print(f"TABLES DIFFER: {name}", file=sys.stderr)
            return 1
    median = {name: statistics.median(values) for name, values in times.items()}
    print(f"  serial sweep / bare loop           {median['serial sweep'] / median['bare loop']:.3f}   "
          f"(machinery overhead; [{median['serial sweep']:.2f} s vs {median['bare loop']:.2f} s])")
    for name in ("pool, 1 point per task", "pool, batched"):
        print(f"  serial sweep / {name:<22}{median['serial sweep'] / median[name]:6.2f}   "
              f"(speed-up; [{median[name]:.2f} s])")
    print("  every variant's table equals the serial sweep's (wall times aside)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
