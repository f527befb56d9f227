#!/usr/bin/env python
"""Post-processing against the solve: ``python scripts/profile_postprocess.py [--repeats 15] [--scene model_ii]``.

The ``standard`` run of a shipped scene (default model (ii), m = 1000 kg, gap 0, 10 s) as ``simulate``
runs it, median of ``--repeats`` runs in this process (after one warm-up):

* ``solve``: Exudyn's ``SolveDynamic`` (``Result.timings["solve"]``);
* ``after the solve``: everything ``simulate`` does after it (``Result.timings["postprocess"]``: reading
  the sensors, the stepped-over-contact check, :func:`~mbs_models.results.postprocess.analyse`, the
  energy-balance check, building the Result; always wall time), and the complete ``simulate`` minus the
  solve (the assembly before it too: an upper bound of the post-processing on either clock);
* ``analyse``: :func:`~mbs_models.results.postprocess.analyse` alone on the same samples, and its parts
  (the contacts' impacts and peaks, the support-force peak -- analyse refines both in the same
  rounds, here apart --, the energies, the extrema).

Prints each as ms and as a fraction of the solve (issue #11's target: post-processing <= 15 % of the
solve).  Not a test: absolute times depend on the machine; the ratios much less.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from mbs_models import load_scene, simulate  # noqa: E402
from mbs_models.elements.barrel import BARREL  # noqa: E402
from mbs_models.engine import driver, result_builder  # noqa: E402
from mbs_models.results import postprocess  # noqa: E402
from mbs_models.results.peaks import refine_maximum  # noqa: E402
from mbs_models.results.refinement import refine  # noqa: E402
from mbs_models.scenes import scene_path  # noqa: E402


def captured_samples(scene, end_time: float):
    """The mechanism and samples ``simulate`` hands to ``analyse`` (captured by wrapping it once)."""
    seen = {}
    original = result_builder.analyse

    def spy(mechanism, samples, *args, **kwargs):
        seen["mechanism"], seen["samples"] = mechanism, samples
        return original(mechanism, samples, *args, **kwargs)

    result_builder.analyse = spy
    try:
        simulate(scene, end_time, "standard")
    finally:
        result_builder.analyse = original
    return seen["mechanism"], seen["samples"]


CLOCK = time.perf_counter  # --cpu: time.process_time (this process's CPU time: steadier on a shared machine)


def timed(function, *args) -> float:
    start = CLOCK()
    function(*args)
    return CLOCK() - start


def solve_clock():
    """Wrap the engine's solve so that each call's time on :data:`CLOCK` is appended to the returned list."""
    seconds = []
    original = driver._solve

    def clocked(*args, **kwargs):
        start = CLOCK()
        try:
            return original(*args, **kwargs)
        finally:
            seconds.append(CLOCK() - start)

    driver._solve = clocked
    return seconds


def parts(mechanism, samples) -> dict[str, float]:
    """Seconds of analyse and of its parts on one set of samples."""
    out = {"analyse": timed(postprocess.analyse, mechanism, samples, 1000.0)}
    interp = postprocess.Interpolant(samples)
    out["  contacts (impacts, peaks)"] = timed(refine, mechanism, samples.time, samples.forces, interp,
                                               mechanism.contacts, 1000.0)
    support = postprocess.support_force_samples(mechanism, samples)
    out["  support force + its peak"] = timed(postprocess.support_force_samples, mechanism, samples) + timed(
        postprocess._refined_support_peak, mechanism, samples, interp, support)
    out["  energies"] = timed(postprocess.energies, mechanism, samples, interp)
    out["  extrema (refine_maximum)"] = timed(refine_maximum, samples.time, samples.positions[BARREL],
                                              samples.velocities[BARREL]) + sum(
        timed(refine_maximum, samples.time, samples.velocities[b.name], samples.accelerations[b.name])
        for b in mechanism.absorber_bodies)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--scene", default="model_ii")
    parser.add_argument("--end-time", type=float, default=10.0)
    parser.add_argument("--cpu", action="store_true", help="CPU time of this process instead of wall time "
                        "(the solve then as timed around the engine's _solve; 'after the solve' stays wall time)")
    args = parser.parse_args(argv)
    global CLOCK
    if args.cpu:
        CLOCK = time.process_time
    solves = solve_clock()
    scene = load_scene(scene_path(args.scene))
    mechanism, samples = captured_samples(scene, args.end_time)  # also the warm-up
    rows: dict[str, list[float]] = {}
    for _ in range(args.repeats):
        start = CLOCK()
        result = simulate(scene, args.end_time, "standard")
        run_time = CLOCK() - start
        rows.setdefault("solve", []).append(solves[-1] if args.cpu else result.timings["solve"])
        rows.setdefault("after the solve (timings['postprocess'], wall)", []).append(result.timings["postprocess"])
        rows.setdefault("complete run minus solve (assembly + after the solve)", []).append(
            run_time - rows["solve"][-1])
        for name, seconds in parts(mechanism, samples).items():
            rows.setdefault(name, []).append(seconds)
    median = {name: statistics.median(values) for name, values in rows.items()}
    solve = median["solve"]
    print(f"{args.scene}, {args.end_time:g} s, standard, {result.steps} steps; median of {args.repeats}"
          f" ({'CPU' if args.cpu else 'wall'} time)")
    print("| stage | ms | / solve |")
    print("|---|---:|---:|")
    for name, seconds in median.items():
        print(f"| {name} | {seconds * 1e3:.2f} | {seconds / solve:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
