"""The replication report: ``recoil paper --out DIR`` writes ``report.html`` and ``results.json``.

One self-contained HTML file (figures embedded as PNG data) for a reviewer of the replication:
a header (the paper replicated; date, package version and commit, libraries, machine), the verdict
in one paragraph, the table of contents, the models and their equations, parameters, Table 2
(ours, paper, difference), the gap sweeps (Figs 4-5), time histories (Figs 6-8) and the energy
of each element (m = 1000 kg), contact force and absorber velocity (Figs 9-11),
engine-vs-reference errors for every case shown, the convention study, the contact-law
calibration, the paper's qualitative claims checked, and a plain list of every published number we
cannot reproduce with its most likely reason.  PNG files, ``table2.md`` and ``table2.json`` are
written beside it.  Everything is written under a temporary name and renamed.

The page shows displacements in mm and forces in kN (:data:`DISPLAY_UNITS`); ``results.json`` and
``table2.json`` stay in SI units.
"""

from __future__ import annotations

import base64
import html
import importlib
import math
import multiprocessing
import os
import re
import textwrap
import time
import warnings
from concurrent.futures import as_completed
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Callable

import numpy as np

from mbs_models import model_i, model_ii, simplified_model, simulate
from mbs_models.scene.models import model_i as _model_i_doc, model_ii as _model_ii_doc, simplified_model as _simp_doc
from mbs_models.outputs import atomic_write_json, atomic_write_text, check_output_dir, prepare_output_dir
from mbs_models.scene import Scene
from mbs_models.studies.sweep import default_workers, process_pool, run_sweep_jobs, sweep_jobs

from .carriage_report import (CARRIAGE_SCENES, carriage_figure, carriage_html, carriage_job, carriage_rows,
                              carriage_table)
from .claims import ClaimEvidence, evaluate_claims
from .compare import compare
from .conventions import (CONVENTION_CASES, TREND_GAPS, convention_jobs, convention_rows, engine_job,
                          reference_job)
from .paper import MODEL_I, MODEL_II, SIMPLIFIED, TABLE2_MASSES, published, published_values, table2
from .progress import counter
from .provenance import FIELDS as PROVENANCE_FIELDS, provenance

Progress = Callable[[str], None]
#: A published number counts as reproduced when ours is within this relative difference.
REPRODUCED_WITHIN = 0.01


def _silent(message: str) -> None:
    pass


@dataclass(frozen=True)
class ReportOptions:
    """What the report computes.  The defaults are the full study; tests use :meth:`reduced`."""

    gap_step: float = 0.001                  # m, the sweeps of Figs 4-5 (0 to 120 mm)
    gap_max: float = 0.12                    # m
    masses: tuple[float, ...] = TABLE2_MASSES
    comparison_gaps: tuple[float, ...] = (0.0, 0.04, 0.08)
    convention_labels: tuple[str, ...] | None = None   # None: every reading
    calibration_parameters: tuple[str, ...] = ("stiffness", "exponent", "damping_factor")
    calibration_bounds: dict = field(default_factory=lambda: {"exponent": (0.5, 2.5)})
    accuracy: str = "standard"
    end_time: float = 10.0
    workers: int | None = None
    studies: bool = True                     # False: no convention study, no calibration (--reproduce-only)
    carriage: bool = True                    # the shipped towed_howitzer at 0 and 45 degrees, engine and reference

    @classmethod
    def reduced(cls, **changes) -> "ReportOptions":
        """A small but complete report (every section and figure) for tests."""
        default = next(label for label, conventions in CONVENTION_CASES if not conventions.active)
        base = dict(gap_step=0.02, comparison_gaps=(0.0,), convention_labels=(default, "literal_gap_sign"),
                    calibration_parameters=("stiffness", "damping_factor"), calibration_bounds={})
        base.update(changes)
        return cls(**base)

    @classmethod
    def reproduction(cls, **changes) -> "ReportOptions":
        """The paper's results only: Table 2 (engine and reference at gap 0), the full gap sweeps, every
        figure of the paper and the report, without the convention study, the calibration and the
        engine-vs-reference cases at gaps 40 and 80 mm (``recoil paper --reproduce-only``)."""
        base = dict(comparison_gaps=(0.0,), studies=False)
        base.update(changes)
        return cls(**base)


# --------------------------------------------------------------------------------------------- compute
def _comparison_job(scene: Scene) -> tuple[dict, object]:
    """The comparison of one case as a dict, and the engine's 10 s run of a gap-0 case (reused for Figs 6-11)."""
    comparison = compare(scene, 10.0, "standard")
    data = comparison.to_dict()
    data["model"] = scene.model_label
    data["absorber_mass"] = scene.absorber.mass if scene.absorber else None
    data["gap"] = scene.contact.gap if scene.contact else None
    # the force on the mount (N, engine only: the reference does not compute it), for Table 2
    data["engine_peak_support_force"] = comparison.engine.peak_support_force
    data["engine_time_of_peak_support_force"] = comparison.engine.time_of_peak_support_force
    return data, (comparison.engine if not data["gap"] else None)


def _comparison_scenes(options: ReportOptions) -> list[Scene]:
    scenes = [simplified_model()]
    for factory in (model_i, model_ii):
        scenes += [factory(m, g) for m in options.masses for g in options.comparison_gaps]
    return scenes


def _counter(progress: Progress, label: str):
    """A (done, total) progress callback: a tqdm bar from the command line, else a line about every quarter."""
    return counter(progress, label)


def _timed(function: Callable, *args) -> tuple[float, object]:
    """``(seconds, function(*args))``: a job of the report's pool with its own run time."""
    start = time.perf_counter()
    value = function(*args)
    return time.perf_counter() - start, value


def _calibration_job(parameters: tuple[str, ...], bounds: dict | None) -> tuple[object, list[dict]]:
    """The contact-law calibration on Section 2.2 and its Table 2 prediction (one job: they run in order)."""
    from .calibration import paper_section22_calibration, predict_table2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        calibration = paper_section22_calibration(parameters, bounds=bounds)
    return calibration, predict_table2(calibration)


#: Gap-sweep runs per job of the report's pool (~10 ms each: small jobs even out the workers' ends).
SWEEP_CHUNK = 12


class _Stage:
    """The jobs of one stage of the report: their results in submission order, progress, run time."""

    def __init__(self, name: str, total: int, progress: Progress):
        self.name, self.total, self.done, self.seconds = name, total, 0, 0.0
        self.results: list = [None] * total
        self.report = _counter(progress, name)

    def finish(self, index: int, seconds: float, value) -> None:
        self.results[index] = value
        self.seconds += seconds
        self.done += 1
        self.report(self.done, self.total)


