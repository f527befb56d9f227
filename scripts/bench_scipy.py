#!/usr/bin/env python
"""Issue #24's benchmark section: the product against a plain scipy script at equal accuracy per metric, and against
the code before the issue, each as ratios measured in one run.

    python scripts/bench_scipy.py            # about a minute on the 2-core machine
    python scripts/bench_scipy.py --quick    # about 15 s
    python scripts/bench.py ...              # section 9 is this section

1. **The plain script** (``scripts/plain_scipy.py``: model (ii), m = 1000 kg, gap 0, 10 s, written from the
   equations with numpy and scipy only: ``solve_ivp`` with dense output, the three metrics from the solver's steps
   refined on the dense output).  Its yardstick: the truth, the event-driven reference at rtol 1e-12
   (:func:`validation.studies.precision.compute_truth`).
2. **Equal accuracy per metric.**  For each preset (``standard``, ``draft``: ``simulate(model_ii(1000, 0), 10,
   preset)``) and each metric separately (max barrel displacement, peak contact force, max absorber velocity), the
   preset's relative error against the truth is the target.  The plain script is run with RK45, DOP853 and LSODA at
   rtol from 1e-3 down in quarter decades to 1e-11 (atol = rtol x 1e-2: the states are ~0.15 m and ~1 m/s, so the
   absolute tolerance is a per cent of their scale times rtol).  A method's tolerance for the metric is the loosest
   rtol *from which on* every tighter rtol of the scan is at least as accurate as the preset and finds the truth's
   impacts (what an engineer tightening the tolerance can rely on; the loosest rtol that is as accurate by chance
   is printed beside it, not used).  The fastest of the three methods at its tolerance is the script an engineer
   would keep: the ratio is its median complete-run time (solve + metrics) over the preset's (``simulate``, all
   its post-processing included), interleaved rounds, wall and CPU time.  Two variants of the script: solve_ivp's
   default maximum step (none), and a maximum step of 10 ms (an engineer's guard against stepping over a contact,
   the ``draft`` preset's and the work-precision study's); both find the truth's impacts on this case.
3. **Against the code before issue #24** (:mod:`bench_before`): a complete ``standard`` run, an early-stopped sweep
   point (CPU per point, serial), the fixed cost of a call (a 1 ms run), the engine's runs of the paper's
   ``compression_only`` reading (the step guard's windows), import to the first result in a fresh interpreter, and
   with ``--paper`` the CPU of a serial ``recoil paper --workers 1``; now / before.

The issue's targets: the scipy script / ``standard`` >= 8x, / ``draft`` >= 4x; import to the first result <= 150 ms;
a complete ``standard`` run >= 1.6x faster than before and a sweep point >= 1.5x faster; a serial ``recoil paper``
<= 30 CPU-s.  The machine is shared:
the load (``/proc/loadavg``) is printed at the start and the end.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import plain_scipy  # noqa: E402

PRESETS = {"standard": 8.0, "draft": 4.0}  # preset: the target of scipy / preset
METRICS = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity")
LABELS = {"max_barrel_displacement": "max barrel displacement", "peak_contact_force": "peak contact force",
          "max_absorber_velocity": "max absorber velocity"}
METHODS = ("RK45", "DOP853", "LSODA")
#: Variants of the plain script: name -> solve_ivp's max_step (s).
VARIANTS = {"no max step (solve_ivp's default)": math.inf, "max step 10 ms": 1e-2}
IMPACT_THRESHOLD = 1000.0  # N: an episode whose peak force exceeds it is an impact (DESIGN.md, "Outputs")
END_TIME = 10.0
#: Spacing (s) of the uniform grid of the dense output on which the script's other variant searches the maxima.
GRID_SPACING = 1e-3


def load() -> str:
    """The 1-, 5- and 15-minute load averages of the machine."""
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "unknown"


def rtol_scan(quick: bool) -> list[float]:
    """rtol from 1e-3 down to 1e-11, in quarter decades (half decades to 1e-10 with ``quick``)."""
    if quick:
        return [10.0 ** (-k / 2) for k in range(6, 21)]
    return [10.0 ** (-k / 4) for k in range(12, 45)]


def relative_error(value: float, truth: float) -> float:
    return abs(value - truth) / abs(truth) if math.isfinite(value) else math.inf


def impact_count(dense, contact_force, spacing: float = 2e-4) -> int:
    """Contact episodes (runs of force > 0 on a uniform grid of ``spacing`` s over the dense output) whose peak
    exceeds :data:`IMPACT_THRESHOLD` (a check, not timed)."""
    grid = np.arange(0.0, END_TIME + spacing / 2, spacing)
    force = contact_force(dense(grid))
    active = np.concatenate(([0], (force > 0).astype(np.int8), [0]))
    starts, ends = np.flatnonzero(np.diff(active) == 1), np.flatnonzero(np.diff(active) == -1)
    return sum(1 for a, b in zip(starts, ends) if force[a:b].max() > IMPACT_THRESHOLD)


def scan(truth: dict, impacts: int, method: str, max_step: float, rtols: list[float]) -> list[dict]:
    """The plain script at each rtol: ``{"rtol", "errors": {metric: relative error}, "impacts_ok", "steps"}``."""
    rows = []
    for rtol in rtols:
        try:
            with np.errstate(all="ignore"):
                run = plain_scipy.run(method, rtol, max_step=max_step, end_time=END_TIME)
        except RuntimeError:
            rows.append({"rtol": rtol, "errors": {m: math.inf for m in METRICS}, "impacts_ok": False, "steps": None})
            continue
        rows.append({"rtol": rtol, "errors": {m: relative_error(run[m], truth[m]) for m in METRICS},
                     "impacts_ok": impact_count(run["dense"], run["contact_force"]) == impacts, "steps": run["steps"]})
    return rows


def loosest(rows: list[dict], metric: str, target: float) -> tuple[float | None, float | None]:
    """(the loosest rtol from which on every tighter rtol of ``rows`` meets ``target`` on ``metric`` and finds the
    truth's impacts, the loosest rtol that meets it at all); None where none does."""
    ok = [row["errors"][metric] <= target and row["impacts_ok"] for row in rows]
    first = next((row["rtol"] for row, good in zip(rows, ok) if good), None)
    reliable = None
    for row, good in zip(reversed(rows), reversed(ok)):  # from the tightest up, while every one is good
        if not good:
            break
        reliable = row["rtol"]
    return reliable, first


def engine_errors(result, truth: dict) -> dict[str, float]:
    return {m: relative_error(getattr(result, m), truth[m]) for m in METRICS}


def equal_accuracy(repeats: int = 7, quick: bool = False, progress=lambda message: None) -> dict:
    """Section 2 of the module docstring: targets, tolerances and median times; see :func:`print_equal_accuracy`."""
    from mbs_models import model_ii, simulate
    from validation.studies.precision import compute_truth

    scene = model_ii(1000.0, 0.0)
    progress("truth: the event-driven reference at rtol 1e-12")
    reference = compute_truth(scene, END_TIME, check_rtol=None)
    truth = {m: getattr(reference, m) for m in METRICS}
    impacts = len(reference.impacts)
    presets = {}
    for preset in PRESETS:
        simulate(scene, END_TIME, preset)  # warm-up
        result = simulate(scene, END_TIME, preset)
        presets[preset] = {"errors": engine_errors(result, truth), "steps": result.steps,
                           "impacts": len(result.impacts)}

    rtols = rtol_scan(quick)
    choices: dict[tuple[str, str, str], dict[str, tuple]] = {}  # (variant, preset, metric) -> method -> rtols
    scans = {}
    for variant, max_step in VARIANTS.items():
        for method in METHODS:
            progress(f"scipy {method}, {variant}: rtol scan")
            rows = scan(truth, impacts, method, max_step, rtols)
            scans[variant, method] = rows
            for preset, engine in presets.items():
                for metric in METRICS:
                    choices.setdefault((variant, preset, metric), {})[method] = \
                        loosest(rows, metric, engine["errors"][metric])

    configs = sorted({(method, rtol, VARIANTS[variant]) for (variant, _, _), by_method in choices.items()
                      for method, (rtol, _) in by_method.items() if rtol is not None},
                     key=lambda c: (c[2], c[0], -c[1]))
    wall: dict = {}
    cpu: dict = {}

    def clock(key, function, *arguments, **keywords):
        start_wall, start_cpu = time.perf_counter(), time.process_time()
        function(*arguments, **keywords)
        wall.setdefault(key, []).append(time.perf_counter() - start_wall)
        cpu.setdefault(key, []).append(time.process_time() - start_cpu)

    for config in configs:  # warm-up
        plain_scipy.run(config[0], config[1], max_step=config[2], end_time=END_TIME)
    for round_ in range(repeats):
        progress(f"timing: round {round_ + 1} of {repeats} ({len(configs)} scipy settings, each with the maxima "
                 f"searched on its steps and on a {GRID_SPACING * 1e3:g} ms grid; {len(PRESETS)} presets)")
        for preset in PRESETS:
            clock(preset, simulate, scene, END_TIME, preset)
        for method, rtol, max_step in configs:
            with np.errstate(all="ignore"):
                clock((method, rtol, max_step), plain_scipy.run, method, rtol, max_step=max_step, end_time=END_TIME)
                clock((method, rtol, max_step, "grid"), plain_scipy.run, method, rtol, max_step=max_step,
                      end_time=END_TIME, grid_spacing=GRID_SPACING)
    wall = {k: statistics.median(v) for k, v in wall.items()}
    cpu = {k: statistics.median(v) for k, v in cpu.items()}

    rows = []
    for (variant, preset, metric), by_method in choices.items():
        timed = [(wall[method, rtol, VARIANTS[variant]], method, rtol) for method, (rtol, _) in by_method.items()
                 if rtol is not None]
        row = {"variant": variant, "preset": preset, "metric": metric, "target": presets[preset]["errors"][metric],
               "lucky": {method: first for method, (_, first) in by_method.items()}}
        if timed:
            t, method, rtol = min(timed)
            key = (method, rtol, VARIANTS[variant])
            errors = next(r["errors"] for r in scans[variant, method] if r["rtol"] == rtol)
            steps = next(r["steps"] for r in scans[variant, method] if r["rtol"] == rtol)
            row.update(method=method, rtol=rtol, error=errors[metric], steps=steps, scipy_wall=t,
                       scipy_cpu=cpu[key], ratio=t / wall[preset], cpu_ratio=cpu[key] / cpu[preset],
                       grid_ratio=wall[(*key, "grid")] / wall[preset],
                       others={m: wall[m, r, VARIANTS[variant]] / wall[preset] for m, (r, _) in by_method.items()
                               if r is not None})
        rows.append(row)
    return {"truth": truth, "impacts": impacts, "presets": presets, "rows": rows,
            "preset_wall": {p: wall[p] for p in PRESETS}, "preset_cpu": {p: cpu[p] for p in PRESETS},
            "repeats": repeats, "rtols": (rtols[0], rtols[-1], len(rtols))}


def ms(seconds: float) -> str:
    return f"{seconds * 1e3:.3g} ms"


def print_equal_accuracy(out: dict) -> None:
    first, last, count = out["rtols"]
    print(f"   truth: event-driven reference at rtol 1e-12, {out['impacts']} impacts; scipy rtol {first:.0e} .. "
          f"{last:.0e} ({count} values), atol = rtol x 1e-2; medians of {out['repeats']} interleaved rounds")
    for preset, engine in out["presets"].items():
        print(f"   {preset:8s}: errors " + ", ".join(f"{LABELS[m]} {engine['errors'][m]:.1e}" for m in METRICS)
              + f"; {engine['steps']} steps, {engine['impacts']} impacts [{ms(out['preset_wall'][preset])}]")
    for variant in VARIANTS:
        print(f"   plain scipy script, {variant}:")
        print(f"     {'preset':8s} {'metric':24s} {'target':>8s}  {'fastest at equal accuracy':40s} "
              f"{'scipy/preset':>12s} {'(CPU)':>7s} {'(grid)':>7s}  {'issue target':14s}")
        for row in out["rows"]:
            if row["variant"] != variant:
                continue
            target = PRESETS[row["preset"]]
            head = f"     {row['preset']:8s} {LABELS[row['metric']]:24s} {row['target']:8.1e}  "
            if "ratio" not in row:
                print(head + "no method reached it down to the scan's floor")
                continue
            chosen = f"{row['method']} rtol {row['rtol']:.2g} ({row['error']:.1e}, {row['steps']} steps)"
            print(head + f"{chosen:40s} {row['ratio']:11.2f}x {row['cpu_ratio']:6.2f}x {row['grid_ratio']:6.2f}x  "
                  f">= {target:g}x "
                  f"{'met' if row['ratio'] >= target else 'NOT met'}  [{ms(row['scipy_wall'])}]")
        print(f"     ((CPU): the ratio of CPU times; (grid): the same script searching the maxima on a "
              f"{GRID_SPACING * 1e3:g} ms grid of the dense output instead of its steps; the same values)")
        print("     (the other methods at their tolerance, scipy/preset; the loosest rtol as accurate by chance):")
        for row in out["rows"]:
            if row["variant"] == variant and "ratio" in row:
                others = ", ".join(f"{m} {r:.2f}x" for m, r in row["others"].items())
                lucky = ", ".join(f"{m} {r:.2g}" if r else f"{m} -" for m, r in row["lucky"].items())
                print(f"       {row['preset']:8s} {LABELS[row['metric']]:24s} {others};  by chance: {lucky}")


def print_before(out: dict) -> None:
    before, now = out["before"], out["now"]
    print(f"   baseline {out['commit'][:12]} imported from {before['file']}; now from {now['file']}; "
          f"same results: {out['same values']}")
    if "values" in now and "values" in before:  # a changed integration path (the max step) moves the last digits
        (x_now, steps_now), points_now = now["values"]
        (x_before, steps_before), points_before = before["values"]
        moved = max([abs(x_now - x_before) / abs(x_before)]
                    + [abs(a - b) / abs(b) for a, b in zip(points_now, points_before) if b])
        print(f"   the standard run's steps now/before {steps_now} / {steps_before} = {steps_now / steps_before:.3f}; "
              f"largest relative change of a displacement (the run and every sweep point): {moved:.1e}")
    rows = [("complete standard run, model (ii) 10 s (wall)", "run wall", 1 / 1.6),
            ("complete standard run (CPU)", "run cpu", 1 / 1.6),
            (f"early-stopped sweep point, CPU per point ({out['points']} points)", "point cpu", 1 / 1.5),
            ("fixed cost of a call: a 1 ms standard run (CPU)", "call cpu", None),
            ("the compression_only reading's engine runs, recoil paper (CPU)", "reading cpu", None),
            ("import to the first result (in the interpreter)", "import", None),
            ("import to the first result (process wall)", "import process", None),
            ("import to the first result (process CPU, user + system)", "import process cpu", None)]
    for name, key, target in rows:
        if key not in now or key not in before:
            continue
        ratio = now[key] / before[key]
        verdict = "" if target is None else \
            f"  target <= {target:.3f} ({1 / target:g}x faster): {'met' if ratio <= target else 'NOT met'}"
        print(f"   {name:58s} now/before {ratio:6.3f}  [{ms(now[key])} vs {ms(before[key])}]{verdict}")
    if "paper cpu" in now:
        ratio = now["paper cpu"] / before["paper cpu"]
        print(f"   {'full recoil paper --workers 1 (CPU s, user + system)':58s} now/before {ratio:6.3f}  "
              f"[{now['paper cpu']:.1f} s vs {before['paper cpu']:.1f} s; wall {now['paper wall']:.1f} s vs "
              f"{before['paper wall']:.1f} s]  target <= 30 s: {'met' if now['paper cpu'] <= 30.0 else 'NOT met'}")
    print(f"   import to the first result now: {ms(now['import process'])} the process's wall time (in the interpreter "
          f"{ms(now['import'])}), target <= 150 ms: {'met' if now['import process'] <= 0.150 else 'NOT met'} "
          f"(judged on the process: a CLI call or a sweep worker pays the interpreter's start too)")
    floor = out.get("floor", {})
    if floor:
        bare, libraries = floor["interpreter (python -c pass)"], floor["interpreter, numpy and Exudyn"]
        print(f"   the floor, in the same rounds: {', '.join(f'{name} {ms(value)}' for name, value in floor.items())}; "
              f"the first result above the bare interpreter {ms(now['import process'] - bare)} (before "
              f"{ms(before['import process'] - bare)}), above numpy and Exudyn {ms(now['import process'] - libraries)} "
              f"(before {ms(before['import process'] - libraries)}): this package's own share")


def run_section(quick: bool = False, repeats: int | None = None, before: bool = True, progress=None,
                paper: bool = False) -> dict:
    """Measure and print the whole section (both parts); return its summary for ``bench.py --json``
    (:func:`summary`)."""
    import bench_before

    progress = progress or (lambda message: print(f"[bench-24] {message}", file=sys.stderr, flush=True))
    start_load, start = load(), time.perf_counter()
    accuracy = equal_accuracy(repeats or (3 if quick else 7), quick, progress)
    history = None
    if before:
        with bench_before.baseline_tree() as tree:
            if tree is None:
                progress(f"no git history: the code before issue #24 ({bench_before.BASELINE_COMMIT}) is not measured")
            else:
                points = bench_before.QUICK_SWEEP_POINTS if quick else bench_before.SWEEP_POINTS
                history = bench_before.measure({"before": tree, "now": ROOT}, rounds=5 if quick else 9, points=points,
                                               import_rounds=bench_before.IMPORT_ROUNDS, progress=progress,
                                               reading_rounds=1 if quick else 3)
                history.update(commit=bench_before.BASELINE_COMMIT, points=len(points))
                if paper:  # one serial run each, alternating (minutes)
                    for name, tree_of in (("before", tree), ("now", ROOT)):
                        progress(f"before/now: recoil paper --workers 1, {name}")
                        history[name]["paper cpu"], history[name]["paper wall"] = bench_before.paper_cpu(tree_of)
    print(f"\n9. issue #24: a plain scipy script at equal accuracy per metric, and now / before the issue "
          f"(load {start_load} at the start, {load()} at the end; {time.perf_counter() - start:.0f} s)")
    print_equal_accuracy(accuracy)
    if history is not None:
        print(f"   against the code before issue #24 (commit {history['commit'][:12]}), interleaved, medians:")
        print_before(history)
    return summary(accuracy, history, start_load)


def summary(accuracy: dict, history: dict | None, start_load) -> dict:
    """The section's numbers as JSON-ready data: per variant, preset and metric the fastest plain scipy script at
    equal accuracy (method, rtol, scipy / product wall-time ratio, the issue's target), and now / before ratios."""
    rows = [{"variant": row["variant"], "preset": row["preset"], "metric": LABELS[row["metric"]],
             "target_error": row["target"], "method": row.get("method"), "rtol": row.get("rtol"),
             "ratio": row.get("ratio"), "issue_target": PRESETS[row["preset"]]} for row in accuracy["rows"]]
    out = {"load_at_start": start_load, "scipy": rows}
    if history is not None:
        names = {"run wall": "complete standard run (wall)", "run cpu": "complete standard run (CPU)",
                 "point cpu": "early-stopped sweep point (CPU per point)", "call cpu": "fixed cost of a call (CPU)",
                 "reading cpu": "the compression_only reading's engine runs (CPU)",
                 "import process": "import to the first result (process wall)"}
        out["commit"] = history["commit"]
        out["now_before"] = {label: history["now"][key] / history["before"][key] for key, label in names.items()
                             if key in history["now"] and key in history["before"]}
        out["import_process_s"] = history["now"].get("import process")
        out["import_floor_s"] = history.get("floor")
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="half-decade scan, fewer rounds and points")
    parser.add_argument("--repeats", type=int, help="interleaved timing rounds of the scipy comparison (7; quick 3)")
    parser.add_argument("--skip-before", action="store_true", help="skip the ratios against the code before #24")
    parser.add_argument("--paper", action="store_true",
                        help="also the CPU time of a serial `recoil paper --workers 1` before and now (minutes)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    run_section(args.quick, args.repeats, not args.skip_before, paper=args.paper)
    return 0


if __name__ == "__main__":
    sys.exit(main())
