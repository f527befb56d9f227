#!/usr/bin/env python
"""Benchmark of reusing the assembled model (:class:`mbs_models.Simulator`, issue #11), in one process.

    python scripts/bench_reuse.py                     # both parts
    python scripts/bench_reuse.py --skip-memory       # the sweep's points per second only
    python scripts/bench_reuse.py --memory-points 1000 --skip-sweep

1. **Points per second** of the paper's Figs 4/5 grid (models (i) and (ii), absorber masses 100, 500,
   1000 kg, gaps 0..120 mm in 1 mm steps: 726 points, ``stop_when_final=("max_barrel_displacement",)``,
   as validation/studies/report.py runs it), serially (one process): a fresh ``simulate`` per point (what
   sweeps did before) against one :class:`~mbs_models.Simulator`, alternating point by point over
   ``--rounds`` passes, the ratio of the totals, and where one point's time goes; the two must give the
   same displacements (``==``).
2. **Memory**: RSS over ``--memory-points`` short points (model (ii), masses and gaps cycling,
   0.2 s "draft" each) through one Simulator: the growth between the first tenth and the end must be ~0.

Not a timed test: absolute times depend on the machine and its load (printed for context); the ratio
is measured in the same run.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

MASSES = (100.0, 500.0, 1000.0)
GAPS_MM = range(0, 121)
EARLY = ("max_barrel_displacement",)


def rss_bytes() -> int:
    """Resident set size of this process in bytes (Linux /proc; else peak RSS from getrusage)."""
    try:
        with open("/proc/self/statm") as stream:
            return int(stream.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except OSError:
        import resource
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def figs_4_5_scenes():
    """The 726 scenes of the Figs 4/5 sweeps, in the report's order."""
    from mbs_models import model_i, model_ii
    return [factory(mass, gap / 1000.0) for factory in (model_i, model_ii) for mass in MASSES for gap in GAPS_MM]


def sweep_throughput(rounds: int = 2, progress=print) -> dict:
    """Points per second of the Figs 4/5 grid: fresh ``simulate`` per point against one Simulator (serial).

    The two alternate point by point (which goes first alternates too), so that a shared machine's load
    drifts into both alike; ``rounds`` passes over the grid.  Returns ``{"points", "fresh_s", "reuse_s"}``
    (seconds per sweep, mean over the rounds), ``"ratio"`` (fresh / reuse: the speed-up) and the mean split
    of one point (``"fresh_timings"``, ``"reuse_timings"``: set-up incl. assembly, solve, post-processing,
    in s).  Raises if any displacement differs.
    """
    from mbs_models import Simulator, simulate

    scenes = figs_4_5_scenes()
    total = {"fresh": 0.0, "reuse": 0.0}
    split: dict[str, dict[str, float]] = {"fresh": {}, "reuse": {}}
    with Simulator() as simulator:
        runs = {"fresh": simulate, "reuse": simulator.simulate}
        for r in range(rounds):
            for i, scene in enumerate(scenes):
                values = {}
                for kind in (("fresh", "reuse") if (i + r) % 2 else ("reuse", "fresh")):
                    start = time.perf_counter()
                    result = runs[kind](scene, 10.0, "standard", stop_when_final=EARLY)
                    total[kind] += time.perf_counter() - start
                    values[kind] = result.max_barrel_displacement
                    for part, seconds in result.timings.items():
                        split[kind][part] = split[kind].get(part, 0.0) + seconds
                if values["fresh"] != values["reuse"]:
                    raise AssertionError(f"the reused model gave another displacement for {scene.name}")
            progress(f"round {r + 1}: fresh {len(scenes) * (r + 1) / total['fresh']:.1f} points/s, "
                     f"reuse {len(scenes) * (r + 1) / total['reuse']:.1f} points/s (so far)")
    runs_done = len(scenes) * rounds
    return {"points": len(scenes), "fresh_s": total["fresh"] / rounds, "reuse_s": total["reuse"] / rounds,
            "ratio": total["fresh"] / total["reuse"],
            "fresh_timings": {k: v / runs_done for k, v in split["fresh"].items()},
            "reuse_timings": {k: v / runs_done for k, v in split["reuse"].items()}}


def memory_reuse(points: int = 10_000, end_time: float = 0.2, progress=print) -> list[tuple[int, int]]:
    """RSS (bytes) before and after each tenth of ``points`` short points through one Simulator:
    ``[(points done, bytes)]``.  Model (ii), masses and gaps cycling (every point a new set of numbers)."""
    from mbs_models import Simulator, model_ii

    marks = sorted({max(1, points * k // 10) for k in range(1, 11)})
    out = [(0, rss_bytes())]
    with Simulator() as simulator:
        for i in range(1, points + 1):
            scene = model_ii(MASSES[i % 3], (i % 121) / 1000.0)
            simulator.simulate(scene, end_time, "draft")
            if i in marks:
                out.append((i, rss_bytes()))
                progress(f"memory: {i} points, RSS {out[-1][1] / 2**20:.1f} MiB")
        assert simulator.assemblies == 1, simulator.assemblies
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=2, help="passes over the grid (default 2)")
    parser.add_argument("--memory-points", type=int, default=10_000, help="points of the memory test (default 10000)")
    parser.add_argument("--skip-sweep", action="store_true")
    parser.add_argument("--skip-memory", action="store_true")
    args = parser.parse_args(argv)
    if not args.skip_sweep:
        out = sweep_throughput(args.rounds)
        print(f"Figs 4/5 grid, {out['points']} points, serial: fresh {out['points'] / out['fresh_s']:.1f} points/s "
              f"[{out['fresh_s']:.1f} s], reuse {out['points'] / out['reuse_s']:.1f} points/s [{out['reuse_s']:.1f} s]: "
              f"x{out['ratio']:.2f}")
        for kind in ("fresh", "reuse"):
            parts = ", ".join(f"{k} {v * 1e3:.2f} ms" for k, v in out[f"{kind}_timings"].items())
            print(f"  one point, {kind}: {parts}")
    if not args.skip_memory:
        marks = memory_reuse(args.memory_points)
        first = marks[1][1]
        print(f"memory over {marks[-1][0]} points: RSS before {marks[0][1] / 2**20:.1f} MiB, after the first tenth "
              f"{first / 2**20:.1f} MiB, at the end {marks[-1][1] / 2**20:.1f} MiB "
              f"(growth after the first tenth {(marks[-1][1] - first) / 2**20:+.2f} MiB)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
