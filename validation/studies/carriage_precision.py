"""What accuracy costs in time on a carriage scene: the work-precision study of the planar model.

``recoil precision towed_howitzer_45 --out DIR`` (any scene with a ``[carriage]``) calls :func:`carriage_study` and
:meth:`CarriageStudy.write`.  The engine runs the scene with each accuracy preset and with DOPRI5 and ODE23 over a
range of relative tolerances (absolute tolerance ``rtol * 1e-2``, the presets' max step); every setting is timed
as the median wall time of ``repeats`` complete ``simulate()`` runs.  Its errors are measured against the
independent planar reference (:func:`validation.reference.solve_reference`, event-driven, DOP853 at
``rtol = 1e-12``):

* relative errors of the max barrel displacement and of the peak support force (the resistance to recoil);
* the carriage's: relative error of the max pitch change, and the absolute error of the stability margin and of
  each support's least normal force relative to its static load (what the margin is made of);
* the pitch history's relative L2 error on a uniform 1 ms grid (the engine's step-end samples interpolated
  linearly: a measure of the trajectory, not of the metrics' refinement).

(The 1-D study's scipy settings are not run here: a plain ``solve_ivp`` script of the planar equations is the
reference itself.)
"""

from __future__ import annotations

import csv
import io
import math
import statistics
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from mbs_models.scene import Scene

#: Metrics of the study, in the order of the tables and figures.
METRICS = ("max_barrel_displacement", "peak_support_force", "max_carriage_pitch", "stability_margin",
           "support_loads", "pitch_l2")
METRIC_LABELS = {"max_barrel_displacement": "max barrel displacement (relative)",
                 "peak_support_force": "peak support force (relative)",
                 "max_carriage_pitch": "max carriage pitch (relative)",
                 "stability_margin": "stability margin (absolute)",
                 "support_loads": "least support loads / static (absolute, worst support)",
                 "pitch_l2": "pitch history (relative L2)"}
#: The truth's tolerances.
TRUTH_RTOL = 1e-12
#: The adaptive solvers' tolerances swept.
RTOLS = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11)


def _silent(message: str) -> None:
    pass


@dataclass
class CarriageOutcome:
    """One setting: its label, solver and tolerance, steps, median wall time (s), errors by metric (None where it
    failed), and the failure's text."""

    label: str
    solver: str
    relative_tolerance: float | None
    steps: int | None = None
    wall_time: float | None = None
    errors: dict[str, float | None] = field(default_factory=dict)
    failure: str | None = None


def _metrics_of(result) -> dict[str, Any]:
    """The compared values of an engine Result or a reference result (both give ``metrics()``)."""
    data = result.metrics()
    return {"max_barrel_displacement": data["max_barrel_displacement"],
            "peak_support_force": data["peak_support_force"],
            "max_carriage_pitch": data["max_carriage_pitch"],
            "stability_margin": data["stability_margin"],
            "supports": {s["name"]: s for s in data["supports"]}}


def errors_against(result, truth_metrics: dict, truth_pitch: Callable, static_pitch: float) -> dict[str, float]:
    """The study's errors (module docstring) of an engine ``result`` against the truth's metrics and pitch."""
    ours = _metrics_of(result)

    def relative(name: str) -> float:
        reference = truth_metrics[name]
        return abs(ours[name] - reference) / max(abs(reference), 1e-300)

    loads = max(abs(ours["supports"][name]["min_normal_force"] - s["min_normal_force"]) / s["static_normal_force"]
                for name, s in truth_metrics["supports"].items())
    grid = np.arange(0.0, float(result.time[-1]) + 1e-12, 1e-3)
    pitch = np.interp(grid, result.time, result.carriage_pitch) - static_pitch
    exact = np.asarray(truth_pitch(grid), dtype=float) - static_pitch
    scale = max(float(np.sqrt(np.mean(exact ** 2))), 1e-300)
    return {"max_barrel_displacement": relative("max_barrel_displacement"),
            "peak_support_force": relative("peak_support_force"),
            "max_carriage_pitch": relative("max_carriage_pitch"),
            "stability_margin": abs(ours["stability_margin"] - truth_metrics["stability_margin"]),
            "support_loads": loads,
            "pitch_l2": float(np.sqrt(np.mean((pitch - exact) ** 2))) / scale}


def default_settings(quick: bool = False) -> list[tuple[str, Any]]:
    """``(label, accuracy)`` pairs: the presets, then DOPRI5 and ODE23 over :data:`RTOLS`."""
    from mbs_models.engine.accuracy import ACCURACY_PRESETS, SolverSettings

    settings: list[tuple[str, Any]] = [(f"preset {name}", name) for name in ACCURACY_PRESETS]
    rtols = RTOLS[::3] if quick else RTOLS
    for solver in ("DOPRI5", "ODE23"):
        for rtol in rtols:
            settings.append((f"{solver} rtol={rtol:g}", SolverSettings(solver=solver, relative_tolerance=rtol,
                                                                      absolute_tolerance=rtol * 1e-2,
                                                                      max_step=5e-3)))
    return settings