def compute_report(options: ReportOptions = ReportOptions(), progress: Progress = _silent) -> dict:
    """Run every computation of the report; return a dict of results (figures are made later).

    Every run of every stage (engine vs reference, gap sweeps, convention study, calibration) is a job of
    one pool of ``options.workers`` processes: the stages share the CPUs side by side instead of one after
    the other, the longest jobs first and the small sweep chunks last so that the workers finish together.
    ``data["timings"][stage]`` is the run time of the stage's jobs added up over the workers (s).
    """
    timings: dict[str, float] = {}
    data: dict = {"options": {k: v for k, v in options.__dict__.items()}}
    data["machine"] = {"cpus": os.cpu_count(), "workers": options.workers or default_workers(),
                       "load_average_at_start": round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None}

    scenes = _comparison_scenes(options)
    if options.comparison_gaps == (0.0, 0.04, 0.08) and options.masses == TABLE2_MASSES:
        assert len(scenes) == 19
    gaps = np.round(np.arange(0.0, options.gap_max + 1e-12, options.gap_step), 6)
    sweep_scenes = [factory(m, float(g)) for factory in (model_i, model_ii) for m in options.masses for g in gaps]
    jobs = sweep_jobs(sweep_scenes, options.end_time, options.accuracy, stop_when_final=("max_barrel_displacement",))
    chunks = [jobs[i:i + SWEEP_CHUNK] for i in range(0, len(jobs), SWEEP_CHUNK)]
    cases = [c for c in CONVENTION_CASES if options.convention_labels is None or c[0] in options.convention_labels]
    convention_runs = convention_jobs(tuple(cases)) if options.studies else []
    convention_scenes = [scene for _, _, scene in convention_runs]

    progress(f"engine vs reference on the paper cases ({len(scenes)}), gap sweeps ({len(gaps)} gaps x "
             f"{len(options.masses)} masses x 2 models)" + (", convention study and contact-law calibration on "
                                                            "Section 2.2" if options.studies else ""))
    # (stage, function, items): submitted in this order, the longest jobs first
    plan: list[tuple[str, Callable, list]] = []
    if options.studies:
        plan.append(("calibration", _calibration_job,
                     [(options.calibration_parameters, options.calibration_bounds or None)]))
        plan.append(("convention study (engine)", engine_job, [(s,) for s in convention_scenes]))
    plan.append(("engine vs reference", _comparison_job, [(s,) for s in scenes]))
    if options.studies:
        plan.append(("convention study (reference)", reference_job, [(s,) for s in convention_scenes]))
    if options.carriage:
        plan.append(("the gun on its carriage", carriage_job, [(name,) for name, _ in CARRIAGE_SCENES]))
    plan.append(("gap sweeps", run_sweep_jobs, [(chunk,) for chunk in chunks]))

    start = time.perf_counter()
    stages = {name: _Stage(name, len(items), progress) for name, _, items in plan}
    with process_pool(options.workers) as pool:
        pending = {}
        for name, function, items in plan:
            for index, args in enumerate(items):
                future = pool.submit(_timed, function, *args)
                if future.done():  # run in this process (workers=1): report it now
                    stages[name].finish(index, *future.result())
                else:
                    pending[future] = (name, index)
        # matplotlib is needed for the figures only: import it here while the workers compute (they were
        # forked without it)
        importlib.import_module("mbs_models.results.plotting")
        for future in as_completed(pending):
            name, index = pending[future]
            stages[name].finish(index, *future.result())
    compute_wall = time.perf_counter() - start

    data["carriage"] = stages["the gun on its carriage"].results if options.carriage else []
    if options.carriage:
        timings["the gun on its carriage"] = stages["the gun on its carriage"].seconds
    outputs = stages["engine vs reference"].results
    data["comparisons"] = [case for case, _ in outputs]
    timings["engine vs reference"] = stages["engine vs reference"].seconds

    start = time.perf_counter()
    # the comparisons ran the gap-0 cases for 10 s at "standard" already: reuse those runs when they match
    compared = {(run.scene.model_label, run.scene.absorber.mass if run.scene.absorber else None): run
                for _, run in outputs if run is not None}
    reuse = options.end_time == 10.0 and options.accuracy == "standard"

    def run_of(label: str, mass: float | None, scene_factory) -> object:
        if reuse and (label, mass) in compared:
            return compared[(label, mass)]
        return simulate(scene_factory(), options.end_time, options.accuracy)

    runs = {SIMPLIFIED: run_of(SIMPLIFIED, None, simplified_model)}
    for mass in options.masses:
        runs[(MODEL_I, mass)] = run_of(MODEL_I, mass, lambda: model_i(mass, 0.0))
        runs[(MODEL_II, mass)] = run_of(MODEL_II, mass, lambda: model_ii(mass, 0.0))
    data["runs"] = runs
    timings["time histories"] = time.perf_counter() - start

    points = [point for chunk in stages["gap sweeps"].results for point in chunk]
    sweeps: dict[tuple[str, float], list[tuple[float, float]]] = {}
    failures = []
    for point in points:
        key = (point.scene.model_label, point.scene.absorber.mass)
        if point.error:
            failures.append({"scene": point.scene.name, "error": point.error})
            continue
        sweeps.setdefault(key, []).append((point.gap, point.max_barrel_displacement))
    data["sweeps"], data["sweep_failures"] = sweeps, failures
    timings["gap sweeps"] = stages["gap sweeps"].seconds

    data["conventions"], data["calibration"], data["calibration_table2"] = [], None, []
    if options.studies:
        data["conventions"] = convention_rows(tuple(cases), convention_runs,
                                              stages["convention study (reference)"].results,
                                              stages["convention study (engine)"].results)
        timings["convention study"] = (stages["convention study (reference)"].seconds
                                       + stages["convention study (engine)"].seconds)
        data["calibration"], data["calibration_table2"] = stages["calibration"].results[0]
        timings["calibration"] = stages["calibration"].seconds
    timings["all studies side by side (wall)"] = compute_wall

    x_max = {(SIMPLIFIED, m): runs[SIMPLIFIED].max_barrel_displacement for m in TABLE2_MASSES}
    for mass in options.masses:
        for label in (MODEL_I, MODEL_II):
            x_max[(label, mass)] = runs[(label, mass)].max_barrel_displacement
    data["x_max"] = x_max
    if set(TABLE2_MASSES) <= set(options.masses):  # the claims compare the three masses
        evidence = ClaimEvidence(x_max=x_max, runs={MODEL_I: runs[(MODEL_I, 1000.0)],
                                                    MODEL_II: runs[(MODEL_II, 1000.0)]}, sweeps=sweeps)
        data["claims"] = evaluate_claims(evidence)
    data["timings"] = timings
    return data


# ------------------------------------------------------------------------------------------- figures
def _sweep_figure(data: dict, model: str, fig_number: int):
    from mbs_models.results.plotting import MODEL_COLOURS, new_figure
    fig, axes = new_figure(1, 1, row_height=3.8)
    ax = axes[0, 0]
    colours = {100.0: "#2ca02c", 500.0: "#ff7f0e", 1000.0: "#9467bd"}
    for mass in data["options"]["masses"]:
        points = data["sweeps"].get((model, mass), [])
        if points:
            gaps, values = zip(*points)
            ax.plot(np.array(gaps) * 1e3, np.array(values) * 1e3, color=colours.get(mass), label=f"m = {mass:g} kg")
    reference = [(c["gap"], next(x for x in c["checks"] if x["name"] == "max_barrel_displacement")["reference"],
                  c["absorber_mass"]) for c in data["comparisons"] if c["model"] == model]
    if reference:
        ax.plot([r[0] * 1e3 for r in reference], [r[1] * 1e3 for r in reference], "kx", ms=7,
                label="independent reference")
    simple = data["runs"][SIMPLIFIED].max_barrel_displacement
    ax.axhline(simple * 1e3, color=MODEL_COLOURS[SIMPLIFIED], ls="--", lw=1, label=f"simplified {simple * 1e3:.1f} mm")
    ax.set_xlabel("gap [mm]")
    ax.set_ylabel("max barrel displacement [mm]")
    ax.set_title(f"Fig. {fig_number}: max barrel displacement vs gap, {model}", fontsize=11)
    ax.legend(fontsize=9)
    return fig


#: Each reading of the paper (the flags of :class:`mbs_models.Conventions`, :data:`CONVENTION_CASES`) in plain
#: words for the text, and a short name for legends.
READINGS = {
    "default": ("our reading: the exact initial velocity, the contact damping as in Hunt-Crossley, the gap as a "
                "clearance", "default"),
    "literal_lambda_sign": ("the contact damping's sign as printed in Eq. (6), which adds energy during compression",
                            "damping sign as printed"),
    "compression_only": ("the contact force acts only while the contact is being compressed", "compression only"),
    "v0_includes_absorber": ("the initial velocity includes the absorber's mass, in model (i)",
                             "v0 includes the absorber"),
    "rounded_initial_velocity": ("the initial velocity as printed, 0.7 m/s, instead of 0.6909 m/s", "v0 = 0.7 m/s"),
    "literal_gap_sign": ("the gap's sign as printed in Eq. (6), which makes the gap an interference",
                         "gap sign as printed"),
}


def reading_text(label: str) -> str:
    """A reading of the paper in plain words."""
    return READINGS.get(label, (label.replace("_", " "),))[0]


def reading_short(label: str) -> str:
    return READINGS.get(label, (None, label.replace("_", " ")))[1]


def coinciding_readings(rows) -> dict[str, str]:
    """Readings whose Fig. 5 trend equals an earlier reading's (label -> that earlier label): their lines coincide."""
    out: dict[str, str] = {}
    for i, row in enumerate(rows):
        for earlier in rows[:i]:
            if earlier.label not in out and np.allclose(row.trend(), earlier.trend(), rtol=1e-9, atol=0.0):
                out[row.label] = earlier.label
                break
    return out


#: (line style, marker) per reading of the convention figure: no two alike, so that no line hides another.
_READING_STYLES = (("-", "o"), ("--", "s"), ("-.", "^"), (":", "D"), ("-", "v"), ("--", "P"), ("-.", "X"), (":", "*"))


def _convention_figure(data: dict):
    from mbs_models.results.plotting import new_figure
    fig, axes = new_figure(1, 1, row_height=3.6)
    ax = axes[0, 0]
    rows = data["conventions"]
    same = coinciding_readings(rows)
    for i, row in enumerate(rows):
        style, marker = _READING_STYLES[i % len(_READING_STYLES)]
        label = reading_short(row.label)
        if row.label in same:   # drawn over the line it equals: hollow, larger markers, dashed
            label += f" (coincides with {reading_short(same[row.label])})"
            ax.plot(np.array(TREND_GAPS) * 1e3, np.array(row.trend()) * 1e3, ls="--", marker=marker, ms=10,
                    mfc="none", mew=1.5, lw=1.5, label=label, zorder=3)
        else:
            ax.plot(np.array(TREND_GAPS) * 1e3, np.array(row.trend()) * 1e3, ls=style, marker=marker, ms=5,
                    label=label)
    ax.set_xlabel("gap [mm]")
    ax.set_ylabel("max barrel displacement [mm]")
    ax.set_title("Model (ii), m = 1000 kg: each reading of the paper vs gap (Fig. 5 claims a maximum at gap 0)",
                 fontsize=10)
    ax.legend(fontsize=8)
    return fig


