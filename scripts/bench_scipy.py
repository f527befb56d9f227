#!/usr/bin/env python
"""Issue #24's benchmark section: the product against a plain scipy script at equal accuracy per metric, and against
the code before the issue, each as ratios measured in one run.

    python scripts/bench_scipy.py            # about 1.5 minutes on the 2-core machine
    python scripts/bench_scipy.py --quick    # about 25 s
    python scripts/bench.py ...              # section 9 is this section

1. **The plain script** (``scripts/plain_scipy.py``: model (ii), m = 1000 kg, gap 0, 10 s, written from the
   equations with numpy and scipy only: ``solve_ivp`` with dense output, the three metrics from the solver's steps
   refined on the dense output).  Its yardstick: the truth, the event-driven reference at rtol 1e-12
   (:func:`validation.studies.precision.compute_truth`).
2. **Equal accuracy per metric.**  For each preset (``standard``, ``draft``: ``simulate(model_ii(1000, 0), 10,
   preset)``) and each metric separately (max barrel displacement, peak contact force, max absorber velocity), the
   preset's relative error against the truth is the target.  The plain script is run with each of solve_ivp's
   methods, RK45, DOP853, LSODA, Radau and BDF, at rtol from 1e-3 down in quarter decades to 1e-11 (half decades to
   1e-10 with ``--quick``), atol = rtol x 1e-2 (:data:`ATOL_PER_RTOL`: the presets' own ratio; the states are
   ~0.15 m and ~1 m/s).  A method's tolerance for the metric is the loosest rtol *from which on* every tighter rtol
   of the scan is at least as accurate as the preset and finds the truth's impacts (what an engineer tightening the
   tolerance can rely on; the loosest rtol that is as accurate by chance is printed beside it, not used).  The
   fastest method at its tolerance is the script an engineer would keep: the ratio is its median complete-run time
   (solve + metrics) over the preset's (``simulate``, assembly and all its post-processing included), interleaved
   rounds, wall and CPU time.  Each setting is timed twice in a warm-up; one whose faster warm-up is slower than
   :data:`PRUNE_FACTOR` x the fastest candidate of every metric it is a candidate for (in practice Radau and BDF,
   whose finite-difference Jacobians and Newton iterations run in Python) keeps its warm-up time and is left out of
   the rounds (it cannot be the fastest).  Two variants of the script: solve_ivp's default maximum step (none), and
   the presets' own maximum step, 20 ms; both find the truth's impacts on this case.
   **Why the ratio is what it is** (printed per preset and per metric): the product's steps, its complete run and
   solve per step, Exudyn's floor per step (:func:`profile_solve.run`: the same system with built-in linear laws,
   no sensors, no pre-step function, at the ``standard`` settings; a step's cost hardly depends on the tolerance)
   and the complete run it would take at the floor (the solve at the floor, the
   rest of the run as measured); the script's steps, evaluations of f and its time per evaluation; the ratio the
   script would reach against the run at the floor, and against the floor alone (the whole run at Exudyn's floor per
   step, nothing else: the most any product on Exudyn could reach at the preset's steps).

   **Fairness, both ways.**  The script is what an engineer writes from the equations: plain ``solve_ivp`` with
   dense output, the contact as ``max(0, ...)`` inside f, the damper's coefficient chosen by the sign of v_M, no
   events (the script finds every impact without them), no project code; the peaks read off its steps and refined
   on the dense output.  In the script's favour: it tunes its tolerance per metric while the product runs one
   setting for all three; the fastest of five methods is picked after the fact; the refinement of the peaks is
   more than most scripts do (it lets a looser tolerance reach the target; its cost is in the script's time);
   f returns a list of floats (a numpy array per call would cost more); the impact check is not timed.  In the
   product's favour: the *reliable* tolerance, not the lucky one.  The product's time is its complete ``simulate``
   (every metric, impact, energy and check it computes), against a script that computes three numbers.
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
METHODS = ("RK45", "DOP853", "LSODA", "Radau", "BDF")
#: Variants of the plain script: name -> solve_ivp's max_step (s).
VARIANTS = {"no max step (solve_ivp's default)": math.inf, "max step 20 ms (the presets')": 2e-2}
#: atol / rtol of the plain script (the presets' own ratio: states of ~0.1 m and ~1 m/s).
ATOL_PER_RTOL = 1e-2
#: A scipy setting slower in its warm-up (the faster of two runs) than this many times the fastest candidate of each
#: row it is a candidate of keeps its warm-up time and is left out of the rounds: it cannot win.  Wide enough that a
#: load spike on a shared machine does not drop a method that could win.
PRUNE_FACTOR = 3.0
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


def script(method: str, rtol: float, max_step: float, grid_spacing: float | None = None) -> dict:
    """One complete run of the plain script (:func:`plain_scipy.run`) at ``rtol``, atol = rtol x
    :data:`ATOL_PER_RTOL`."""
    return plain_scipy.run(method, rtol, atol=rtol * ATOL_PER_RTOL, max_step=max_step, end_time=END_TIME,
                           grid_spacing=grid_spacing)


def scan(truth: dict, impacts: int, method: str, max_step: float, rtols: list[float]) -> list[dict]:
    """The plain script at each rtol: ``{"rtol", "errors": {metric: relative error}, "impacts_ok", "steps",
    "evaluations"}``."""
    rows = []
    for rtol in rtols:
        try:
            with np.errstate(all="ignore"):
                run = script(method, rtol, max_step)
        except RuntimeError:
            rows.append({"rtol": rtol, "errors": {m: math.inf for m in METRICS}, "impacts_ok": False, "steps": None,
                         "evaluations": None})
            continue
        rows.append({"rtol": rtol, "errors": {m: relative_error(run[m], truth[m]) for m in METRICS},
                     "impacts_ok": impact_count(run["dense"], run["contact_force"]) == impacts, "steps": run["steps"],
                     "evaluations": run["evaluations"]})
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
    import profile_solve
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
            scans[variant, method] = {row["rtol"]: row for row in rows}
            for preset, engine in presets.items():
                for metric in METRICS:
                    choices.setdefault((variant, preset, metric), {})[method] = \
                        loosest(rows, metric, engine["errors"][metric])

    def candidates(variant, by_method):
        return [(method, rtol, VARIANTS[variant]) for method, (rtol, _) in by_method.items() if rtol is not None]

    configs = sorted({config for (variant, _, _), by_method in choices.items()
                      for config in candidates(variant, by_method)}, key=lambda c: (c[2], c[0], -c[1]))
    wall: dict = {}
    cpu: dict = {}

    def clock(key, function, *arguments, **keywords):
        start_wall, start_cpu = time.perf_counter(), time.process_time()
        value = function(*arguments, **keywords)
        wall.setdefault(key, []).append(time.perf_counter() - start_wall)
        cpu.setdefault(key, []).append(time.process_time() - start_cpu)
        return value

    progress(f"timing: warm-up of {len(configs)} scipy settings (each run twice)")
    with np.errstate(all="ignore"):
        for _ in range(2):
            for config in configs:
                clock(config, script, *config)
    warm_up = {config: min(wall.pop(config)) for config in configs}  # the faster of the two
    for config in configs:
        cpu.pop(config)
    timed = set()  # the settings within PRUNE_FACTOR of the fastest candidate of a row they are a candidate of
    for (variant, _, _), by_method in choices.items():
        row_configs = candidates(variant, by_method)
        if row_configs:
            fastest = min(warm_up[config] for config in row_configs)
            timed.update(config for config in row_configs if warm_up[config] <= PRUNE_FACTOR * fastest)
    timed = sorted(timed, key=configs.index)
    solve: dict[str, list[float]] = {}
    floor: list[float] = []
    for round_ in range(repeats):
        progress(f"timing: round {round_ + 1} of {repeats} ({len(timed)} scipy settings, each with the maxima "
                 f"searched on its steps and on a {GRID_SPACING * 1e3:g} ms grid; {len(PRESETS)} presets; "
                 f"Exudyn's floor)")
        for preset in PRESETS:
            solve.setdefault(preset, []).append(clock(preset, simulate, scene, END_TIME, preset).timings["solve"])
        seconds, steps = profile_solve.run(scene, "symbolic", pre_step=False, sensors=False, laws=False,
                                           end_time=END_TIME)
        floor.append(seconds / steps)
        with np.errstate(all="ignore"):
            for method, rtol, max_step in timed:
                clock((method, rtol, max_step), script, method, rtol, max_step)
                clock((method, rtol, max_step, "grid"), script, method, rtol, max_step, GRID_SPACING)
    wall = {k: statistics.median(v) for k, v in wall.items()}
    cpu = {k: statistics.median(v) for k, v in cpu.items()}
    floor_step = statistics.median(floor)
    for preset, engine in presets.items():
        engine.update(wall=wall[preset], cpu=cpu[preset], solve=statistics.median(solve[preset]),
                      floor_step=floor_step)
        # the same complete run if the solve cost Exudyn's floor per step (the rest of the run unchanged)
        engine["floor_run"] = engine["wall"] - engine["solve"] + engine["steps"] * floor_step

    rows = []
    for (variant, preset, metric), by_method in choices.items():
        engine = presets[preset]
        row = {"variant": variant, "preset": preset, "metric": metric, "target": engine["errors"][metric],
               "max_step": VARIANTS[variant], "lucky": {method: first for method, (_, first) in by_method.items()}}
        row_configs = candidates(variant, by_method)
        if row_configs:
            t, (method, rtol, max_step) = min((wall[config], config) for config in row_configs if config in timed)
            key = (method, rtol, max_step)
            run = scans[variant, method][rtol]
            row.update(method=method, rtol=rtol, atol=rtol * ATOL_PER_RTOL, error=run["errors"][metric],
                       steps=run["steps"], evaluations=run["evaluations"], scipy_wall=t, scipy_cpu=cpu[key],
                       ratio=t / engine["wall"], cpu_ratio=cpu[key] / engine["cpu"],
                       grid_ratio=wall[(*key, "grid")] / engine["wall"], floor_bound=t / engine["floor_run"],
                       ceiling=t / (engine["steps"] * engine["floor_step"]),
                       others={config[0]: ((wall[config] if config in timed else warm_up[config]) / engine["wall"],
                                           config not in timed) for config in row_configs})
        rows.append(row)
    return {"truth": truth, "impacts": impacts, "presets": presets, "rows": rows, "repeats": repeats,
            "rtols": (rtols[0], rtols[-1], len(rtols)), "pruned": len(configs) - len(timed), "settings": len(configs)}


def ms(seconds: float) -> str:
    return f"{seconds * 1e3:.3g} ms"


def us(seconds: float) -> str:
    return f"{seconds * 1e6:.2f} us"


def print_equal_accuracy(out: dict) -> None:
    first, last, count = out["rtols"]
    print(f"   truth: event-driven reference at rtol 1e-12, {out['impacts']} impacts; scipy {', '.join(METHODS)} "
          f"at rtol {first:.0e} .. {last:.0e} ({count} values), atol = rtol x {ATOL_PER_RTOL:g}; medians of "
          f"{out['repeats']} interleaved rounds ({out['pruned']} of {out['settings']} settings, slower than "
          f"{PRUNE_FACTOR:g}x the fastest in the warm-up, timed in the warm-up only)")
    for preset, engine in out["presets"].items():
        print(f"   {preset:8s}: errors " + ", ".join(f"{LABELS[m]} {engine['errors'][m]:.1e}" for m in METRICS)
              + f"; {engine['steps']} steps, {engine['impacts']} impacts; complete run {ms(engine['wall'])} "
              f"({us(engine['wall'] / engine['steps'])} per step), solve {ms(engine['solve'])} "
              f"({us(engine['solve'] / engine['steps'])} per step); Exudyn's floor {us(engine['floor_step'])} per "
              f"step: the run at the floor {ms(engine['floor_run'])}")
    for variant in VARIANTS:
        print(f"   plain scipy script, {variant}:")
        print(f"     {'preset':8s} {'metric':24s} {'target':>8s}  {'fastest at equal accuracy':56s} "
              f"{'scipy/preset':>12s} {'(CPU)':>7s} {'(grid)':>7s} {'(floor)':>7s} {'(ceil.)':>7s}  "
              f"{'issue target':14s}")
        for row in out["rows"]:
            if row["variant"] != variant:
                continue
            target = PRESETS[row["preset"]]
            head = f"     {row['preset']:8s} {LABELS[row['metric']]:24s} {row['target']:8.1e}  "
            if "ratio" not in row:
                print(head + "no method reached it down to the scan's floor")
                continue
            chosen = (f"{row['method']} rtol {row['rtol']:.2g} ({row['error']:.1e}, {row['steps']} steps, "
                      f"{row['evaluations']} f at {us(row['scipy_wall'] / row['evaluations'])})")
            print(head + f"{chosen:56s} {row['ratio']:11.2f}x {row['cpu_ratio']:6.2f}x {row['grid_ratio']:6.2f}x "
                  f"{row['floor_bound']:6.2f}x {row['ceiling']:6.2f}x  >= {target:g}x "
                  f"{'met' if row['ratio'] >= target else 'NOT met'}  [{ms(row['scipy_wall'])}]")
        print(f"     ((CPU): the ratio of CPU times; (grid): the same script searching the maxima on a "
              f"{GRID_SPACING * 1e3:g} ms grid of the dense output instead of its steps, the same values; (floor): "
              f"the ratio if the product's solve cost Exudyn's floor per step, the rest of its run unchanged; "
              f"(ceil.): the ratio if the whole run cost Exudyn's floor per step, nothing else; "
              f"'f at': the script's complete time per evaluation of f)")
        print("     (the other methods at their tolerance, scipy/preset, * timed in the warm-up only; the loosest rtol "
              "as accurate by chance):")
        for row in out["rows"]:
            if row["variant"] == variant and "ratio" in row:
                others = ", ".join(f"{m} {r:.2f}x{'*' if once else ''}" for m, (r, once) in row["others"].items())
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
            (f"early-stopped point through simulate(), CPU per point ({out['points']} points)", "point cpu", None),
            ("early-stopped sweep point as gap_sweep runs it (serial, kept systems), CPU per point", "sweep point cpu",
             1 / 1.5),
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
    """The section's numbers as JSON-ready data: the script and its search (``script``: file, methods, rtol scan,
    atol rule), per preset the product's run (steps, complete and solve time, Exudyn's floor per step), per variant,
    preset and metric the fastest plain scipy script at equal accuracy (method, rtol, atol, max step (None: none),
    the error it reached, its steps and evaluations of f, scipy / product wall-time ratio, the ratio if the product's
    solve cost Exudyn's floor and if its whole run did, the issue's target), and now / before ratios."""
    first, last, count = accuracy["rtols"]
    rows = [{"variant": row["variant"], "preset": row["preset"], "metric": LABELS[row["metric"]],
             "target_error": row["target"], "method": row.get("method"), "rtol": row.get("rtol"),
             "atol": row.get("atol"), "max_step_s": None if math.isinf(row["max_step"]) else row["max_step"],
             "error": row.get("error"), "steps": row.get("steps"), "evaluations": row.get("evaluations"),
             "ratio": row.get("ratio"), "cpu_ratio": row.get("cpu_ratio"), "floor_bound": row.get("floor_bound"),
             "ceiling": row.get("ceiling"),
             "issue_target": PRESETS[row["preset"]]} for row in accuracy["rows"]]
    presets = {preset: {"steps": engine["steps"], "complete_s": engine["wall"], "solve_s": engine["solve"],
                        "floor_step_s": engine["floor_step"], "floor_run_s": engine["floor_run"]}
               for preset, engine in accuracy["presets"].items()}
    out = {"load_at_start": start_load,
           "script": {"file": "scripts/plain_scipy.py", "methods": list(METHODS), "rtol_first": first,
                      "rtol_last": last, "rtol_count": count, "atol_per_rtol": ATOL_PER_RTOL,
                      "repeats": accuracy["repeats"]},
           "presets": presets, "scipy": rows}
    if history is not None:
        names = {"run wall": "complete standard run (wall)", "run cpu": "complete standard run (CPU)",
                 "point cpu": "early-stopped point through simulate(), fresh system (CPU per point)",
                 "sweep point cpu": "early-stopped sweep point as gap_sweep runs it, serial (CPU per point)",
                 "call cpu": "fixed cost of a call (CPU)",
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