@dataclass
class CarriageStudy:
    """The outcomes of every setting on one carriage scene (module docstring)."""

    scene_name: str
    end_time: float
    repeats: int
    truth_seconds: float
    outcomes: list[CarriageOutcome]

    def to_dict(self) -> dict:
        return {"scene": self.scene_name, "end_time": self.end_time, "repeats": self.repeats,
                "truth": f"validation.reference (planar, DOP853 rtol {TRUTH_RTOL:g})",
                "truth_seconds": self.truth_seconds, "outcomes": [asdict(o) for o in self.outcomes]}

    def csv_text(self) -> str:
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(["setting", "solver", "relative_tolerance", "steps", "wall_time [s]", *METRICS, "failure"])
        for o in self.outcomes:
            writer.writerow([o.label, o.solver, o.relative_tolerance, o.steps, o.wall_time,
                             *[o.errors.get(m) for m in METRICS], o.failure or ""])
        return buffer.getvalue()

    def table_markdown(self) -> str:
        head = "| setting | steps | time per run | " + " | ".join(METRIC_LABELS[m] for m in METRICS) + " |"
        lines = [head, "|" + "---|" * (3 + len(METRICS))]
        for o in self.outcomes:
            if o.failure:
                lines.append(f"| {o.label} | - | - | " + " | ".join("-" for _ in METRICS) + f" |  ({o.failure})")
                continue
            cells = [f"{o.errors[m]:.1e}" for m in METRICS]
            lines.append(f"| {o.label} | {o.steps} | {o.wall_time * 1e3:.0f} ms | " + " | ".join(cells) + " |")
        return "\n".join(lines)

    def summary_markdown(self) -> str:
        return (f"# What accuracy costs on a carriage scene: {self.scene_name}, {self.end_time:g} s\n\n"
                f"Errors against the independent planar reference (event-driven, DOP853 at rtol {TRUTH_RTOL:g}; "
                f"{self.truth_seconds:.1f} s to compute); time: median of {self.repeats} complete `simulate()` runs "
                "on this machine.\n\n" + self.table_markdown() + "\n")

    def figure(self):
        """Error against time per run, one panel per metric, one line per solver (the presets as stars)."""
        from mbs_models.results.plotting import new_figure

        rows = (len(METRICS) + 1) // 2
        fig, axes = new_figure(rows, 2, width=10.0, row_height=3.0)
        for k, metric in enumerate(METRICS):
            ax = axes[k // 2, k % 2]
            for solver, style in (("DOPRI5", "o-"), ("ODE23", "s-")):
                points = [(o.wall_time, o.errors[metric]) for o in self.outcomes
                          if o.solver == solver and not o.label.startswith("preset") and not o.failure]
                if points:
                    ax.loglog(*zip(*points), style, ms=4, lw=1.0, label=solver)
            for o in self.outcomes:
                if o.label.startswith("preset") and not o.failure:
                    ax.loglog([o.wall_time], [max(o.errors[metric], 1e-17)], "*", ms=10,
                              label=o.label.replace("preset ", ""))
            ax.set_title(METRIC_LABELS[metric], fontsize=9)
            ax.set_xlabel("time per run [s]")
            ax.set_ylabel("error")
            ax.legend(fontsize=7)
        for k in range(len(METRICS), rows * 2):
            axes[k // 2, k % 2].set_visible(False)
        fig.suptitle(f"work-precision on a carriage: {self.scene_name}, {self.end_time:g} s", fontsize=11)
        return fig

    def write(self, out: str | Path) -> dict[str, Path]:
        """Write ``carriage_precision.csv``, ``.json``, ``.md`` and ``work_precision_carriage.png``."""
        from mbs_models.outputs import atomic_write_json, atomic_write_text, prepare_output_dir
        from mbs_models.results.plotting import save_figure

        directory = prepare_output_dir(out)
        return {"csv": atomic_write_text(directory / "carriage_precision.csv", self.csv_text()),
                "json": atomic_write_json(directory / "carriage_precision.json", self.to_dict()),
                "markdown": atomic_write_text(directory / "carriage_precision.md", self.summary_markdown()),
                "figure": save_figure(self.figure(), directory / "work_precision_carriage.png")}


def carriage_study(scene: Scene, settings: Sequence[tuple[str, Any]] | None = None, *, end_time: float = 1.0,
                   repeats: int = 3, quick: bool = False, progress: Callable[[str], None] = _silent) -> CarriageStudy:
    """Run every setting (default :func:`default_settings`) on the carriage ``scene`` against the planar reference."""
    from mbs_models import SimulationError, simulate
    from validation.reference import solve_reference

    settings = default_settings(quick) if settings is None else list(settings)
    progress(f"truth: the planar reference at rtol {TRUTH_RTOL:g}")
    started = time.perf_counter()
    truth = solve_reference(scene, end_time, rtol=TRUTH_RTOL)
    truth_seconds = time.perf_counter() - started
    truth_metrics = _metrics_of(truth)
    static_pitch = float(truth.carriage_pitch(np.array([0.0]))[0])
    outcomes = []
    for k, (label, accuracy) in enumerate(settings):
        progress(f"{k + 1}/{len(settings)} {label}")
        solver = label.split()[0] if not label.startswith("preset") else "preset"
        rtol = getattr(accuracy, "relative_tolerance", None)
        outcome = CarriageOutcome(label, solver, rtol)
        walls = []
        try:
            for _ in range(repeats):
                result = simulate(scene, end_time, accuracy)
                walls.append(result.wall_time)
        except SimulationError as exc:
            outcome.failure = " ".join(str(exc).split())[:200]
            outcomes.append(outcome)
            continue
        outcome.steps, outcome.wall_time = result.steps, statistics.median(walls)
        outcome.errors = errors_against(result, truth_metrics, truth.carriage_pitch, static_pitch)
        outcomes.append(outcome)
    return CarriageStudy(scene.name, end_time, repeats, truth_seconds, outcomes)


__all__ = ["CarriageStudy", "CarriageOutcome", "carriage_study", "default_settings", "errors_against", "METRICS"]
