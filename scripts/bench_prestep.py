#!/usr/bin/env python
"""The pre-step function's cost on the Figs 4/5 sweep points, this version against a git ref (issue #11).

    python scripts/bench_prestep.py                    # against main, 42 points, 7 rounds
    python scripts/bench_prestep.py --against 8dd6b2f --rounds 11

Every sweep point runs ``simulate(scene, 10.0, "standard", stop_when_final=("max_barrel_displacement",))``
on a reused model; Exudyn calls the engine's Python pre-step function (step budget, onset capture,
finality tracker) at every step.  This script loads the ref's ``engine/guard.py``, ``final_metrics.py`` and
``simulation.py`` beside this checkout's (module names ``mbs_models.engine._ref_*``; everything else is
shared: against a ref with ``driver.py``, its solves are this checkout's), runs every point with both, alternating which goes first, and prints

* the CPU time (``time.process_time``) per point, median over ``--rounds``, summed over the points, and the
  ratio ref / this;
* the pre-step function's share of a point: its own time (``perf_counter_ns`` around every call, the
  wrapper's own cost subtracted) over the point's time, in a separate pass (the wrapper slows the run);
* a check that every result is bit-identical (``end_time``, ``final_metrics``, steps, the displacement);
* the solve alone of a run without the early stop (model (ii), 1000 kg, gap 0, 10 s: the pre-step function is
  the step budget only) with the ref's pre-step function, this one and none, interleaved, median CPU time.

Not a test: absolute times depend on the machine and its load; the ratio is measured in the same run.
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

MASSES = (100.0, 500.0, 1000.0)
GAPS_MM = (0, 1, 5, 10, 20, 40, 80)
EARLY = ("max_barrel_displacement",)
MODULES = ("guard", "final_metrics", "simulation")


def load_ref(ref: str):
    """The ref's ``simulation`` module, importing the ref's guard and final_metrics (everything else shared)."""
    for name in MODULES:
        source = subprocess.run(["git", "-C", str(ROOT), "show", f"{ref}:mbs_models/engine/{name}.py"],
                                check=True, capture_output=True, text=True).stdout
        for other in MODULES:
            source = source.replace(f"from .{other} import", f"from ._ref_{other} import")
        full = f"mbs_models.engine._ref_{name}"
        spec = importlib.util.spec_from_loader(full, loader=None)
        module = importlib.util.module_from_spec(spec)
        module.__package__ = "mbs_models.engine"
        module.__file__ = f"<{ref}:mbs_models/engine/{name}.py>"
        sys.modules[full] = module
        exec(compile(source, module.__file__, "exec"), module.__dict__)
    return sys.modules["mbs_models.engine._ref_simulation"]


def scenes():
    from mbs_models import model_i, model_ii
    return [factory(mass, gap / 1000.0) for factory in (model_i, model_ii) for mass in MASSES for gap in GAPS_MM]


def fingerprint(result) -> tuple:
    return (result.end_time, result.final_metrics, result.steps, result.max_barrel_displacement,
            result.time_of_max_barrel_displacement, result.stop_reason)


def timing_wrapper(inner, totals: list):
    """``inner(mbs, t)`` wrapped so that each call's time adds to ``totals[0]`` (ns) and counts in ``totals[1]``."""

    def pre_step(mbs, t):
        start = time.perf_counter_ns()
        try:
            return inner(mbs, t)
        finally:
            totals[0] += time.perf_counter_ns() - start
            totals[1] += 1

    return pre_step


def timed_pre_step(module, totals: list):
    """Wrap ``module._pre_step_function`` so that every call's time adds to ``totals[0]`` (ns)."""
    original = module._pre_step_function

    def factory(*args):
        inner = original(*args)
        pre_step = timing_wrapper(inner, totals)
        pre_step.new_solve = inner.new_solve
        return pre_step

    module._pre_step_function = factory
    return original


def wrapper_overhead_ns() -> float:
    """The cost (ns) the timing wrapper adds to a call, measured on an empty function."""
    totals = [0, 0]

    def inner(mbs, t):
        return True

    pre_step = timing_wrapper(inner, totals)

    n = 200_000
    start = time.perf_counter_ns()
    for _ in range(n):
        inner(None, 0.0)
    bare = time.perf_counter_ns() - start
    start = time.perf_counter_ns()
    for _ in range(n):
        pre_step(None, 0.0)
    wrapped = time.perf_counter_ns() - start
    return max(wrapped - bare, 0) / n