#: The force on the mount is drawn over the first seconds only (the largest forces come before 1 s).
MOUNT_FORCE_WINDOW = 2.0   # s


def mount_force_mass(data: dict) -> float:
    """The absorber mass of the force-on-the-mount figure: 1000 kg, the largest mass of the paper."""
    return max(data["options"]["masses"])


def _mount_force_figure(data: dict, mass: float):
    """The force on the mount (support force, kN) vs time of the three models at one absorber mass, gap 0."""
    from mbs_models.results.plotting import MODEL_COLOURS, new_figure
    fig, axes = new_figure(1, 1, row_height=3.6)
    ax = axes[0, 0]
    runs = data["runs"]
    for run in (runs[SIMPLIFIED], runs[(MODEL_I, mass)], runs[(MODEL_II, mass)]):
        run = run.densified()  # the histories 1 ms apart at most (the solver's steps reach 20 ms)
        model, colour = run.scene.model_label, MODEL_COLOURS.get(run.scene.model_label)
        shown = run.time <= MOUNT_FORCE_WINDOW
        label = model
        if run.peak_support_force is not None:
            t_peak = run.time_of_peak_support_force
            label += f": peak |S| {run.peak_support_force / 1e3:.2f} kN at {t_peak:.3f} s"
            if t_peak <= MOUNT_FORCE_WINDOW:
                sign = 1.0 if np.interp(t_peak, run.time, run.support_force) >= 0 else -1.0
                ax.plot([t_peak], [sign * run.peak_support_force / 1e3], "o", color=colour, ms=4)
        ax.plot(run.time[shown], run.support_force[shown] / 1e3, color=colour, lw=1.2, label=label)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("support force S [kN]")
    ax.set_title(f"Force on the mount, m = {mass:g} kg, gap 0 (S > 0: pushed in the recoil direction)", fontsize=11)
    ax.legend(fontsize=9)
    return fig


#: Line style of each kind of energy in the energy figure.
ENERGY_STYLES = {"kinetic": "-", "stored": "--", "dissipated": "-."}


def energy_histories(run) -> list[tuple[str, str, np.ndarray]]:
    """Every energy history of a run as (kind, name, J over ``run.time``): the kinetic energy of each body, the
    energy stored in each spring or contact, the energy dissipated by each damper or contact."""
    out = []
    for kind, histories in (("kinetic", run.kinetic_energy_histories), ("stored", run.stored_energy_histories),
                            ("dissipated", run.dissipated_energy_history)):
        out += [(kind, name, np.asarray(history)) for name, history in histories.items()]
    return out


def _energy_figure(data: dict, mass: float):
    """Where the firing's energy goes: kinetic, stored and dissipated energy of each element vs time, models
    (i) and (ii), gap 0; the sum of them all is the initial kinetic energy of the barrel (up to the error)."""
    from mbs_models.results.plotting import new_figure
    runs = [data["runs"][(MODEL_I, mass)].densified(), data["runs"][(MODEL_II, mass)].densified()]  # 1 ms apart
    fig, axes = new_figure(2, 1, width=10.0, row_height=3.3, sharex=True)
    names = sorted({name for run in runs for _, name, _ in energy_histories(run)})
    colours = {name: _ENERGY_COLOURS[i % len(_ENERGY_COLOURS)] for i, name in enumerate(names)}
    for ax, run in zip(axes[:, 0], runs):
        histories = energy_histories(run)
        for kind, name, history in histories:
            ax.plot(run.time, history, ls=ENERGY_STYLES[kind], color=colours[name], lw=1.3,
                    label=f"{name.replace('_', ' ')}: {kind}")
        total = sum(history for _, _, history in histories)
        ax.plot(run.time, total, color="k", lw=0.8, ls=":", label=f"sum ({total[0]:.0f} J at t = 0)")
        ax.set_ylabel("energy [J]")
        ax.set_title(f"{run.scene.model_label}, m = {mass:g} kg, gap 0", fontsize=10)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))   # beside the curves, never on them
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle("Energy per element: kinetic (solid), stored (dashed), dissipated (dash-dot)", fontsize=11)
    return fig


_ENERGY_COLOURS = ("#444444", "#1f77b4", "#2ca02c", "#d62728", "#9467bd", "#ff7f0e", "#8c564b", "#17becf")


def energy_figure_mass(data: dict) -> float | None:
    """The absorber mass of the energy figure: the paper's m = 1000 kg (None when the run has not got it)."""
    return 1000.0 if 1000.0 in data["options"]["masses"] else None


#: (file stem, zero-argument figure builder) of the figures being rendered; forked workers read it
_PENDING_FIGURES: list[tuple[str, Callable]] = []


def _render_pending(index: int) -> bytes:
    """PNG bytes of the ``index``-th pending figure (runs in a forked worker)."""
    from mbs_models.results.plotting import figure_png
    return figure_png(_PENDING_FIGURES[index][1]())


def figure_builders(data: dict) -> list[tuple[str, Callable]]:
    """Every figure of the report as (file stem, zero-argument builder returning a Figure)."""
    from mbs_models.results.plotting import plot_barrel_displacements, plot_contact_histories, plot_first_impact
    runs = data["runs"]
    builders = [("fig4_gap_sweep_model_i", partial(_sweep_figure, data, MODEL_I, 4)),
                ("fig5_gap_sweep_model_ii", partial(_sweep_figure, data, MODEL_II, 5))]
    for mass in data["options"]["masses"]:
        pair = [runs[(MODEL_I, mass)], runs[(MODEL_II, mass)]]
        tag = f"m{mass:g}"
        builders += [
            (f"barrel_displacement_{tag}", partial(plot_barrel_displacements, [runs[SIMPLIFIED], *pair],
                                                   title=f"Figs 6-8: barrel displacement, m = {mass:g} kg, gap 0")),
            (f"contact_force_{tag}", partial(plot_contact_histories, pair, "contact_force",
                                             title=f"Fig. 9: contact force between absorber and wall A, m = {mass:g} kg")),
            (f"absorber_velocity_{tag}", partial(plot_contact_histories, pair, "absorber_velocity",
                                                 title=f"Fig. 10: absorber velocity, m = {mass:g} kg")),
            (f"first_impact_{tag}", partial(plot_first_impact, pair, title=f"Fig. 11: first impact, m = {mass:g} kg")),
        ]
    mass = mount_force_mass(data)
    builders.append((f"support_force_m{mass:g}", partial(_mount_force_figure, data, mass)))
    mass = energy_figure_mass(data)
    if mass is not None:
        builders.append((f"energy_m{mass:g}", partial(_energy_figure, data, mass)))
    if data["conventions"]:
        builders.append(("conventions_gap_trend", partial(_convention_figure, data)))
    if data.get("carriage"):
        builders.append(("carriage_ground_reactions", partial(carriage_figure, data["carriage"])))
    return builders


#: File stems of the figures that take longest to render (submitted first).
_COSTLY_FIGURES = ("contact_force_", "absorber_velocity_")


def make_figures(data: dict, workers: int | None = None) -> dict[str, bytes]:
    """Every figure of the report as PNG bytes, keyed by file stem.

    Rendering (matplotlib, ~0.4 s a figure) is spread over ``workers`` processes (default: all CPUs)
    where processes can be forked -- the workers inherit the figure data instead of receiving it
    pickled; elsewhere, or with ``workers=1``, the figures are rendered here one by one.
    """
    global _PENDING_FIGURES
    from mbs_models.results.plotting import figure_png
    builders = figure_builders(data)
    if workers == 1 or "fork" not in multiprocessing.get_all_start_methods():
        return {name: figure_png(build()) for name, build in builders}
    _PENDING_FIGURES = builders
    # one figure per job, the costliest first (the 2 x 2 panels of Figs 9-10 take ~3x a one-panel figure),
    # so that the workers finish together
    order = sorted(range(len(builders)), key=lambda i: not builders[i][0].startswith(_COSTLY_FIGURES))
    try:
        with process_pool(workers) as pool:
            futures = {i: pool.submit(_render_pending, i) for i in order}
            pngs = [futures[i].result() for i in range(len(builders))]
    finally:
        _PENDING_FIGURES = []
    return {name: png for (name, _), png in zip(builders, pngs)}



# --------------------------------------------------------------------------------------------- tables
def table2_rows(data: dict) -> list[dict]:
    """Table 2 from the gap-0 comparisons: engine, reference, paper, differences (m), and the engine's peak
    force on the mount, ``peak_support_force`` (N, largest |support force|) at ``time_of_peak_support_force`` (s)."""
    published_table = table2()
    by_case = {(c["model"], c["absorber_mass"] or 0.0): c for c in data["comparisons"] if not c["gap"]}
    rows = []
    for model in (SIMPLIFIED, MODEL_I, MODEL_II):
        for mass in TABLE2_MASSES:
            case = by_case.get((model, 0.0 if model == SIMPLIFIED else mass))
            if case is None:
                continue
            check = next(x for x in case["checks"] if x["name"] == "max_barrel_displacement")
            paper = published_table[(model, mass)].value
            rows.append({"model": model, "absorber_mass": mass, "engine": check["engine"],
                         "reference": check["reference"], "engine_vs_reference": check["relative_error"],
                         "paper": paper, "difference": check["engine"] - paper,
                         "relative_difference": (check["engine"] - paper) / paper,
                         "peak_support_force": case.get("engine_peak_support_force"),
                         "time_of_peak_support_force": case.get("engine_time_of_peak_support_force")})
    return rows


