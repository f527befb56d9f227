"""Design optimisation: the best values of some scene fields within bounds, by differential evolution.

    from mbs_models import model_ii
    from mbs_models.studies.optimise import optimise
    best = optimise(model_ii(), {"absorber.mass": (100.0, 2000.0), "contact.gap": (0.0, 0.12)},
                    minimise="peak_support_force", constraints=["max_barrel_displacement<=0.2215"])
    best.parameters, best.metrics, best.feasible, best.history   # history: every evaluated point

Method
------
:func:`scipy.optimize.differential_evolution` (bounded and global: the metrics are not smooth in the
gap -- an impact comes or goes -- so gradient methods and a final gradient polish are not used).
Each point is the sweep's point (:func:`~mbs_models.studies.point.evaluate_point`: the scene with the
dotted-key overrides, simulated); every generation's trial population is evaluated at once, in
parallel, through the sweep's backends (:func:`~mbs_models.studies.backends.make_backend`: a local
process pool, or a Dask cluster with ``scheduler=``).

Constraints
-----------
Constraints ``metric <= value`` (or ``>=``) on any metric are scipy :class:`~scipy.optimize.NonlinearConstraint`\\ s,
not a penalty: scipy's differential evolution then ranks points by Lampinen's feasibility rules (a
feasible point beats an infeasible one; of two infeasible points, one replaces the other only if it
violates no constraint more; of two feasible points the lower objective wins).  scipy evaluates
constraints in the calling process, point by point, before it maps the objective over ``workers``; so
the objective and the constraints are given to scipy *vectorised* (``vectorized=True``, which implies
``updating="deferred"``): scipy passes the whole trial population, which is simulated in one parallel
batch through the backend, and the objective reads the same simulations from a cache (each point is
simulated once).

A point whose solve fails (or whose scene is refused, or that raises anything else, or whose worker
process dies, or that lacks a value of a metric) is **infeasible**, never a crash: it violates the implicit constraint ``solved <= 0`` by 1 and every
metric constraint by infinity, so any solved point beats it; its row keeps the error.  If no feasible
point is found, :attr:`OptimisationResult.feasible` is False and the reported design is the least
violating one.

Reproducibility: a fixed ``seed`` gives the same points in the same order, on any backend (the
backend only changes where each point is simulated).
"""

from __future__ import annotations

import math
import re
import time
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from ..errors import ClusterError, SceneError
from ..scene import Scene

#: Columns of the history added to the sweep's row: evaluation number, generation (0: the initial
#: population), feasibility and the largest relative constraint violation (0 when feasible).
HISTORY_COLUMNS = ("evaluation", "generation", "feasible", "violation")

_CONSTRAINT = re.compile(r"^\s*([A-Za-z_][\w.]*)\s*(<=|>=)\s*(\S+)\s*$")


@dataclass(frozen=True)
class Constraint:
    """``metric <= limit`` (``upper=True``) or ``metric >= limit``, in the metric's SI unit."""

    metric: str
    limit: float
    upper: bool = True

    def __str__(self) -> str:
        return f"{self.metric}{'<=' if self.upper else '>='}{self.limit:g}"

    def violation(self, value: float | None) -> float:
        """How far ``value`` is outside, relative to ``|limit|`` (absolute if the limit is 0); inf if None."""
        if value is None or not math.isfinite(value):
            return math.inf
        excess = value - self.limit if self.upper else self.limit - value
        return max(0.0, excess) / (abs(self.limit) or 1.0)


def parse_constraint(text: str | Constraint, key: str = "--constraint") -> Constraint:
    """``"METRIC<=VALUE"`` or ``"METRIC>=VALUE"`` (VALUE in SI units) as a :class:`Constraint`."""
    if isinstance(text, Constraint):
        return text
    match = _CONSTRAINT.match(str(text))
    if not match:
        raise SceneError(key, f"must be METRIC<=VALUE or METRIC>=VALUE (e.g. max_barrel_displacement<=0.2215), "
                              f"got {text!r}")
    metric, op, value = match.groups()
    try:
        limit = float(value)
    except ValueError:
        raise SceneError(key, f"{text!r}: the limit must be a number in SI units, got {value!r}") from None
    if not math.isfinite(limit):
        raise SceneError(key, f"{text!r}: the limit must be finite")
    return Constraint(metric, limit, op == "<=")


