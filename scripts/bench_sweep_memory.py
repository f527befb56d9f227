#!/usr/bin/env python
"""What memory ``run_sweep`` needs as the grid grows, without simulating: each point's evaluation is replaced by
an instant row (``evaluate_point`` mocked, a 4 ms 'solve'), so that the grid, the scheduling, the table file, the
resume scan and the final sort are measured alone (a real solve adds the same few MB of Exudyn per worker,
whatever the grid).

    python scripts/bench_sweep_memory.py                          # 10^6 points run in full; 10^8 points, 10^6 run
    python scripts/bench_sweep_memory.py --sizes 1e6 --run 1e6

For each grid size N (two keys of sqrt(N) values) a fresh interpreter runs ``--run`` points of it into a CSV
file (``table=False``: only the summary comes back), stopping there if the grid is larger (as a kill would),
then a second fresh interpreter resumes the file for ``--resume`` more points.  A grid run in full ends with the
file put in grid order (the external sort).  Printed: the peak resident memory of each interpreter (ru_maxrss)
over its memory after the imports and a 2-point warm-up sweep, the time, and the file's size.
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


class _Stop(Exception):
    pass


def _rss_mb() -> float:
    with open("/proc/self/status") as handle:
        for line in handle:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return float("nan")


def child(size: int, run: int, out: str, workers: int, batch: int) -> dict:
    """One interpreter: ``run`` points of an N-point grid into ``out`` (resumed if it holds rows)."""
    from mbs_models import model_i
    from mbs_models.studies import point as point_module
    from mbs_models.studies.grid_sweep import run_sweep

    def instant(scene, overrides, settings=None):
        return {**overrides, "wall_time": 0.004, "status": "ok", "error": None}

    point_module.evaluate_point = instant
    with tempfile.TemporaryDirectory() as warm:   # imports (pandas, Exudyn...) are no part of the grid's cost
        run_sweep(model_i(), {"contact.gap": [0.0, 0.01]}, workers=workers, out=Path(warm) / "w.csv",
                  progress=False, announce=False)
    side = math.isqrt(size)
    params = {"absorber.mass": f"1:1000:{side}", "contact.gap": f"0:0.1:{size // side}"}
    base = _rss_mb()
    start_points = {}

    def progress(done, total):
        start_points.setdefault("first", done)
        if done - start_points["first"] >= run - 1:
            raise _Stop

    start = time.perf_counter()
    finished = True
    try:
        summary = run_sweep(model_i(), params, workers=workers, out=out, large=True, table=False, batch_size=batch,
                            progress=progress if run < size else False, announce=lambda line: None)
    except _Stop:
        finished, summary = False, {}
    seconds = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return {"points": size, "run_to": run, "finished": finished, "resumed": summary.get("resumed"),
            "rss_after_imports_mb": round(base, 1), "peak_rss_mb": round(peak, 1),
            "peak_over_imports_mb": round(peak - base, 1), "seconds": round(seconds, 1),
            "file_mb": round(Path(out).stat().st_size / 1e6, 1)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="1e6,1e8", help="grid sizes (default 1e6,1e8)")
    parser.add_argument("--run", type=float, default=1e6, help="points run in the first interpreter (default 1e6)")
    parser.add_argument("--resume", type=float, default=1e5, help="points run on resuming (default 1e5)")
    parser.add_argument("--workers", type=int, default=1, help="pool size (default 1: this process)")
    parser.add_argument("--batch", type=int, default=256, help="points per task (default 256)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        size, run, out = json.loads(args.child)
        print(json.dumps(child(size, run, out, args.workers, args.batch)))
        return 0
    with tempfile.TemporaryDirectory() as directory:
        for size in [int(float(s)) for s in args.sizes.split(",")]:
            out = str(Path(directory) / f"sweep_{size}.csv")
            for run in (min(size, int(args.run)), int(args.resume)):
                proc = subprocess.run([sys.executable, __file__, "--workers", str(args.workers), "--batch",
                                       str(args.batch), "--child", json.dumps([size, run, out])],
                                      capture_output=True, text=True)
                if proc.returncode:
                    print(proc.stderr, file=sys.stderr)
                    return 1
                print(proc.stdout.strip(), flush=True)
                if run >= size:
                    break
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