#: The units the page shows (machine-readable outputs stay SI): SI unit -> (shown unit, factor).
#: Displacements in mm, forces in kN, in every table, figure and sentence.
DISPLAY_UNITS = {"m": ("mm", 1e3), "N": ("kN", 1e-3)}


def display(value: float | None, unit: str) -> tuple[float | None, str]:
    """``value`` in SI ``unit`` as the page shows it: (value in the shown unit, shown unit)."""
    shown, factor = DISPLAY_UNITS.get(unit, (unit, 1.0))
    return (None if value is None else value * factor), shown


def _kn(force: float | None) -> str:
    """A force in N written in kN (a dash when there is none)."""
    return "-" if force is None else f"{force / 1e3:.2f}"


def table2_markdown(rows: list[dict]) -> str:
    lines = [("| model | m [kg] | ours [mm] | peak support force [kN] | paper [mm] | ours - paper [mm] | rel. diff. | "
              "engine vs reference |"),
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['model']} | {r['absorber_mass']:g} | {r['engine'] * 1e3:.2f} | "
                     f"{_kn(r['peak_support_force'])} | {r['paper'] * 1e3:.1f} | {r['difference'] * 1e3:+.2f} | "
                     f"{r['relative_difference'] * 100:+.2f} % | "
                     f"{r['engine_vs_reference']:.1e} |")
    return "\n".join(lines) + "\n"


#: Units of the numbers in :func:`table2_rows` (written beside them in ``table2.json``).
TABLE2_UNITS = {"absorber_mass": "kg", "engine": "m", "reference": "m", "paper": "m", "difference": "m",
                "relative_difference": "1", "engine_vs_reference": "1", "peak_support_force": "N",
                "time_of_peak_support_force": "s"}


def mount_force_sentences(rows: list[dict]) -> list[str]:
    """What Table 2's rows say about the force on the mount: at each absorber mass with the three models,
    which model moderates it most (the lowest peak support force) and how that goes with the recoil length
    (the lowest maximum barrel displacement)."""
    by_case = {(r["model"], r["absorber_mass"]): r for r in rows if r.get("peak_support_force") is not None}
    sentences, lowest_models, trade_offs = [], set(), []
    for mass in TABLE2_MASSES:
        cases = [by_case.get((model, mass)) for model in (SIMPLIFIED, MODEL_I, MODEL_II)]
        if None in cases:
            continue
        lowest = min(cases, key=lambda r: r["peak_support_force"])
        shortest = min(cases, key=lambda r: r["engine"])
        others = ", ".join(f"{r['model']} {_kn(r['peak_support_force'])} kN" for r in cases if r is not lowest)
        text = (f"m = {mass:g} kg: {lowest['model']} moderates the force on the mount most, "
                f"{_kn(lowest['peak_support_force'])} kN ({others})")
        if shortest is lowest:
            text += f", and also recoils least ({shortest['engine'] * 1e3:.1f} mm)."
        else:
            excess = shortest["peak_support_force"] / lowest["peak_support_force"] - 1
            text += (f"; {shortest['model']} recoils least, {shortest['engine'] * 1e3:.1f} mm against "
                     f"{lowest['engine'] * 1e3:.1f} mm, but pushes {excess * 100:.1f} % harder on the mount.")
        sentences.append(text)
        lowest_models.add(lowest["model"])
        trade_offs.append(shortest is not lowest)
    if len(sentences) > 1 and len(lowest_models) == 1:
        text = f"At every absorber mass, {next(iter(lowest_models))} moderates the force on the mount most"
        sentences.append(text + ("; the shortest recoil comes with a higher force on the mount: a lower displacement "
                                 "is not a lower load on the support." if all(trade_offs) else "."))
    return sentences


def section22_rows(data: dict) -> list[dict]:
    """The Section 2.2 numbers (m = 1000 kg, gap 0): ours (engine) vs the paper."""
    rows = []
    if 1000.0 not in data["options"]["masses"]:
        return rows
    for model in (MODEL_I, MODEL_II):
        run = data["runs"][(model, 1000.0)]
        for quantity, ours in (("peak_contact_force", run.peak_contact_force),
                               ("max_absorber_velocity", run.max_absorber_velocity),
                               ("time_of_max_absorber_velocity", run.time_of_max_absorber_velocity)):
            pv = published(quantity, model, 1000.0)
            rows.append({"model": model, "quantity": quantity, "ours": ours, "paper": pv.value, "unit": pv.unit,
                         "relative_difference": (ours - pv.value) / pv.value, "source": pv.source})
    return rows


_NOT_STUDIED = ("The readings of the paper and the contact-law calibration were not computed in this run "
                "(recoil paper --reproduce-only); the full report studies them")


def _sentence(text: str) -> str:
    """``text`` as a sentence: a capital first letter (a symbol such as "m = 100 kg" stays) and a full stop."""
    text = text.strip()
    if text and not re.match(r"[a-z] =", text):
        text = text[0].upper() + text[1:]
    return text if text.endswith((".", "!", "?")) else text + "."


def _law_text(parameters: dict, fixed: dict) -> str:
    """A contact law's parameters in words: "contact stiffness 3.31e+07 N/m^0.98, ..."."""
    exponent = parameters.get("exponent", fixed.get("exponent"))
    parts = []
    for name, value in parameters.items():
        words, _, unit = CONTACT_PARAMETERS.get(name, (name.replace("_", " "), "", ""))
        if name == "stiffness" and exponent is not None:
            unit = f"N/m^{exponent:.3g}"
        parts.append(f"{words} {value:.3g}" + (f"\u00a0{unit}" if unit else ""))
    return ", ".join(parts)


def unreproduced(data: dict) -> list[dict]:
    """Every published number we do not reproduce within :data:`REPRODUCED_WITHIN`, with the likely reason
    (``reason``: plain sentences for an engineer, numbers shown as in the report: mm, kN)."""
    conventions = data["conventions"]
    calibration_rows = {(r["model"], r["absorber_mass"]): r for r in data["calibration_table2"]}
    items = []

    default_rms = next((row.rms_error() for row in conventions if not row.conventions.active), None)

    def best_reading(errors_of: Callable) -> tuple[list[str], bool]:
        """Sentences about the reading closest to the paper, and whether it reproduces the number."""
        if not conventions:
            return [_NOT_STUDIED], True
        closest = min(conventions, key=lambda row: (abs(errors_of(row)), row.label))
        signed = errors_of(closest)
        err = abs(signed)
        if not closest.conventions.active:
            texts = [f"No other reading of the paper comes closer than ours ({percent_text(signed)})"]
        else:
            texts = [f"The reading of the paper closest to it ({reading_text(closest.label)}) gives "
                     f"{percent_text(signed)}"]
        if err <= REPRODUCED_WITHIN and closest.conventions.active and default_rms is not None:
            texts.append(f"That reading reproduces this number but moves the others away (RMS over all published "
                         f"numbers {closest.rms_error() * 100:.1f}\u00a0% against {default_rms * 100:.1f}\u00a0% with "
                         "ours): the paper may have used it for this case only")
        return texts, err <= REPRODUCED_WITHIN

    def item(published_text: str, paper, ours, unit: str, relative, reasons: list[str]) -> dict:
        return {"published": published_text, "paper": paper, "ours": ours, "unit": unit,
                "relative_difference": relative, "reason": " ".join(_sentence(r) for r in reasons)}

    for row in table2_rows(data):
        if abs(row["relative_difference"]) <= REPRODUCED_WITHIN:
            continue
        key = (row["model"], row["absorber_mass"])
        calibrated = calibration_rows.get(key)
        reason, explained = best_reading(lambda c: c.table2_errors()[key])
        if calibrated:
            reason.append("The contact law calibrated on Section 2.2 gives "
                          + percent_text(calibrated["relative_error"]))
        if row["model"] == MODEL_II and row["paper"] == table2()[(SIMPLIFIED, row["absorber_mass"])].value:
            reason.append("The published value equals the simplified model's exactly, as if the absorber were never "
                          "hit, which gap 0 cannot give; the paper's own Fig. 6 sentence says model (ii) is lower. "
                          "Most likely a transcription or set-up error in Table 2")
        elif not explained:
            reason.append("No reading and no contact law closes it, and Table 2 hardly depends on the contact law: "
                          "the published value most likely comes from a set-up the paper does not describe")
        items.append(item(f"Table 2, {row['model']}, m = {row['absorber_mass']:g} kg", row["paper"], row["engine"],
                          "m", row["relative_difference"], reason))
    calibration = data["calibration"]
    for row in section22_rows(data):
        if abs(row["relative_difference"]) <= REPRODUCED_WITHIN:
            continue
        key = (row["model"], row["quantity"])
        reason = best_reading(lambda c: c.section22_errors()[key])[0]
        if calibration is not None:
            fitted = next((r for r in calibration.residuals if r.get("quantity") == row["quantity"]
                           and row["model"] + ":" in r.get("description", "")), None)
            if fitted is not None and fitted.get("relative_error") is not None:
                law = _law_text(calibration.parameters, calibration.fixed)
                reason.append(f"A contact law fitted to Section 2.2 ({law}) "
                              f"reproduces it to {percent_text(fitted['relative_error'], 2)}, so the published impact "
                              "numbers most likely come from other contact parameters than Table 1's")
        items.append(item(f"Section 2.2, {row['model']}, {row['quantity'].replace('_', ' ')}", row["paper"],
                          row["ours"], row["unit"], row["relative_difference"], reason))
    for verdict in data.get("claims", []):
        if verdict.holds is False:
            reason = ["Evidence: " + verdict.evidence]
            if verdict.claim.key == "ii_max_at_gap_zero":
                trend = {row.label: row.trend() for row in conventions}
                literal = trend.get("literal_gap_sign")
                if literal:
                    reason.append("Only the reading with the gap's sign as printed in Eq. (6), where the gap acts "
                                  "as an interference, makes the displacement fall with the gap "
                                  f"({', '.join(f'{x * 1e3:.1f}' for x in literal)}\u00a0mm at gaps "
                                  f"{', '.join(f'{g * 1e3:g}' for g in TREND_GAPS)}\u00a0mm), as Fig. 5 claims")
            items.append(item(f"Claim of {verdict.claim.source}: \u201c{verdict.claim.text}\u201d", None, None, "",
                              None, reason))
    return items