def parse_bound(text: str, key: str = "--vary") -> tuple[str, tuple[float, float]]:
    """``"KEY=LOW:HIGH"`` as ``(key, (low, high))``, ``low < high`` finite numbers (SI units)."""
    name, sep, spec = str(text).partition("=")
    parts = spec.split(":")
    if not sep or not name.strip() or len(parts) != 2:
        raise SceneError(key, f"must be KEY=LOW:HIGH (e.g. contact.gap=0:0.12), got {text!r}")
    try:
        low, high = (float(p) for p in parts)
    except ValueError:
        raise SceneError(key, f"{text!r}: LOW and HIGH must be numbers") from None
    return name.strip(), (low, high)


def check_bounds(scene: Scene, bounds: Mapping[str, tuple[float, float]]) -> dict[str, tuple[float, float]]:
    """The bounds, each key a field of ``scene`` and each end a value the scene accepts (checked by
    applying both ends); SceneErrors name the key."""
    from ..scene.overrides import apply_overrides, check_keys

    if not bounds:
        raise SceneError("bounds", "give at least one parameter to vary (KEY=LOW:HIGH)")
    checked = {}
    check_keys(scene, list(bounds))
    for key, pair in bounds.items():
        try:
            low, high = (float(v) for v in pair)
        except (TypeError, ValueError):
            raise SceneError(key, f"bounds must be two numbers (low, high), got {pair!r}") from None
        if not (math.isfinite(low) and math.isfinite(high) and low < high):
            raise SceneError(key, f"bounds must be finite with low < high, got {low:g}:{high:g}")
        for end in (low, high):
            apply_overrides(scene, {key: end})  # a value the scene refuses: its error names the key
        checked[key] = (low, high)
    return checked


def _metric_needs(metric: str) -> str:
    """The metric whose finality makes ``metric`` final (``time_of_X`` is final with ``X``)."""
    return metric[len("time_of_"):] if metric.startswith("time_of_") else metric


def early_stop_metrics(metrics: Sequence[str]) -> tuple[str, ...]:
    """``stop_when_final`` for these metrics: all of them if each can be proven final, else none (a
    run must then go to its end time)."""
    from ..engine.final_metrics import FINAL_METRICS

    needed = tuple(dict.fromkeys(_metric_needs(m) for m in metrics))
    return needed if all(m in FINAL_METRICS for m in needed) else ()


