#!/usr/bin/env python
"""The cost of the planar model: a carriage scene against the 1-D scene of the same hardware, per simulated second.

    python scripts/bench_carriage.py                  # towed_howitzer and towed_howitzer_45, 10 s, standard
    python scripts/bench_carriage.py --repeats 9 --end-time 5

For each carriage scene, its 1-D twin is the same scene without ``[carriage]`` (the cradle is then the ground,
gravity acts along the axis on the barrel: DESIGN.md).  Both are run ``repeats`` times, interleaved, in this
process (``simulate`` at each accuracy preset); the ratio of the median wall times of complete runs (and of the
solves alone) is the planar model's cost per simulated second (issue #22's target: at most 3x at ``standard``).
Absolute times are printed in brackets only.

Beside it, Exudyn's floor (:func:`bare_floor`): per fixed DOPRI5 step, a bare ``ObjectKinematicTree`` of the planar
model's links (prismatic X, prismatic Y, revolute pitch, one prismatic axis link; linear coordinate springs, no
user function, no sensor) against a bare 1-D ``ObjectMass1D`` with one linear spring: what the tree costs
Exudyn before the product adds anything.  With the carriage's extra steps it bounds the ratio from below.
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


def _bare_step_cost(tree: bool, steps: int = 20000) -> float:
    """us per fixed DOPRI5 step of a bare tree (``tree``) or a bare 1-D mass (module docstring)."""
    import math
    import time

    import exudyn
    import numpy as np
    from exudyn.itemInterface import (MarkerNodeCoordinate, NodeGenericODE2, NodePointGround,
                                      ObjectConnectorCoordinateSpringDamper, ObjectKinematicTree, ObjectMass1D)

    container = exudyn.SystemContainer()
    mbs = container.AddSystem()
    n = 4 if tree else 1
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n, initialCoordinates=[0.0] * n,
                                       initialCoordinates_t=[0.0] * (n - 1) + [1.0], numberOfODE2Coordinates=n))
    if tree:
        joint = exudyn.JointType
        turn = np.array([[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]])
        mbs.AddObject(ObjectKinematicTree(
            nodeNumber=node, jointTypes=[joint.PrismaticX, joint.PrismaticY, joint.RevoluteZ, joint.PrismaticX],
            linkParents=[-1, 0, 1, 2], jointTransformations=exudyn.Matrix3DList([np.eye(3)] * 3 + [turn]),
            jointOffsets=exudyn.Vector3DList([[0.0, 0.0, 0.0]] * 3 + [[2.5, 1.0, 0.0]]),
            linkInertiasCOM=exudyn.Matrix3DList([np.zeros((3, 3))] * 2 + [np.eye(3) * 1500.0, np.eye(3)]),
            linkCOMs=exudyn.Vector3DList([[0.0, 0.0, 0.0]] * 2 + [[2.4, 0.8, 0.0], [0.0, 0.0, 0.0]]),
            linkMasses=[0.0, 0.0, 2000.0, 1000.0], gravity=[0.0, 0.0, 0.0]))
    else:
        mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=1000.0))
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    for k in range(n):
        marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=k))
        mbs.AddObject(ObjectConnectorCoordinateSpringDamper(markerNumbers=[ground, marker], stiffness=27500.0,
                                                            damping=6239.0))
    mbs.Assemble()
    settings = exudyn.SimulationSettings()
    settings.timeIntegration.endTime = 1.0
    settings.timeIntegration.numberOfSteps = steps
    settings.timeIntegration.verboseMode = 0
    settings.solutionSettings.writeSolutionToFile = False
    started = time.perf_counter()
    mbs.SolveDynamic(settings, solverType=exudyn.DynamicSolverType.DOPRI5)
    cost = (time.perf_counter() - started) / steps * 1e6
    container.Reset()
    return cost if math.isfinite(cost) else float("nan")


def bare_floor(repeats: int = 5) -> tuple[float, float]:
    """Median us per step: (bare tree, bare 1-D mass)."""
    trees, masses = [], []
    for _ in range(repeats):
        trees.append(_bare_step_cost(True))
        masses.append(_bare_step_cost(False))
    return statistics.median(trees), statistics.median(masses)


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
    tree, mass = bare_floor()
    print(f"Exudyn's floor per fixed DOPRI5 step: a bare tree of the planar links {tree / mass:5.1f}x a bare 1-D mass "
          f"[{tree:.1f} / {mass:.1f} us]")
    for row in rows:
        if row["preset"] == "standard":
            per_step_1d = row["1-D"][1] / row["1-D"][2] * 1e6
            print(f"   {row['scene']}: the bare tree alone per step is {tree / per_step_1d:4.2f}x the 1-D product's "
                  f"whole step [{per_step_1d:.1f} us]; times the {row['step_ratio']:.2f}x steps: at least "
                  f"{tree / per_step_1d * row['step_ratio']:4.1f}x per simulated second")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