# ------------------------------------------------------------------------------------------------ HTML
_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;
color:#222;line-height:1.45}
h1{font-size:1.6em}h2{border-bottom:2px solid #ddd;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;margin:1em 0;font-size:.92em}th,td{border:1px solid #ccc;padding:.3em .6em;
text-align:left;vertical-align:top}th{background:#f3f3f3}td.n,th.n{text-align:right}td.n{white-space:nowrap}
.scroll{max-width:100%;overflow-x:auto}#tab-conventions td:first-child{min-width:12em}
#tab-conventions,#tab-conventions-trend,#tab-engine-vs-reference{font-size:.85em}
#tab-conventions th,#tab-engine-vs-reference th{vertical-align:bottom}
pre{background:#f7f7f7;padding:.8em;max-width:100%;box-sizing:border-box;overflow-x:auto;font-size:.85em}
pre.wrap{white-space:pre-wrap;overflow-wrap:anywhere}
figure{margin:1.2em 0}figure img{max-width:100%;height:auto;border:1px solid #eee}
figcaption{font-size:.9em;color:#555}
.bad{color:#b00020;font-weight:600}.good{color:#1b7f2a;font-weight:600}.bad,.good{white-space:nowrap}
.note{background:#fff8e1;padding:.6em 1em;border-left:4px solid #f0c000}
dl.meta{display:grid;grid-template-columns:max-content 1fr;gap:.15em 1em;font-size:.92em;margin:1em 0}
dl.meta dt{font-weight:600;color:#555}dl.meta dd{margin:0;overflow-wrap:anywhere}
#summary{font-size:1.05em;background:#f3f7fb;padding:.7em 1em;border-left:4px solid #4a7fb5}
@media (max-width:700px){body{padding:0 .5em;margin:1em auto}figure{margin:1em -.5em}
figure img{width:100%;border-left:0;border-right:0}figcaption{padding:0 .5em}}
@media print{pre{white-space:pre-wrap;overflow-wrap:anywhere}.scroll{overflow:visible}}
"""


def _e(text) -> str:
    return html.escape(str(text))


def bind_units(text: str) -> str:
    """``text`` with a non-breaking space between each number and its unit or % sign (never wrapped apart)."""
    return re.sub(r"(\d) (%|mm|kN|m/s|ms|kg|J|s|m)(?=[\s,;:.)]|$)", "\\1\u00a0\\2", text)


#: A cell that reads as a number: signed decimal or exponent, maybe a unit or "%", or "n / n" (counts).
_NUMBER = re.compile(r"[+\-\u2212]?(\d+(\.\d*)?|\.\d+)(e[+\-]?\d+)?(\s*(%|[a-zA-Z]{1,3}))?|\d+ / \d+")
#: A cell with nothing to align (a dash for "none").
_EMPTY = {"", "-", "\u2013", "\u2014"}


def _cell_text(cell: str) -> str:
    return html.unescape(re.sub(r"<[^>]*>", "", str(cell))).replace("\u00a0", " ").strip()


def numeric_columns(rows: list[list]) -> list[bool]:
    """Which columns hold numbers (right-aligned, never wrapped): those whose every cell but dashes reads
    as a number.  Text columns are left-aligned."""
    width = max((len(row) for row in rows), default=0)
    out = []
    for i in range(width):
        texts = [_cell_text(row[i]) for row in rows if i < len(row)]
        texts = [t for t in texts if t not in _EMPTY]
        out.append(bool(texts) and all(_NUMBER.fullmatch(t) for t in texts))
    return out


def _table(headers: list[str], rows: list[list], table_id: str = "") -> str:
    """A table, text columns left-aligned and number columns right-aligned (see :func:`numeric_columns`)."""
    id_attr = f' id="{table_id}"' if table_id else ""
    numeric = numeric_columns(rows) + [False] * len(headers)
    cls = lambda i: "n" if numeric[i] else "l"  # noqa: E731
    head = "".join(f'<th class="{cls(i)}">{_e(h)}</th>' for i, h in enumerate(headers))
    body = "".join("<tr>" + "".join(f'<td class="{cls(i)}">{c}</td>' for i, c in enumerate(row)) + "</tr>"
                   for row in rows)
    # wide tables scroll inside their own box on a narrow screen instead of widening the page
    return f"<div class='scroll'><table{id_attr}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table></div>"


def _img(name: str, png: bytes, caption: str) -> str:
    """A figure embedded as PNG data, linked to its PNG file beside the report (``NAME.png``): a click opens it
    full size, to be zoomed on a phone."""
    encoded = base64.b64encode(png).decode("ascii")
    return (f'<figure id="fig-{name}"><a href="{name}.png" title="open the figure full size">'
            f'<img alt="{_e(caption)}" src="data:image/png;base64,{encoded}"></a>'
            f"<figcaption>{_e(caption)} <small>(click the figure to open it full size)</small></figcaption>"
            "</figure>")


def _fmt(value, digits: int = 4) -> str:
    if value is None:
        return "&ndash;"
    if isinstance(value, float) and not math.isfinite(value):
        return "&ndash;"
    return f"{value:.{digits}g}"


def _pct(value) -> str:
    if value is None:
        return "&ndash;"
    cls = "bad" if abs(value) > REPRODUCED_WITHIN else "good"
    return f'<span class="{cls}">{value * 100:+.2f}&nbsp;%</span>'


_EQUATIONS = """Simplified model, Eq. (1):   M x_M'' + k x_M + c(x_M') x_M' = 0,   c = 6239 N s/m (x_M' > 0), 14050 N s/m (x_M' < 0)
Model (i), Eqs. (4)-(5):     M x_M'' + k x_M + c x_M' + c_r (x_M' - x_m') + k_r (x_M - x_m) + F = 0
                             m x_m'' - c_r (x_M' - x_m') - k_r (x_M - x_m) - F = 0
Model (ii), Eqs. (7)-(8):    M x_M'' + k x_M + c x_M' + F = 0
                             m x_m'' + k_r x_m + c_r x_m' - F = 0
Contact, Eq. (6), our signs: p = (x_M - x_m) - gap,  F = k_c p^n_c (1 + lambda p') for p > 0, F >= 0 (never pulls)
Initial state:               x_M = x_m = 0, x_m' = 0, x_M' = v0 = 6.86 kg * 564 m/s / 5600 kg = 0.6909 m/s
(F is written here as the force pushing the absorber forward; the paper's F_ct = -F.)"""


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def _sketch(func) -> str:
    """The model's ASCII sketch: the literal block after the first line ending in ``::`` of ``func``'s docstring.

    As in reStructuredText, the block is every line after the ``::`` line up to the first non-blank line
    indented no deeper than that paragraph (blank lines inside the drawing belong to it), dedented as
    a whole so that the drawing keeps its own indentation.  A ``::`` on the docstring's first line sits
    at the docstring's margin: the least indentation of the other lines, the closing quotes' line
    included (``inspect.cleandoc`` leaves that line out, and when every other line is the drawing it is
    all that marks the margin).  An empty string when there is no such block.
    """
    lines = (func.__doc__ or "").expandtabs().splitlines()
    start = next((i for i, line in enumerate(lines) if line.rstrip().endswith("::")), None)
    if start is None:
        return ""
    if start:
        paragraph = _indent(lines[start])
    else:
        margin_lines = [line for line in lines[1:] if line.strip()]
        if len(lines) > 1 and not lines[-1].strip():
            margin_lines.append(lines[-1])
        paragraph = min(map(_indent, margin_lines), default=0)
    block: list[str] = []
    for line in lines[start + 1:]:
        if line.strip() and _indent(line) <= paragraph:
            break
        block.append(line)
    return textwrap.dedent("\n".join(block)).strip("\n")


def _contents(sections: list[tuple[str, str]]) -> str:
    """The table of contents: a numbered link to every section, as (id, title)."""
    items = "".join(f"<li><a href='#{section_id}'>{_e(title)}</a></li>" for section_id, title in sections)
    return f"<nav id='contents' aria-label='Contents'><p><b>Contents</b></p><ol>{items}</ol></nav>"


def _provenance_html(fields: dict[str, str]) -> str:
    """The header: the paper replicated, when and with what the report was made."""
    items = "".join(f"<dt>{_e(label)}</dt><dd>{'<i>' if key == 'paper' else ''}{_e(fields.get(key, 'unknown'))}"
                    f"{'</i>' if key == 'paper' else ''}</dd>" for key, label in PROVENANCE_FIELDS)
    return f"<dl id='provenance' class='meta'>{items}</dl>"


def _count(n: int, total: int) -> str:
    return f"{n} of {total}"


def verdict(data: dict) -> str:
    """The report's verdict in one paragraph of plain text: what is reproduced, what is not, how well the
    engine agrees with the independent reference."""
    t2, s22 = table2_rows(data), section22_rows(data)
    ok = lambda rows: sum(abs(r["relative_difference"]) <= REPRODUCED_WITHIN for r in rows)  # noqa: E731
    comparisons = data["comparisons"]
    passed = sum(c["passed"] for c in comparisons)
    worst = largest_engine_error(comparisons)
    claims = [v for v in data.get("claims", []) if v.holds is not None]
    text = (f"{_count(ok(t2), len(t2))} maximum barrel displacements of Table 2"
            + (f" and {_count(ok(s22), len(s22))} first-impact numbers of Section 2.2" if s22 else "")
            + f" are reproduced within {REPRODUCED_WITHIN * 100:g} % of the published values")
    if claims:
        text += f"; {sum(v.holds for v in claims)} of the paper's {len(claims)} qualitative claims hold"
    text += (f". The engine agrees with the independent reference in {_count(passed, len(comparisons))} cases"
             + (f" (largest relative error {engine_error_text(worst[0])}: {worst[2]} of {worst[1]}, in the table "
                "\u201cEngine vs independent reference\u201d)" if worst is not None else "") + ".")
    missed = [r for r in t2 if abs(r["relative_difference"]) > REPRODUCED_WITHIN]
    if missed:
        text += (" Not reproduced in Table 2: "
                 + ", ".join(f"{r['model']} at m = {r['absorber_mass']:g} kg ({percent_text(r['relative_difference'])})"
                             for r in missed) + ".")
    missed22 = [r for r in s22 if abs(r["relative_difference"]) > REPRODUCED_WITHIN]
    if missed22:
        largest = max(missed22, key=lambda r: abs(r["relative_difference"]))
        text += (f" Not reproduced in Section 2.2: {_count(len(missed22), len(s22))} numbers, by up to "
                 f"{percent_text(largest['relative_difference'])}.")
    failed = [v for v in claims if not v.holds]
    if failed:
        text += f" {len(failed)} of the claims do not hold."
    return text


#: The engine-vs-reference table's columns: (check name of :func:`validation.studies.compare.compare_results`,
#: short header); a check of another name (a scene with several contacts) gets a column of its own name.
ENGINE_REFERENCE_COLUMNS = (("max_barrel_displacement", "x_max"), ("time_of_max_barrel_displacement", "t(x_max)"),
                            ("peak_support_force", "peak support force"), ("peak_contact_force", "peak contact force"),
                            ("max_absorber_velocity", "v_max absorber"),
                            ("time_of_max_absorber_velocity", "t(v_max absorber)"),
                            ("time_to_battery", "t(battery)"),
                            ("barrel_position_history", "x_M(t)"), ("absorber_position_history", "x_m(t)"))


def engine_reference_columns(comparisons: list[dict]) -> list[tuple[str, str]]:
    """The (check name, header) columns of the engine-vs-reference table: every check any case has, those
    of :data:`ENGINE_REFERENCE_COLUMNS` first, so that every number the verdict quotes is in a column."""
    known = dict(ENGINE_REFERENCE_COLUMNS)
    names = {x["name"] for c in comparisons for x in c["checks"]}
    return ([(name, header) for name, header in ENGINE_REFERENCE_COLUMNS if name in names]
            + [(name, name.replace("_", " ")) for name in sorted(names - set(known))])


def engine_error_text(value: float | None) -> str:
    """A relative error as the engine-vs-reference table and the verdict print it (two significant digits)."""
    return "&ndash;" if value is None or not math.isfinite(value) else f"{value:.1e}"


def largest_engine_error(comparisons: list[dict]) -> tuple[float, str, str] | None:
    """The largest relative error of any check of any case, as (value, case, column header of the
    engine-vs-reference table); None when no check has one."""
    headers = dict(engine_reference_columns(comparisons))
    found = [(x["relative_error"], c["scene"], headers[x["name"]]) for c in comparisons for x in c["checks"]
             if x.get("relative_error") is not None]
    return max(found, key=lambda item: item[0], default=None)


def percent_text(fraction: float, digits: int = 1) -> str:
    """A signed relative difference in %, with enough decimals not to print a non-zero one as "-0.0 %"
    (a non-breaking space before the % sign, which never wraps onto its own line)."""
    value = fraction * 100
    if value == 0:
        return "0\u00a0%"
    while digits < 4 and round(abs(value), digits) == 0:
        digits += 1
    if round(abs(value), digits) == 0:
        return f"{'-' if value < 0 else '+'}less than 0.001\u00a0%"
    return f"{value:+.{digits}f}\u00a0%"


_COLOUR_RULE = (f"<p class='note' id='colour-rule'>Colours: <span class='good'>green</span> marks a number within "
                f"{REPRODUCED_WITHIN * 100:g} % of the published value, or a check that passes; "
                "<span class='bad'>red</span> one further off, or a check that fails.</p>")


#: The contact law's parameters: (words, symbol, unit).
CONTACT_PARAMETERS = {"stiffness": ("contact stiffness", "k_c", "N/m^n_c"), "exponent": ("contact exponent", "n_c", ""),
                      "damping_factor": ("contact damping factor", "lambda_c", "s/m")}


def _parameter_name(name: str) -> str:
    words, symbol, _ = CONTACT_PARAMETERS.get(name, (name.replace("_", " "), "", ""))
    return f"{words} {symbol}".strip()


def _calibration_html(calibration) -> str:
    """The calibration's fit: outcome, parameters (with standard errors), each number fitted, its cost."""
    errors = calibration.standard_errors or {}
    status = calibration.identifiability.get("parameters", {})
    at_bounds = set(calibration.identifiability.get("at_bounds", []))
    rows = [[_e(_parameter_name(name)), _fmt(value, 6),
             _fmt(errors.get(name), 3) if errors.get(name) is not None else "&ndash;",
             _e(CONTACT_PARAMETERS.get(name, ("", "", ""))[2]),
             _e(status.get(name, "")) + (" (at the search bound)" if name in at_bounds else "")]
            for name, value in calibration.parameters.items()]
    rows += [[_e(_parameter_name(name)), _fmt(value, 6), "&ndash;",
              _e(CONTACT_PARAMETERS.get(name, ("", "", ""))[2]), "fixed (Table 1)"]
             for name, value in calibration.fixed.items()]
    fitted = []
    for r in calibration.residuals:
        target, unit = display(r["target"], r["unit"])
        fitted.append([_e(r["model"]), _e(r["quantity"].replace("_", " ")), _fmt(target, 5),
                       _fmt(display(r["value"], r["unit"])[0], 5), _fmt(display(r["initial_value"], r["unit"])[0], 5),
                       _e(unit), _pct(r["relative_error"])])
    outcome = "converged" if calibration.success else "<span class='bad'>did not converge</span>"
    return (f"<p>The contact law's parameters fitted to the Section 2.2 numbers (m = 1000 kg) with the independent "
            f"reference: the fit {outcome} ({_e(calibration.message.replace('.;', ';').replace('`', ''))}).</p>"
            + _table(["parameter", "fitted value", "standard error", "unit", "identifiable?"], rows,
                     table_id="tab-calibration-parameters")
            + _table(["model", "quantity", "paper", "fitted", "with Table 1's law", "unit", "fitted vs paper"], fitted,
                     table_id="tab-calibration-fit")
            + f"<p>Cost {calibration.cost:.3g} (with Table 1's law {calibration.initial_cost:.3g}), "
              f"{calibration.forward_solves} solves, {calibration.wall_time:.1f} s.</p>")


def render_html(data: dict, pngs: dict[str, bytes]) -> str:
    """The report as one self-contained HTML page."""
    parts = ["<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
             "<meta name='viewport' content='width=device-width, initial-scale=1'>"
             f"<title>Recoil absorber replication report</title><style>{_CSS}</style></head><body>",
             "<h1>Replication report: recoil mechanism with impact absorbers</h1>",
             _provenance_html(data.get("provenance") or provenance()),
             f"<p id='summary'><b>Verdict.</b> {_e(verdict(data))}"
             + (" Each number not reproduced is listed with its most likely reason under <a href='#unreproduced'>"
                "Published numbers we cannot reproduce</a>." if data.get("unreproduced") else "") + "</p>",
             "<p>Engine: Exudyn (symbolic user functions, accuracy preset "
             f"<code>{_e(data['options']['accuracy'])}</code>). Independent check: an event-driven scipy solution of "
             "the same equations (<code>validation.reference</code>). Nothing is tuned to the published numbers; where "
             "we differ, the difference is reported and studied.</p>"]
    contents_at = len(parts)        # the table of contents goes here, once every section is known
    sections: list[tuple[str, str]] = []

    def section(section_id: str, title: str) -> str:
        """The numbered heading of the next section, recorded for the table of contents."""
        sections.append((section_id, title))
        return f"<h2 id='{section_id}'>{len(sections)}. {_e(title)}</h2>"

    # models
    parts.append(section("models", "Models and equations"))
    for title, func in (("Simplified model (Fig. 1)", _simp_doc), ("Model (i) (Fig. 2)", _model_i_doc),
                        ("Model (ii) (Fig. 3)", _model_ii_doc)):
        parts.append(f"<h3>{_e(title)}</h3><pre>{_e(_sketch(func))}</pre>")
    parts.append(f"<pre>{_e(_EQUATIONS)}</pre>")
    # parameters
    parts.append(section("parameters", "Parameters"))
    rows = [[_e(p.quantity.replace("_", " ")), _e(p.model), _fmt(p.value, 6), _e(p.unit), _e(p.source), _e(p.note)]
            for p in published_values() if p.model == "all"]
    parts.append(_table(["quantity", "model", "value", "unit", "source", "note"], rows,
                        table_id="tab-parameters"))
    # table 2
    t2 = table2_rows(data)
    parts.append(section("table2", "Table 2: maximum barrel displacement and force on the mount (gap 0, 10 s)"))
    parts.append(_COLOUR_RULE)          # the first table with coloured numbers follows
    parts.append(_table(["model", "m [kg]", "ours [mm]", "peak support force [kN]", "reference [mm]", "paper [mm]",
                         "ours - paper [mm]", "relative", "engine vs reference"],
                        [[_e(r["model"]), f"{r['absorber_mass']:g}", f"{r['engine'] * 1e3:.2f}",
                          _kn(r["peak_support_force"]), f"{r['reference'] * 1e3:.2f}", f"{r['paper'] * 1e3:.1f}",
                          f"{r['difference'] * 1e3:+.2f}",
                          _pct(r["relative_difference"]), f"{r['engine_vs_reference']:.1e}"] for r in t2],
                        table_id="tab-table2"))
    parts.append("<p id='mount-force'>Peak support force: the largest magnitude of the force on the mount (what "
                 "the recoil spring and damper, and in model (ii) the absorber's spring and damper, transmit to the "
                 "ground) over the 10 s, engine. Moderating it is what a recoil mechanism is for; the paper does not "
                 "report it.</p><ul id='mount-force-verdict'>"
                 + "".join(f"<li>{_e(sentence)}</li>" for sentence in mount_force_sentences(t2)) + "</ul>")
    mass = mount_force_mass(data)
    name = f"support_force_m{mass:g}"
    parts.append(_img(name, pngs[name], f"Force on the mount: support force of the three models, m = {mass:g} kg, "
                                        f"gap 0, first {MOUNT_FORCE_WINDOW:g} s"))
    # sweeps
    parts.append(section("sweeps", "Gap sweeps (Figs 4 and 5)"))
    gap_step = data["options"]["gap_step"]
    parts.append(f"<p>Gaps 0 to {data['options']['gap_max'] * 1e3:g} mm in {gap_step * 1e3:g} mm steps, engine; "
                 "crosses mark the independent reference.</p>")
    if data["sweep_failures"]:
        parts.append(f"<p class='bad'>{len(data['sweep_failures'])} sweep points failed: "
                     f"{_e(data['sweep_failures'][:3])}</p>")
    parts.append(_img("fig4_gap_sweep_model_i", pngs["fig4_gap_sweep_model_i"], "Fig. 4 (ours): model (i)"))
    parts.append(_img("fig5_gap_sweep_model_ii", pngs["fig5_gap_sweep_model_ii"], "Fig. 5 (ours): model (ii)"))
    # time histories
    parts.append(section("histories", "Time histories (Figs 6-8)"))
    for mass in data["options"]["masses"]:
        name = f"barrel_displacement_m{mass:g}"
        parts.append(_img(name, pngs[name], f"Barrel displacement, m = {mass:g} kg (paper: Figs 6-8)"))
    mass = energy_figure_mass(data)
    if mass is not None:
        name = f"energy_m{mass:g}"
        parts.append(f"<p id='energy'>Where the firing's energy goes, m = {mass:g} kg, gap 0: the barrel's initial "
                     "kinetic energy is passed to the springs and the absorber, and dissipated by the recoil damper, "
                     "the absorber's damper and the contact at wall A. The dotted line, the sum of all, stays at the "
                     "initial energy (energy conservation; its drift is the integration error).</p>")
        parts.append(_img(name, pngs[name], f"Energy per element vs time, models (i) and (ii), m = {mass:g} kg, "
                                            "gap 0 (not in the paper)"))
    parts.append(section("contact", "Contact force and absorber velocity (Figs 9-11)"))
    s22 = section22_rows(data)
    parts.append(_table(["model", "quantity", "ours", "paper", "unit", "relative", "source"],
                        [[_e(r["model"]), _e(r["quantity"].replace("_", " ")),
                          _fmt(display(r["ours"], r["unit"])[0], 5),
                          _fmt(display(r["paper"], r["unit"])[0], 5), _e(display(r["paper"], r["unit"])[1]),
                          _pct(r["relative_difference"]), _e(r["source"])] for r in s22], table_id="tab-section22"))
    for mass in data["options"]["masses"]:
        for stem, caption in (("contact_force", "Contact force (Fig. 9), with the paper's detail windows"),
                              ("absorber_velocity", "Absorber velocity (Fig. 10)"),
                              ("first_impact", "First impact zoomed (Fig. 11)")):
            name = f"{stem}_m{mass:g}"
            parts.append(_img(name, pngs[name], f"{caption}, m = {mass:g} kg"))
    # engine vs reference
    parts.append(section("engine-vs-reference", "Engine vs independent reference, every case shown"))
    rows = []
    columns = engine_reference_columns(data["comparisons"])
    for c in data["comparisons"]:
        err = {x["name"]: x["relative_error"] for x in c["checks"]}
        rows.append([_e(c["scene"])] + [engine_error_text(err.get(name)) for name, _ in columns]
                    + [f"{c['engine_impacts']} / {c['reference_impacts']}",
                       "<span class='good'>pass</span>" if c["passed"] else "<span class='bad'>FAIL</span>"])
    parts.append("<p>Relative errors of every compared quantity; tolerances 1e-4 (x_max), 1e-2 (t(v_max "
                 "absorber)), 1e-3 (the others: times, forces, velocity, the histories x_M(t) and x_m(t) of the "
                 "barrel and the absorber); the impact counts must be equal.</p>")
    parts.append(_table(["case"] + [header for _, header in columns] + ["impacts engine / ref.", "verdict"], rows,
                        table_id="tab-engine-vs-reference"))
    # conventions
    parts.append(section("conventions", "Convention study: readings of the paper"))
    parts.append("<p>Each reading of the paper alone, computed with the independent reference (the engine runs the "
                 "same scenes). The first table compares each reading with the paper: the columns <i>model (i), 100 "
                 "kg</i> to <i>model (ii), 1000 kg</i> give the maximum barrel displacement of Table 2 as (ours "
                 "&minus; paper) / paper; <i>peak contact force</i> and <i>max absorber velocity</i> the same for "
                 "Section 2.2 (model (i), m = 1000 kg); <i>RMS</i> is over those 6 Table 2 cells and the 6 Section "
                 "2.2 numbers. The second table gives model (ii)'s maximum barrel displacement at m = 1000 kg at "
                 "three gaps (Fig. 5 says it is largest at gap 0) and the engine's largest relative difference from "
                 "the reference over the reading's cases.</p>")
    conv_rows, trend_rows = [], []
    for row in data["conventions"]:
        t2e = row.table2_errors()
        s2e = row.section22_errors()
        engine = row.engine_errors()
        failures = sum(1 for v in engine.values() if isinstance(v, str))
        worst = max((v for v in engine.values() if not isinstance(v, str)), default=None)
        engine_text = (f"{worst:.1e}" if worst is not None else "") + (
            f"; <span class='bad'>{failures} cases fail</span> (sticking contact)" if failures else "")
        conv_rows.append([f"<b>{_e(reading_short(row.label))}</b><br><small>{_e(reading_text(row.label))} "
                          f"(option <code>{_e(row.label)}</code>)</small>"]
                         + [_pct(t2e[(m, mass)]) for m in (MODEL_I, MODEL_II) for mass in TABLE2_MASSES]
                         + [_pct(s2e[(MODEL_I, "peak_contact_force")]), _pct(s2e[(MODEL_I, "max_absorber_velocity")]),
                            f"{row.rms_error() * 100:.1f}&nbsp;%"])
        trend_rows.append([f"<b>{_e(reading_short(row.label))}</b>"] + [f"{x * 1e3:.1f}" for x in row.trend()]
                          + [engine_text])
    not_run = ("<p class='note'>Not computed in this run (<code>recoil paper --reproduce-only</code>); "
               "<code>recoil paper</code> without that option computes it.</p>")
    if data["conventions"]:
        parts.append(_table(["reading"] + [f"{m}, {mass:g} kg" for m in (MODEL_I, MODEL_II) for mass in TABLE2_MASSES]
                            + ["peak contact force, model (i)", "max absorber velocity, model (i)", "RMS"],
                            conv_rows, table_id="tab-conventions"))
        parts.append(_table(["reading"] + [f"gap {g * 1e3:g} mm [mm]" for g in TREND_GAPS]
                            + ["engine vs reference, largest"], trend_rows, table_id="tab-conventions-trend"))
        same = coinciding_readings(data["conventions"])
        parts.append(_img("conventions_gap_trend", pngs["conventions_gap_trend"],
                          "Model (ii), m = 1000 kg: maximum barrel displacement vs gap under each reading"
                          + "".join(f"; the line of '{reading_short(a)}' coincides with that of '{reading_short(b)}' "
                                    "(drawn dashed with hollow markers over it): that reading does not change "
                                    "model (ii)"
                                    for a, b in same.items())))
    else:
        parts.append(not_run)
    # calibration
    calibration = data["calibration"]
    parts.append(section("calibration", "Contact-law calibration on Section 2.2"))
    if calibration is not None:
        parts.append(_calibration_html(calibration))
        parts.append(_table(["model", "m [kg]", "predicted x_max [mm]", "paper [mm]", "relative"],
                            [[_e(r["model"]), f"{r['absorber_mass']:g}", f"{r['max_barrel_displacement'] * 1e3:.1f}",
                              "&ndash;" if r["published"] is None else f"{r['published'] * 1e3:.1f}",
                              _pct(r["relative_error"])] for r in data["calibration_table2"]],
                            table_id="tab-calibration-table2"))
    else:
        parts.append(not_run)
    # claims
    parts.append(section("claims", "The paper's qualitative claims"))
    parts.append(_table(["claim", "source", "holds?", "evidence"],
                        [[_e(v.claim.text), _e(v.claim.source),
                          "<span class='good'>yes</span>" if v.holds else
                          ("&ndash;" if v.holds is None else "<span class='bad'>no</span>"), _e(bind_units(v.evidence))]
                         for v in data.get("claims", [])], table_id="tab-claims"))
    # unreproduced
    parts.append(section("unreproduced", "Published numbers we cannot reproduce, and the most likely reason"))
    parts.append(f"<p>Counted as reproduced: within {REPRODUCED_WITHIN * 100:g} % of the published value.</p><ul "
                 "id='unreproduced-list'>")
    for item in data["unreproduced"]:
        if item["paper"] is None:
            parts.append(f"<li><b>{_e(item['published'])}</b> {_e(bind_units(item['reason']))}</li>")
            continue
        (paper, unit), ours = display(item["paper"], item["unit"]), display(item["ours"], item["unit"])[0]
        numbers = (f"paper {_fmt(paper, 5)}&nbsp;{_e(unit)}, ours {_fmt(ours, 5)}&nbsp;{_e(unit)} "
                   f"({_e(percent_text(item['relative_difference']))})")
        parts.append(f"<li><b>{_e(item['published'])}</b> &mdash; {numbers}. {_e(bind_units(item['reason']))}</li>")
    parts.append("</ul>")
    if data.get("carriage"):
        parts.append(section("carriage", "The gun on its carriage: does it stay on the ground?"))
        rows = carriage_rows(data["carriage"])
        parts.append(carriage_html(rows, _table(*carriage_table(rows), table_id="tab-carriage"),
                                   _img("carriage_ground_reactions", pngs["carriage_ground_reactions"],
                                        "Ground reactions of the towed howitzer at 0 and 45 degrees (engine)")))
    timing_rows = [[_e(k), f"{v:.1f}&nbsp;s"] for k, v in data["timings"].items()]
    machine = data.get("machine", {})
    parts.append(section("cost", "What this report cost") + _table(["stage", "wall time"], timing_rows)
                 + (f"<p>{machine.get('cpus')} CPUs, {machine.get('workers')} worker processes, load average "
                    f"{machine.get('load_average_at_start')} at the start (other programs share the CPUs). The "
                    "stages run side by side on the worker processes: a stage's time is that of its runs added "
                    "up over the workers, the rows marked wall and the total are elapsed times. The gap "
                    "sweeps and the convention study stop each run once its peak metrics are proven final by "
                    "energy bounds (same values as the full 10 s runs); the engine-vs-reference cases and the "
                    "time histories run the full 10 s.</p>" if machine else ""))
    parts.append("</body></html>")
    parts.insert(contents_at, _contents(sections))
    return "\n".join(parts)


def results_json(data: dict) -> dict:
    """The machine-readable results (no NaN)."""
    def clean(value):
        if isinstance(value, float) and not math.isfinite(value):
            return None
        if isinstance(value, dict):
            return {str(k): clean(v) for k, v in value.items()}
        if isinstance(value, (list, tuple)):
            return [clean(v) for v in value]
        return value

    return clean({
        "options": data["options"],
        "table2": table2_rows(data),
        "section22": section22_rows(data),
        "engine_vs_reference": data["comparisons"],
        "gap_sweeps": [{"model": model, "absorber_mass": mass, "gap": [p[0] for p in points],
                        "max_barrel_displacement": [p[1] for p in points]}
                       for (model, mass), points in data["sweeps"].items()],
        "sweep_failures": data["sweep_failures"],
        "time_histories": {f"{key[0]}:{key[1]:g}" if isinstance(key, tuple) else key: run.metrics()
                           for key, run in data["runs"].items()},
        "conventions": [row.to_dict() for row in data["conventions"]],
        "calibration": None if data["calibration"] is None else data["calibration"].to_dict(),
        "calibration_table2": data["calibration_table2"],
        "claims": [v.to_dict() for v in data.get("claims", [])],
        "unreproduced": data["unreproduced"],
        "carriage": [{k: v for k, v in row.items()} for row in carriage_rows(data.get("carriage") or [])],
        "timings": data["timings"],
        "machine": data.get("machine"),
        "provenance": data.get("provenance"),
    })


def write_report(out: str | Path, options: ReportOptions = ReportOptions(), progress: Progress = _silent) -> dict:
    """Compute everything and write ``report.html``, ``results.json``, ``table2.md/json`` and PNGs to ``out``."""
    check_output_dir(out)   # a bad directory: SceneError before any work; created once there is something to write
    start = time.perf_counter()
    data = compute_report(options, progress)
    progress("figures and report")
    data["unreproduced"] = unreproduced(data)
    figures_start = time.perf_counter()
    pngs = make_figures(data, options.workers)
    data["timings"]["figures (wall)"] = time.perf_counter() - figures_start
    from mbs_models.outputs import atomic_write_bytes
    out = prepare_output_dir(out)
    for name, png in pngs.items():
        atomic_write_bytes(out / f"{name}.png", png)
    rows = table2_rows(data)
    atomic_write_text(out / "table2.md", "# Table 2: maximum barrel displacement and force on the mount, "
                      "gap 0, 10 s\n\n"
                      "Ours = Exudyn engine (standard); reference = independent scipy solution; peak support force "
                      "= largest |force on the mount| (engine).\n\n" + table2_markdown(rows) + "\n"
                      + "".join(f"- {sentence}\n" for sentence in mount_force_sentences(rows)))
    atomic_write_json(out / "table2.json", {"rows": rows, "units": TABLE2_UNITS})
    data["timings"]["total"] = time.perf_counter() - start
    data["provenance"] = provenance()
    atomic_write_json(out / "results.json", results_json(data))
    atomic_write_text(out / "report.html", render_html(data, pngs))
    return data