@dataclass
class OptimisationResult:
    """The best design found and how it was found.

    ``parameters`` (dotted key -> value, SI), ``metrics`` (every scalar metric of the design),
    ``constraint_values`` (per constraint: value, limit, satisfied), ``feasible`` (the design solved and
    meets every constraint), ``history`` (a DataFrame: every evaluated point in order, with
    :data:`HISTORY_COLUMNS`), ``convergence`` (a DataFrame: per generation the best objective, its
    feasibility and scipy's convergence measure), ``settings`` (seed, population, iterations, ...),
    ``message``/``success``/``generations``/``evaluations`` from scipy.
    """

    scene: Scene
    minimise: str
    bounds: dict[str, tuple[float, float]]
    constraints: tuple[Constraint, ...]
    parameters: dict[str, float]
    metrics: dict[str, Any]
    constraint_values: list[dict[str, Any]]
    feasible: bool
    history: Any
    convergence: Any
    settings: dict[str, Any]
    message: str
    success: bool
    generations: int
    evaluations: int
    wall_time: float

    @property
    def objective(self) -> float | None:
        """The minimised metric at the design (SI)."""
        return self.metrics.get(self.minimise)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (no history: that is the CSV)."""
        def clean(value):
            if isinstance(value, (float, np.floating)):
                return float(value) if math.isfinite(value) else None
            if isinstance(value, np.integer):
                return int(value)
            return value

        return {
            "minimise": self.minimise, "objective": clean(self.objective), "feasible": self.feasible,
            "parameters": {k: clean(v) for k, v in self.parameters.items()},
            "bounds": {k: list(v) for k, v in self.bounds.items()},
            "constraints": [{k: clean(v) for k, v in c.items()} for c in self.constraint_values],
            "metrics": {k: clean(v) for k, v in self.metrics.items()},
            "settings": {k: clean(v) for k, v in self.settings.items()},
            "success": bool(self.success), "message": self.message, "generations": self.generations,
            "evaluations": self.evaluations, "failed_evaluations": int((self.history["status"] != "ok").sum()),
            "wall_time": self.wall_time,
        }

    def summary(self) -> str:
        """A few lines for the terminal, every value in SI units as typed on the command line (the limit
        and the value of a constraint in the same unit; plain unit strings, no plot markup)."""
        from ..results.units import metric_si_unit, parameter_si_unit

        unit = metric_si_unit(self.minimise)
        value = "none" if self.objective is None else f"{self.objective:.6g} {unit}"
        lines = [f"{'feasible' if self.feasible else 'NO FEASIBLE DESIGN FOUND; least violating'} design: "
                 f"{self.minimise} = {value}"]
        for key, v in self.parameters.items():
            lines.append(f"  {key:32s} {v:.6g} {parameter_si_unit(key)}")
        for c, entry in zip(self.constraints, self.constraint_values):
            state = "met" if entry["satisfied"] else "VIOLATED"
            unit = metric_si_unit(c.metric)
            value = "none (failed)" if entry["value"] is None else f"{entry['value']:.6g} {unit}"
            bound = f"{c.metric} {'<=' if c.upper else '>='} {c.limit:g} {unit}"
            lines.append(f"  constraint {bound:40s} value {value} ({state})")
        failed = int((self.history["status"] != "ok").sum())
        lines.append(f"  {self.evaluations} evaluations ({failed} failed) in {self.generations} generations, "
                     f"{self.wall_time:.1f} s; scipy: {self.message}")
        return "\n".join(lines)

    def write(self, out) -> dict[str, Any]:
        """Write ``history.csv``, ``convergence.csv``, ``optimum.json`` and ``optimise.png`` to the directory
        ``out`` (atomically each); returns the summary dict."""
        from pathlib import Path

        from ..outputs import atomic_write_json, atomic_write_text, prepare_output_dir
        from ..results.optimise_plots import plot_optimisation
        from ..results.plotting import save_figure

        out = prepare_output_dir(Path(out))
        atomic_write_text(out / "history.csv", self.history.to_csv(index=False))
        atomic_write_text(out / "convergence.csv", self.convergence.to_csv(index=False))
        data = self.to_dict()
        atomic_write_json(out / "optimum.json", data)
        save_figure(plot_optimisation(self), out / "optimise.png")
        return data


class _Evaluations:
    """Simulates populations through a backend, once per point, and keeps every row in order."""

    def __init__(self, scene: Scene, keys: list[str], settings, backend, minimise: str,
                 constraints: tuple[Constraint, ...], progress: Callable[[str], None] | None):
        self.scene, self.keys, self.settings, self.backend = scene, keys, settings, backend
        self.minimise, self.constraints, self.progress = minimise, constraints, progress
        self.cache: dict[tuple[float, ...], dict[str, Any]] = {}
        self.rows: list[dict[str, Any]] = []
        #: 0 for the initial population (and scipy's probe of its first point), k for the k-th generation's
        #: trials: scipy evaluates the constraints of every population first, in one call
        self.generation, self.batches = 0, 0

    def _ok(self, row: Mapping[str, Any]) -> bool:
        if row["status"] != "ok":
            return False
        metrics = [self.minimise, *(c.metric for c in self.constraints)]
        return all(row.get(m) is not None and math.isfinite(float(row[m])) for m in metrics)

    def rows_for(self, xs: np.ndarray) -> list[dict[str, Any]]:
        """The rows of the points ``xs`` (shape (S, N)), simulating the new ones in one parallel batch."""
        from .backends import batch_size
        from .grid_sweep import run_points

        points = [tuple(float(v) for v in x) for x in np.atleast_2d(xs)]
        new = list(dict.fromkeys(p for p in points if p not in self.cache))
        if new:
            size = batch_size(len(new), self.backend.workers)
            indexed = [(i, dict(zip(self.keys, p))) for i, p in enumerate(new)]
            tasks = [(self.scene, self.settings, indexed[i:i + size]) for i in range(0, len(indexed), size)]
            done: dict[int, dict[str, Any]] = {}
            for batch in run_points(self.backend, tasks):   # a point whose worker dies: a failed row
                done.update(batch)
            for i, p in enumerate(new):
                row = done[i]
                if row["status"] == "ok" and not self._ok(row):
                    missing = [m for m in [self.minimise, *(c.metric for c in self.constraints)]
                               if row.get(m) is None or not math.isfinite(float(row[m]))]
                    row.update(status="MissingMetric", error=f"no value of {', '.join(missing)} at this point")
                violation = (math.inf if not self._ok(row) else
                             max([c.violation(row[c.metric]) for c in self.constraints], default=0.0))
                row.update(evaluation=len(self.rows), generation=self.generation,
                           feasible=violation == 0.0, violation=violation)
                self.cache[p] = row
                self.rows.append(row)
            if self.progress:
                failed = sum(1 for p in new if self.cache[p]["status"] != "ok")
                self.progress(f"generation {self.generation}: {len(new)} points"
                              + (f" ({failed} failed: infeasible)" if failed else ""))
        return [self.cache[p] for p in points]

    def objective(self, x: np.ndarray) -> np.ndarray | float:
        """scipy's vectorised objective: ``x`` has shape (N, S) (or (N,) for one point)."""
        rows = self.rows_for(np.asarray(x).T)
        values = np.array([float(r[self.minimise]) if self._ok(r) else math.inf for r in rows])
        return values if np.ndim(x) == 2 else values[0]

    def constraint_values(self, x: np.ndarray) -> np.ndarray:
        """scipy's vectorised constraint function: rows ``[solved flag, each metric]``, shape (1 + M, S).

        The flag is 0 for a solved point and 1 for a failed one (bound: <= 0); a failed point's metrics
        are +inf for an upper limit and -inf for a lower one (the largest violation)."""
        if np.ndim(x) == 2:  # a population: the initial one (generation 0), then each generation's trials
            self.generation, self.batches = self.batches, self.batches + 1
        rows = self.rows_for(np.asarray(x).T)
        out = np.empty((1 + len(self.constraints), len(rows)))
        for j, row in enumerate(rows):
            ok = self._ok(row)
            out[0, j] = 0.0 if ok else 1.0
            for i, c in enumerate(self.constraints, start=1):
                out[i, j] = float(row[c.metric]) if ok else (math.inf if c.upper else -math.inf)
        return out if np.ndim(x) == 2 else out[:, 0]


