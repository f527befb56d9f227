#!/usr/bin/env python
"""Where Exudyn's time per step goes: ``python scripts/profile_solve.py [--repeats 7]``.

The ``standard`` solve of model (ii) (m = 1000 kg, gap 0, 10 s) as ``simulate`` runs it, beside variants
that each remove one thing the product adds, measured in this process, median of ``--repeats``:

* ``product``: the assembled model, its sensors, the pre-step function (step budget), symbolic user
  functions (the contact law, and the asymmetric damper with the recoil spring folded into it:
  ``mbs_models/engine/folding.py``);
* ``one item per connector``: the same with the spring and the damper as two items (before the folding);
* ``no pre-step``: the same without the pre-step Python function (the step budget);
* ``sensors off``: the same without writing the position/velocity/acceleration/force sensors every step;
* ``python user functions``: the two laws as Python callbacks instead of symbolic ones;
* ``built-in laws``: the same items with Exudyn's built-in linear law in place of the two user functions
  (the motion differs: compare per step, not per run);
* ``Exudyn's floor``: built-in laws, no sensor stored, no pre-step function: Exudyn's own cost per step
  for this system; with one item per connector (the floor issue #24 measured against) and with the connectors on
  the same ends folded into one item (the engine's items).

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

from mbs_models.engine.exudyn_build import load_exudyn  # noqa: E402

exudyn = load_exudyn()  # the module the engine runs on (the fast one), not the one a bare import picks

from mbs_models import model_ii  # noqa: E402
from mbs_models.engine.accuracy import solver_settings_for  # noqa: E402
from mbs_models.engine.assembly import assemble  # noqa: E402
from mbs_models.engine.folding import linear_part  # noqa: E402
from mbs_models.engine.guard import StepBudget, step_budget  # noqa: E402
from mbs_models.engine.driver import _pre_step_function, exudyn_simulation_settings  # noqa: E402

END = 10.0


def run(scene, backend: str, pre_step: bool, sensors: bool, laws: bool = True,
        end_time: float = END, fold: bool = True) -> tuple[float, int]:
    """One ``standard`` solve of ``scene`` to ``end_time`` (s) with or without the pre-step function, stored sensors
    and the user functions (``laws``: False puts Exudyn's built-in linear law in their place); returns (solve wall
    time s, steps)."""
    return run_counted(scene, backend, pre_step, sensors, laws, end_time, fold)[:2]


def run_counted(scene, backend: str, pre_step: bool, sensors: bool, laws: bool = True,
                end_time: float = END, fold: bool = True) -> tuple[float, int, int]:
    """:func:`run`, and the steps the solver rejected (Exudyn's ``rejectedAutomaticStepSizeSteps``): (solve wall
    time s, accepted steps, rejected steps)."""
    settings = solver_settings_for("standard", backend)
    assembly = assemble(scene, backend, fold=fold)
    try:
        mbs = assembly.mbs
        if not laws:  # Exudyn's built-in linear law instead: the linear members' coefficients (engine/folding.py)
            for name in assembly.user_function_connectors:
                index = assembly.connectors[name]
                mbs.SetObjectParameter(index, "springForceUserFunction", 0)
                stiffness, damping = linear_part([c for c in assembly.mechanism.connectors
                                                  if assembly.connectors[c.name] == index])
                mbs.SetObjectParameter(index, "stiffness", stiffness)
                mbs.SetObjectParameter(index, "damping", damping)
        if not sensors:
            for index in assembly.sensors.values():
                mbs.SetSensorParameter(index, "storeInternal", False)
        if pre_step:
            mbs.SetPreStepUserFunction(_pre_step_function(assembly, StepBudget(step_budget(end_time)), None))
        ss = exudyn_simulation_settings(settings, end_time)
        exudyn.config.printToConsole = False
        start = time.perf_counter()
        mbs.SolveDynamic(ss, solverType=getattr(exudyn.DynamicSolverType, settings.solver))
        elapsed = time.perf_counter() - start
        counters = mbs.sys["dynamicSolver"].it
        return elapsed, int(counters.currentStepIndex), int(counters.rejectedAutomaticStepSizeSteps)
    finally:
        assembly.close()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args(argv)
    scene = model_ii(1000.0, 0.0)
    variants = {"product": ("symbolic", True, True, True, True),
                "one item per connector (not folded)": ("symbolic", True, True, True, False),
                "no pre-step": ("symbolic", False, True, True, True),
                "sensors off": ("symbolic", True, False, True, True),
                "python user functions": ("python", True, True, True, True),
                "built-in laws (no user function)": ("symbolic", True, True, False, True),
                "Exudyn's floor (built-in laws, no sensor, no pre-step)": ("symbolic", False, False, False, True),
                "Exudyn's floor, one item per connector": ("symbolic", False, False, False, False)}
    rows = {}
    for name, (backend, pre, sensors, laws, fold) in variants.items():
        run(scene, backend, pre, sensors, laws, fold=fold)  # warm-up
        samples = [run(scene, backend, pre, sensors, laws, fold=fold) for _ in range(args.repeats)]
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