def budget_only_solves(ref, rounds: int) -> dict[str, float]:
    """Median CPU time (s) of the solve of model (ii) (1000 kg, gap 0, 10 s, ``standard``) with the step budget's
    pre-step function of ``ref``, of this checkout, and with none; the three interleaved."""
    import exudyn

    from mbs_models import model_ii
    from mbs_models.engine import driver, guard
    from mbs_models.engine.accuracy import solver_settings_for
    from mbs_models.engine.assembly import assemble

    ref_guard = sys.modules["mbs_models.engine._ref_guard"]
    settings = solver_settings_for("standard", "symbolic")
    installs = {"ref": lambda a: ref._pre_step_function(a, ref_guard.StepBudget(ref_guard.step_budget(10.0)), None),
                "this": lambda a: driver._pre_step_function(a, guard.StepBudget(guard.step_budget(10.0)), None),
                "none": None}
    cpu = {kind: [] for kind in installs}
    for r in range(rounds):
        for kind in (list(installs) if r % 2 else list(installs)[::-1]):
            assembly = assemble(model_ii(1000.0, 0.0), "symbolic")
            try:
                if installs[kind] is not None:
                    assembly.mbs.SetPreStepUserFunction(installs[kind](assembly))
                ss = driver.exudyn_simulation_settings(settings, 10.0)
                exudyn.config.printToConsole = False
                start = time.process_time()
                assembly.mbs.SolveDynamic(ss, solverType=getattr(exudyn.DynamicSolverType, settings.solver))
                cpu[kind].append(time.process_time() - start)
            finally:
                assembly.close()
    return {kind: statistics.median(values) for kind, values in cpu.items()}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", default="main", help="git ref of the old code (default main)")
    parser.add_argument("--rounds", type=int, default=7, help="passes over the points (median per point)")
    args = parser.parse_args(argv)

    from mbs_models import Simulator
    from mbs_models.engine import driver
    from mbs_models.engine import simulation as this

    ref = load_ref(args.against)
    points = scenes()
    runs = {"ref": ref.simulate_with, "this": this.simulate_with}
    cpu = {kind: [[] for _ in points] for kind in runs}
    with Simulator() as sim_ref, Simulator() as sim_this:
        models = {"ref": sim_ref, "this": sim_this}
        for kind in runs:  # warm up: assemble each structure once
            for scene in points[:: len(GAPS_MM) * len(MASSES)]:
                runs[kind](models[kind], scene, 10.0, "standard", stop_when_final=EARLY)
        for r in range(args.rounds):
            for i, scene in enumerate(points):
                found = {}
                for kind in (("ref", "this") if (i + r) % 2 else ("this", "ref")):
                    start = time.process_time()
                    result = runs[kind](models[kind], scene, 10.0, "standard", stop_when_final=EARLY)
                    cpu[kind][i].append(time.process_time() - start)
                    found[kind] = fingerprint(result)
                if found["ref"] != found["this"]:
                    raise AssertionError(f"{scene.name}: {found['ref']} != {found['this']}")
        per_point = {kind: [statistics.median(c) for c in cpu[kind]] for kind in runs}
        total = {kind: sum(per_point[kind]) for kind in runs}
        print(f"{len(points)} points (models (i), (ii); masses {MASSES} kg; gaps {GAPS_MM} mm), {args.rounds} rounds, "
              "results identical")
        for kind in runs:
            print(f"  {kind:>4} ({args.against if kind == 'ref' else 'checkout'}): "
                  f"{1e3 * total[kind] / len(points):.2f} ms CPU per point (mean of the per-point medians)")
        print(f"  ratio ref / this: {total['ref'] / total['this']:.3f}")

        # the pre-step's share, in a separate pass with the timing wrapper (interleaved the same way)
        overhead = wrapper_overhead_ns()
        modules = {"ref": ref, "this": driver}  # where each side's pre-step function is looked up
        totals = {kind: [0, 0] for kind in runs}
        elapsed = {kind: 0.0 for kind in runs}
        originals = {kind: timed_pre_step(modules[kind], totals[kind]) for kind in runs}
        try:
            for r in range(max(1, args.rounds // 3)):
                for i, scene in enumerate(points):
                    for kind in (("ref", "this") if (i + r) % 2 else ("this", "ref")):
                        start = time.process_time()
                        runs[kind](models[kind], scene, 10.0, "standard", stop_when_final=EARLY)
                        elapsed[kind] += time.process_time() - start
        finally:
            for kind in runs:
                modules[kind]._pre_step_function = originals[kind]
        for kind in runs:
            calls = totals[kind][1]
            own = (totals[kind][0] - overhead * calls) * 1e-9
            print(f"  {kind:>4}: pre-step {1e6 * own / calls:.2f} us per call, {calls} calls, "
                  f"{100 * own / (elapsed[kind] - overhead * calls * 1e-9):.1f} % of the points' CPU time "
                  f"(wrapper {overhead:.0f} ns per call subtracted)")
    solves = budget_only_solves(ref, 3 * args.rounds)
    print(f"solve without the early stop (model (ii), 1000 kg, gap 0; step budget only), median of {3 * args.rounds}: "
          + ", ".join(f"{kind} {1e3 * seconds:.2f} ms" for kind, seconds in solves.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