def optimisable_metrics(scene: Scene) -> list[str]:
    """The metrics of ``scene`` that can be minimised or constrained: every metric column of its sweep
    rows but the run information (end time, stop reason, steps, initial velocity)."""
    from .point import RUN_COLUMNS, metric_columns

    return [m for m in metric_columns(scene) if m not in RUN_COLUMNS]


def check_problem(scene: Scene, bounds: Mapping[str, tuple[float, float]], minimise: str,
                  constraints: Sequence[str | Constraint] = (), *, end_time: float = 10.0,
                  accuracy: str = "standard", seed: int = 1, popsize: int = 10, maxiter: int = 30,
                  tol: float = 1e-4) -> tuple[dict[str, tuple[float, float]], tuple[Constraint, ...], list[str]]:
    """Every argument of :func:`optimise` checked before any simulation: ``(bounds, constraints,
    metrics)``, or one SceneError naming the argument (or the scene key) and what is allowed."""
    from ..engine.accuracy import solver_settings_for
    from ..engine.simulation import _check_arguments
    from ..results.sweep_plots import check_column

    if not isinstance(scene, Scene):
        raise SceneError("scene", f"must be a Scene, got {type(scene).__name__}")
    bounds = check_bounds(scene, bounds)
    metrics = optimisable_metrics(scene)
    check_column(str(minimise), metrics, "minimise", "metric")
    constraints = tuple(parse_constraint(c, "constraints") for c in constraints)
    for c in constraints:
        check_column(c.metric, metrics, "constraints", "metric")
    for name, value, low in (("popsize", popsize, 1), ("maxiter", maxiter, 0), ("seed", seed, 0)):
        if isinstance(value, bool) or not isinstance(value, int) or value < low:
            raise SceneError(name, f"must be a whole number >= {low}, got {value!r}")
    if isinstance(tol, bool) or not isinstance(tol, (int, float)) or not tol >= 0:
        raise SceneError("tol", f"must be a number >= 0, got {tol!r}")
    _check_arguments(scene, end_time, 0.0)
    solver_settings_for(accuracy)
    return bounds, constraints, metrics


