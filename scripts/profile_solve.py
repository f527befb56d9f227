#!/usr/bin/env python
"""Where Exudyn's time per step goes: ``python scripts/profile_solve.py [--repeats 7]``.

The ``standard`` solve of model (ii) (m = 1000 kg, gap 0, 10 s) as ``simulate`` runs it, beside variants
that each remove one thing the product adds, measured in this process, median of ``--repeats``:

* ``product``: the assembled model, its sensors, the pre-step function (step budget), symbolic user
  functions (the contact law and the asymmetric damper);
* ``no pre-step``: the same without the pre-step Python function (the step budget);
* ``sensors off``: the same without writing the position/velocity/acceleration/force sensors every step;
* ``python user functions``: the two laws as Python callbacks instead of symbolic ones;
* ``stripped``: no user function, no sensor, no pre-step: the simplified model with a symmetric damper
  (Exudyn's built-in linear spring-damper only; one body instead of two: compare per step, not per run).

Not a test: absolute times depend on the machine; the per-step ratios much less.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import exudyn  # noqa: E402

from mbs_models import model_ii  # noqa: E402
from mbs_models.engine.accuracy import solver_settings_for  # noqa: E402
from mbs_models.engine.assembly import assemble  # noqa: E402
from mbs_models.engine.guard import StepBudget, step_budget  # noqa: E402
from mbs_models.engine.simulation import _pre_step_function, exudyn_simulation_settings  # noqa: E402

END = 10.0


def run(scene, backend: str, pre_step: bool, sensors: bool) -> tuple[float, int]:
    settings = solver_settings_for("standard", backend)
    assembly = assemble(scene, backend)
    try:
        mbs = assembly.mbs
        if not sensors:
            for index in assembly.sensors.values():
                mbs.SetSensorParameter(index, "storeInternal", False)
        if pre_step:
            mbs.SetPreStepUserFunction(_pre_step_function(assembly, StepBudget(step_budget(END)), None))
        ss = exudyn_simulation_settings(settings, END)
        exudyn.config.printToConsole = False
        start = time.perf_counter()
        mbs.SolveDynamic(ss, solverType=getattr(exudyn.DynamicSolverType, settings.solver))
        elapsed = time.perf_counter() - start
        return elapsed, int(mbs.sys["dynamicSolver"].it.currentStepIndex)
    finally:
        assembly.close()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args(argv)
    scene = model_ii(1000.0, 0.0)
    from mbs_models import simplified_model
    stripped = simplified_model().with_changes(**{"recoil_damper.counter_recoil": 6239.0})
    variants = {"product": (scene, "symbolic", True, True), "no pre-step": (scene, "symbolic", False, True),
                "sensors off": (scene, "symbolic", True, False), "python user functions": (scene, "python", True, True),
                "stripped (no user function)": (stripped, "symbolic", False, False)}
    rows = {}
    for name, (sc, backend, pre, sensors) in variants.items():
        run(sc, backend, pre, sensors)  # warm-up
        samples = [run(sc, backend, pre, sensors) for _ in range(args.repeats)]
        seconds = statistics.median(s for s, _ in samples)
        steps = samples[0][1]
        rows[name] = (seconds, steps, seconds / steps)
    base = rows["product"][2]
    print("| variant | solve | steps | per step | per step / product |")
    print("|---|---:|---:|---:|---:|")
    for name, (seconds, steps, per_step) in rows.items():
        print(f"| {name} | {seconds * 1e3:.1f} ms | {steps} | {per_step * 1e6:.2f} us | {per_step / base:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
