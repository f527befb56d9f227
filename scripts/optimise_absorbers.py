#!/usr/bin/env python
"""The user guide's design optimisation of the paper's absorbers (docs/guide/optimise.md):
``python scripts/optimise_absorbers.py``.

For each mount -- model (i) (absorber on the barrel) and model (ii) (absorber on the ground) -- the
absorber mass (100-2000 kg) and gap (0-120 mm) that

* A: minimise the recoil length (``max_barrel_displacement``);
* B: minimise the peak force on the mount (``peak_support_force``) with the recoil length at most the
  simplified model's (the engine's ``simplified_model()``, no absorber);

and how they compare with the paper's designs (Table 2: m = 100, 500, 1000 kg at gap 0); and, at each of
the paper's masses, the gap alone that does A and B (what the gap gains without more mass).  Differential
evolution (seed 1, population 10 per parameter, at most 30 generations for mass and gap, 20 for the gap
alone, tol 1e-4), accuracy
``standard``, every point stopped once its metrics are proven final.  Each optimum is then re-simulated
over the full 10 s (``standard`` and ``reference``) to confirm its numbers, and the early stop's saving is
measured on a sample of the evaluated points.  Writes ``docs/figures/optimise_absorbers.png`` and
``docs/optimise_absorbers.json``; prints the guide's tables.  About 1-2 minutes on 2 cores.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from mbs_models import model_i, model_ii, simplified_model, simulate  # noqa: E402
from mbs_models.outputs import atomic_write_json  # noqa: E402
from mbs_models.results.optimise_plots import draw_design_space  # noqa: E402
from mbs_models.results.plotting import new_figure, save_figure  # noqa: E402
from mbs_models.scene.models import PAPER_ABSORBER_MASSES  # noqa: E402
from mbs_models.studies.optimise import optimise  # noqa: E402

BOUNDS = {"contact.gap": (0.0, 0.12), "absorber.mass": (100.0, 2000.0)}
MOUNTS = {"model (i)": model_i, "model (ii)": model_ii}
SETTINGS = dict(seed=1, popsize=10, maxiter=30, tol=1e-4, accuracy="standard", end_time=10.0)
GAP_ONLY = {"contact.gap": BOUNDS["contact.gap"]}
GAP_ONLY_SETTINGS = {**SETTINGS, "maxiter": 20}
EARLY_STOP_SAMPLE = 24  # evaluated points re-timed with and without the early stop


def metrics_of(scene, accuracy: str = "standard") -> dict[str, float]:
    result = simulate(scene, 10.0, accuracy)
    return {"max_barrel_displacement": result.max_barrel_displacement,
            "peak_support_force": result.peak_support_force}


def early_stop_cost(factory, history, metrics: tuple[str, ...]) -> dict[str, float]:
    """Mean wall time per point (s) of full 10 s runs and of runs stopped once ``metrics`` are final, on
    an evenly spaced sample of the evaluated points, serially in this process; and the largest
    difference of the metrics between the two (they must agree)."""
    rows = history.iloc[np.linspace(0, len(history) - 1, EARLY_STOP_SAMPLE).astype(int)]
    full = early = 0.0
    largest = 0.0
    for _, row in rows.iterrows():
        scene = factory(float(row["absorber.mass"]), float(row["contact.gap"]))
        a = simulate(scene, 10.0, "standard")
        b = simulate(scene, 10.0, "standard", stop_when_final=metrics)
        full, early = full + a.wall_time, early + b.wall_time
        largest = max([largest] + [abs(getattr(a, m) - getattr(b, m)) for m in metrics])
    return {"full_run_s": full / len(rows), "early_stop_s": early / len(rows), "largest_metric_difference": largest}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=None, help="local worker processes (default: all CPUs)")
    args = parser.parse_args()
    start = time.perf_counter()
    simplified = metrics_of(simplified_model())
    limit = simplified["max_barrel_displacement"]
    print(f"simplified model: recoil length {limit * 1e3:.2f} mm, peak force on the mount "
          f"{simplified['peak_support_force'] / 1e3:.3f} kN")
    data = {"settings": {**SETTINGS, "bounds": BOUNDS, "population": SETTINGS["popsize"] * len(BOUNDS)},
            "simplified": simplified, "mounts": {}}
    fig, axes = new_figure(2, 2, width=11.0, row_height=4.3)
    for row, (mount, factory) in enumerate(MOUNTS.items()):
        paper = {f"{m:g}": metrics_of(factory(m, 0.0)) for m in PAPER_ABSORBER_MASSES}
        gap_only = {}
        for m in PAPER_ABSORBER_MASSES:
            a = optimise(factory(m, 0.0), GAP_ONLY, "max_barrel_displacement", workers=args.workers,
                         **GAP_ONLY_SETTINGS)
            b = optimise(factory(m, 0.0), GAP_ONLY, "peak_support_force", [f"max_barrel_displacement<={limit!r}"],
                         workers=args.workers, **GAP_ONLY_SETTINGS)
            gap_only[f"{m:g}"] = {
                name: {"gap": r.parameters["contact.gap"], "feasible": r.feasible, "evaluations": r.evaluations,
                       "full_run": metrics_of(factory(m, r.parameters["contact.gap"]))}
                for name, r in (("A", a), ("B", b))}
            print(f"{mount} m = {m:g} kg, gap only: A gap {a.parameters['contact.gap'] * 1e3:.2f} mm, "
                  f"B gap {b.parameters['contact.gap'] * 1e3:.2f} mm ({a.evaluations} + {b.evaluations} evaluations)")
        problems = {
            "A": optimise(factory(1000.0, 0.0), BOUNDS, "max_barrel_displacement", workers=args.workers, **SETTINGS),
            "B": optimise(factory(1000.0, 0.0), BOUNDS, "peak_support_force",
                          [f"max_barrel_displacement<={limit!r}"], workers=args.workers, **SETTINGS),
        }
        entry = {"paper_designs": paper, "gap_only": gap_only}
        for col, (name, result) in enumerate(problems.items()):
            scene = factory(result.parameters["absorber.mass"], result.parameters["contact.gap"])
            check = {accuracy: metrics_of(scene, accuracy) for accuracy in ("standard", "reference")}
            metrics = tuple(dict.fromkeys([result.minimise, *(c.metric for c in result.constraints)]))
            entry[name] = {
                "minimise": result.minimise, "constraints": [str(c) for c in result.constraints],
                "feasible": result.feasible, "parameters": result.parameters,
                "metrics": {m: result.metrics[m] for m in ("max_barrel_displacement", "peak_support_force")
                            if result.metrics[m] is not None},
                "full_run": check, "evaluations": result.evaluations, "generations": result.generations,
                "message": result.message, "wall_time_s": result.wall_time,
                "early_stop": early_stop_cost(factory, result.history, metrics),
            }
            ax = axes[row, col]
            draw_design_space(ax, result)
            for m in PAPER_ABSORBER_MASSES:
                ax.plot([0.0], [m], "s", color="white", mec="black", ms=7, clip_on=False, zorder=6)
            ax.plot([], [], "s", color="white", mec="black", ms=7, label="Table 2 designs (gap 0)")
            ax.legend(fontsize=7, loc="lower right", framealpha=0.9)
            what = "recoil length" if name == "A" else "force on the mount, recoil length <= simplified"
            ax.set_title(f"{mount}: minimise {what}", fontsize=10)
            full = check["standard"]
            print(f"{mount} {name}: m = {result.parameters['absorber.mass']:.1f} kg, gap "
                  f"{result.parameters['contact.gap'] * 1e3:.2f} mm -> recoil length "
                  f"{full['max_barrel_displacement'] * 1e3:.2f} mm, peak force on the mount "
                  f"{full['peak_support_force'] / 1e3:.3f} kN ({'feasible' if result.feasible else 'INFEASIBLE'}; "
                  f"{result.evaluations} evaluations, {result.generations} generations, {result.wall_time:.1f} s)")
        data["mounts"][mount] = entry
    out = ROOT / "docs" / "figures" / "optimise_absorbers.png"
    fig.suptitle("absorber mass and gap by differential evolution (stars: optima; squares: the paper's designs)",
                 fontsize=11)
    save_figure(fig, out)
    data["wall_time_s"] = time.perf_counter() - start
    atomic_write_json(ROOT / "docs" / "optimise_absorbers.json", data)
    print_tables(data)
    print(f"wrote {out} and docs/optimise_absorbers.json in {data['wall_time_s']:.0f} s")
    return 0


def print_tables(data) -> None:
    """The guide's table: every design's recoil length and force on the mount (full 10 s runs)."""
    simplified = data["simplified"]
    print("\n| mount | design | m (kg) | gap (mm) | recoil length (mm) | peak force on the mount (kN) |")
    print("|---|---|---|---|---|---|")
    print(f"| -- | simplified model | -- | -- | {simplified['max_barrel_displacement'] * 1e3:.2f} | "
          f"{simplified['peak_support_force'] / 1e3:.3f} |")
    for mount, entry in data["mounts"].items():
        for mass, values in entry["paper_designs"].items():
            print(f"| {mount} | Table 2 | {mass} | 0 | {values['max_barrel_displacement'] * 1e3:.2f} | "
                  f"{values['peak_support_force'] / 1e3:.3f} |")
            for name, label in (("A", "gap for min recoil length"), ("B", "gap for min force")):
                best = entry["gap_only"][mass][name]
                values = best["full_run"]
                print(f"| {mount} | {label} | {mass} | {best['gap'] * 1e3:.1f} | "
                      f"{values['max_barrel_displacement'] * 1e3:.2f} | {values['peak_support_force'] / 1e3:.3f} |")
        for name, label in (("A", "min recoil length"), ("B", "min force, length <= simplified")):
            best = entry[name]
            values = best["full_run"]["standard"]
            print(f"| {mount} | {label} | {best['parameters']['absorber.mass']:.0f} | "
                  f"{best['parameters']['contact.gap'] * 1e3:.1f} | {values['max_barrel_displacement'] * 1e3:.2f} | "
                  f"{values['peak_support_force'] / 1e3:.3f} |")
    print()
    for mount, entry in data["mounts"].items():
        for name in ("A", "B"):
            best = entry[name]
            ref = best["full_run"]["reference"]
            std = best["full_run"]["standard"]
            cost = best["early_stop"]
            optimiser_length = best["metrics"].get("max_barrel_displacement", np.nan)
            print(f"{mount} {name}: standard vs reference at the optimum: "
                  f"{abs(std['max_barrel_displacement'] - ref['max_barrel_displacement']):.1e} m, "
                  f"{abs(std['peak_support_force'] - ref['peak_support_force']):.1e} N; optimiser's values vs the "
                  f"10 s run: {abs(optimiser_length - std['max_barrel_displacement']):.1e} m; "
                  f"early stop {cost['early_stop_s'] * 1e3:.0f} ms vs full {cost['full_run_s'] * 1e3:.0f} ms per point "
                  f"(metrics equal to {cost['largest_metric_difference']:.1e})")


if __name__ == "__main__":
    sys.exit(main())