def optimise(scene: Scene, bounds: Mapping[str, tuple[float, float]], minimise: str,
             constraints: Sequence[str | Constraint] = (), *, end_time: float = 10.0,
             accuracy: str = "standard", stop_when_final: bool = True, seed: int = 1, popsize: int = 10,
             maxiter: int = 30, tol: float = 1e-4, init: str = "latinhypercube", workers: int | None = None,
             scheduler: Any = None, progress: Callable[[str], None] | None = None,
             worker_timeout: float | None = None) -> OptimisationResult:
    """Minimise the metric ``minimise`` of ``scene`` over the fields in ``bounds`` (dotted key ->
    (low, high), SI units), subject to ``constraints`` (``"metric<=value"``, ``"metric>=value"`` or
    :class:`Constraint`).

    Differential evolution (scipy, strategy ``best1bin``, mutation (0.5, 1), recombination 0.7) with a
    population of ``popsize`` times the number of parameters, at most ``maxiter`` generations after the
    initial population, stopping earlier once the standard deviation of the population's objective is
    below ``tol`` times its mean (scipy's ``tol``; the default 1e-4 is tighter than scipy's 0.01, because
    the metrics vary by only a few per cent over a design space: with 0.01 a gap search stopped after one
    generation, 3 mm from the optimum); no gradient polish.  ``seed`` fixes the random stream (same points
    on any backend).
    Each point is simulated to ``end_time`` (s) at ``accuracy``; with ``stop_when_final`` (default) a run
    ends as soon as the objective's and the constraints' metrics are proven final (when they all can be:
    :func:`early_stop_metrics`).  ``workers``/``scheduler``: the sweep's backends (local processes,
    default all CPUs; or a Dask scheduler address / Client; ``worker_timeout``: seconds without a worker
    before a Dask run stops, default 60).  A fault of the cluster (unreachable, scheduler lost, no worker) is
    an error of the whole optimisation, :class:`~mbs_models.errors.ClusterError`, never a failed point.  See
    the module docstring for how constraints and failed points are handled.
    """
    from scipy.optimize import NonlinearConstraint, differential_evolution

    import pandas as pd

    from ..engine.unit_slips import warn_unit_slips
    from .backends import make_backend
    from .point import PointSettings

    start = time.perf_counter()
    bounds, constraints, metrics = check_problem(scene, bounds, minimise, constraints, end_time=end_time,
                                                 accuracy=accuracy, seed=seed, popsize=popsize, maxiter=maxiter,
                                                 tol=tol)
    warn_unit_slips(scene, grid=bounds)  # at the corners of the design space, to the caller of optimise
    swf = early_stop_metrics([minimise, *(c.metric for c in constraints)]) if stop_when_final else ()
    settings = PointSettings(end_time=end_time, accuracy=accuracy, stop_when_final=swf)

    keys = list(bounds)
    convergence_rows: list[dict[str, Any]] = []
    with make_backend(workers, scheduler, worker_timeout) as backend:
        evaluations = _Evaluations(scene, keys, settings, backend, minimise, constraints, progress)
        # rows of constraint_values: the solved flag (<= 0), then each metric within its limit
        nonlinear = NonlinearConstraint(evaluations.constraint_values,
                                        np.array([-np.inf, *(-np.inf if c.upper else c.limit for c in constraints)]),
                                        np.array([0.0, *(c.limit if c.upper else np.inf for c in constraints)]))

        def callback(intermediate_result):
            best = evaluations.cache.get(tuple(float(v) for v in intermediate_result.x))
            convergence_rows.append({
                "generation": len(convergence_rows) + 1, "evaluations": len(evaluations.rows),
                "best_objective": float(intermediate_result.fun) if math.isfinite(intermediate_result.fun) else None,
                "best_feasible": bool(best["feasible"]) if best else False,
                "convergence": float(getattr(intermediate_result, "convergence", math.nan)),
                **{k: float(v) for k, v in zip(keys, intermediate_result.x)}})

        try:
            solution = differential_evolution(
                evaluations.objective, list(bounds.values()), strategy="best1bin", maxiter=maxiter,
                popsize=popsize, tol=tol, mutation=(0.5, 1.0), recombination=0.7, seed=seed, callback=callback,
                polish=False, init=init, updating="deferred", workers=1, vectorized=True, constraints=(nonlinear,))
        except ClusterError as exc:
            raise ClusterError(f"{exc} after {len(evaluations.rows):,} evaluations (generation "
                               f"{evaluations.generation}); the optimisation stopped, nothing of it is kept: "
                               "run it again") from None

    history = pd.DataFrame(evaluations.rows)
    front = [*HISTORY_COLUMNS, *keys]
    history = history[front + [c for c in history.columns if c not in front]]
    best = evaluations.cache[tuple(float(v) for v in solution.x)]
    metric_values = {m: best.get(m) for m in metrics + ["wall_time", "status", "error"]}
    constraint_values = [{"constraint": str(c), "metric": c.metric, "value": best.get(c.metric),
                          "limit": c.limit, "satisfied": c.violation(best.get(c.metric)) == 0.0}
                         for c in constraints]
    return OptimisationResult(
        scene=scene, minimise=minimise, bounds=bounds, constraints=constraints,
        parameters={k: float(v) for k, v in zip(keys, solution.x)}, metrics=metric_values,
        constraint_values=constraint_values, feasible=bool(best["feasible"]), history=history,
        convergence=pd.DataFrame(convergence_rows),
        settings={"seed": seed, "popsize": popsize, "population": max(5, popsize * len(keys)),  # scipy's rule
                  "maxiter": maxiter,
                  "tol": tol, "init": init, "strategy": "best1bin", "end_time": end_time,
                  "accuracy": accuracy if isinstance(accuracy, str) else repr(accuracy),
                  "stop_when_final": ",".join(swf), "backend": backend.name, "workers": backend.workers},
        message=str(solution.message), success=bool(solution.success), generations=int(solution.nit),
        evaluations=len(evaluations.rows), wall_time=time.perf_counter() - start)


__all__ = ["optimise", "check_problem", "optimisable_metrics", "OptimisationResult", "Constraint", "parse_constraint",
           "parse_bound", "check_bounds",
           "early_stop_metrics", "HISTORY_COLUMNS"]
