"""Contact-law calibration: identify Hunt-Crossley parameters from observed impact results.

Engineers fit a contact law to drop-test data; here the same tool states which contact law the paper's
published Section 2.2 results imply.  Any subset of the Hunt-Crossley parameters (Eq. 6)

* ``"stiffness"``       k_c in N/m^n_c   (fitted as log10 k_c),
* ``"exponent"``        n_c              (fitted as is),
* ``"damping_factor"``  lambda_c in s/m  (fitted as is, or as log10 lambda with ``log_damping=True``),

is fitted by non-linear least squares (:func:`scipy.optimize.least_squares`, trust-region reflective,
finite-difference Jacobian) to a list of :class:`Observation` (a scene, a metric, a target value).  Every
residual is ``weight * (model - target) / scale`` with ``scale = |target|`` by default, i.e. a relative error.
Parameters that are not fitted keep the values of each observation's scene; the fitted ones are shared by
all scenes (the gap always stays the scene's own).

The forward model is by default the independent scipy reference (:func:`validation.reference.solve_reference`,
``rtol = 1e-8`` for speed); ``solver="engine"`` uses the Exudyn engine (:func:`mbs_models.simulate`,
accuracy ``"standard"``), and any callable ``simulate(scene, end_time) -> object`` whose attributes carry the
metric names can be passed.  Observations sharing a scene and an end time share one forward solve.

The result (:class:`CalibrationResult`) says honestly whether the parameters are identifiable from the data:
the rank and condition number of the Jacobian at the solution, its near-null directions (parameter
combinations the data do not constrain), and a covariance only when it is well defined.
:func:`paper_section22_calibration` applies the tool to the paper's Section 2.2 numbers and
:func:`predict_table2` evaluates what the calibrated law predicts for Table 2.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field, replace
from typing import Any, Callable, Iterable, Mapping, Sequence

import numpy as np
from scipy.optimize import least_squares

from mbs_models.errors import SceneError, SimulationError
from mbs_models.scene.models import model_i, model_ii
from mbs_models.scene import Contact, Conventions, Scene

from . import paper

__all__ = [
    "QUANTITIES", "PARAMETERS", "DEFAULT_BOUNDS", "Observation", "CalibrationResult", "CalibrationWarning",
    "calibrate_contact", "reference_forward", "engine_forward", "paper_section22_observations",
    "paper_section22_calibration", "predict_table2",
]

#: Observable quantities -> unit.  The first-impact ones are read over a short run (see Observation.end_time).
QUANTITIES: dict[str, str] = {
    "peak_contact_force": "N",
    "time_of_peak_contact_force": "s",
    "max_absorber_velocity": "m/s",
    "time_of_max_absorber_velocity": "s",
    "first_impact_duration": "s",
    "max_barrel_displacement": "m",
}
#: Calibratable contact parameters (fields of :class:`mbs_models.scene.Contact`).
PARAMETERS = ("stiffness", "exponent", "damping_factor")
#: Default search bounds in physical units: k_c (N/m^n_c), n_c, lambda_c (s/m).
DEFAULT_BOUNDS: dict[str, tuple[float, float]] = {
    "stiffness": (1e5, 1e13),
    "exponent": (1.0, 2.5),
    "damping_factor": (0.0, 5.0),
}
#: Lower bound used for lambda when it is fitted as log10 lambda and the given bound is 0.
_LOG_DAMPING_FLOOR = 1e-4
#: Run length (s) for first-impact quantities with zero gap; a gap adds 4 gap / v0.
_SHORT_END_TIME = 0.1
#: Run length (s) for the maximum barrel displacement (the paper's 10 s).
_LONG_END_TIME = 10.0
#: Singular values of the Jacobian below RANK_TOL * largest count as zero (finite-difference noise level).
RANK_TOL = 1e-6
#: Condition number above which the fit is reported as poorly conditioned.
CONDITION_WARN = 1e4
#: |correlation| above which two fitted parameters are reported as strongly correlated.
STRONG_CORRELATION = 0.99
#: Components of a near-null direction larger than this mark the parameter as involved in it.
_NULL_COMPONENT = 0.1
_LABELS = {"stiffness": "k_c", "exponent": "n_c", "damping_factor": "lambda_c"}
_UNITS = {"stiffness": "N/m^n_c", "exponent": "", "damping_factor": "s/m"}


class CalibrationWarning(UserWarning):
    """The calibration problem is under-determined or the fit is unreliable (see the message)."""


def _finite_number(key: str, value, *, positive: bool = False, nonnegative: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise SceneError(key, f"must be a number, got {type(value).__name__} {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise SceneError(key, f"must be a finite number, got {value}")
    if positive and not value > 0:
        raise SceneError(key, f"must be > 0, got {value:g}")
    if nonnegative and value < 0:
        raise SceneError(key, f"must be >= 0, got {value:g}")
    return value


def default_end_time(scene: Scene, quantity: str) -> float:
    """Shortest run (s) that contains what ``quantity`` needs.

    ``max_barrel_displacement``: 10 s (the paper's runs).  First-impact quantities: 0.1 s (a zero-gap impact
    lasts about 15 ms) plus ``4 gap / v0`` for the barrel to close the gap, at most 10 s.
    """
    if quantity == "max_barrel_displacement":
        return _LONG_END_TIME
    gap = scene.contact.gap if scene.contact is not None else 0.0
    v0 = abs(scene.initial_velocity)
    extra = 4.0 * gap / v0 if v0 > 0 else _LONG_END_TIME
    return float(min(_SHORT_END_TIME + extra, _LONG_END_TIME))


@dataclass(frozen=True)
class Observation:
    """One observed number to fit: ``quantity`` of ``scene`` should equal ``target``.

    Attributes
    ----------
    scene: a scene with an absorber and a contact; its contact supplies the fixed parameters (and, for the
        first observation, the starting guess of the free ones).
    quantity: one of :data:`QUANTITIES` (``"peak_contact_force"`` N, ``"max_absorber_velocity"`` m/s,
        ``"time_of_max_absorber_velocity"`` s, ``"time_of_peak_contact_force"`` s, ``"max_barrel_displacement"``
        m, ``"first_impact_duration"`` s).  Maxima are taken over ``[0, end_time]``.
    target: the observed value, finite and > 0, in the quantity's unit.
    scale: residual divisor in the quantity's unit; default ``|target|`` (relative residual).  With
        ``absolute_sigma=True`` in :func:`calibrate_contact` it is the observation's standard deviation.
    weight: residual multiplier (>= 0), default 1.
    end_time: simulated time in s; default :func:`default_end_time` (0.1 s for first-impact quantities at
        zero gap, 10 s for the barrel displacement).
    label: free text shown in reports.
    """

    scene: Scene
    quantity: str
    target: float
    scale: float | None = None
    weight: float = 1.0
    end_time: float | None = None
    label: str = ""

    def __post_init__(self):
        if not isinstance(self.scene, Scene):
            raise SceneError("observation.scene", f"must be a mbs_models Scene, got {type(self.scene).__name__}")
        if self.scene.contact is None:
            raise SceneError("observation.scene",
                             f"scene {self.scene.name!r} has no absorber/contact: nothing to calibrate")
        if not isinstance(self.quantity, str) or self.quantity not in QUANTITIES:
            raise SceneError("observation.quantity",
                             f"unknown quantity {self.quantity!r}; allowed: {', '.join(QUANTITIES)}")
        object.__setattr__(self, "target", _finite_number("observation.target", self.target, positive=True))
        if self.scale is not None:
            object.__setattr__(self, "scale", _finite_number("observation.scale", self.scale, positive=True))
        object.__setattr__(self, "weight", _finite_number("observation.weight", self.weight, nonnegative=True))
        if self.end_time is None:
            object.__setattr__(self, "end_time", default_end_time(self.scene, self.quantity))
        else:
            object.__setattr__(self, "end_time",
                               _finite_number("observation.end_time", self.end_time, positive=True))
        if not isinstance(self.label, str):
            raise SceneError("observation.label", "must be a string")

    @property
    def residual_scale(self) -> float:
        """The divisor of the residual: ``scale`` or ``|target|``."""
        return self.scale if self.scale is not None else abs(self.target)

    @property
    def unit(self) -> str:
        return QUANTITIES[self.quantity]

    @property
    def description(self) -> str:
        return self.label or f"{self.scene.model_label}: {self.quantity} ({self.scene.name})"


# ------------------------------------------------------------------------------------- forward models
def reference_forward(rtol: float = 1e-8, atol: float = 1e-11, method: str = "DOP853", **options) -> Callable:
    """Forward model ``simulate(scene, end_time)`` using the scipy reference with the given tolerances."""
    from ..reference import solve_reference

    def simulate(scene: Scene, end_time: float):
        return solve_reference(scene, end_time, method=method, rtol=rtol, atol=atol, **options)
    simulate.label = f"validation reference ({method}, rtol={rtol:g}, atol={atol:g})"
    simulate.builtin = "reference"
    return simulate


def engine_forward(accuracy: Any = "standard", **options) -> Callable:
    """Forward model ``simulate(scene, end_time)`` using the Exudyn engine, :func:`mbs_models.simulate`."""
    def simulate(scene: Scene, end_time: float):
        from mbs_models.engine.simulation import simulate as run
        return run(scene, end_time, accuracy, **options)
    simulate.label = f"Exudyn engine (accuracy {accuracy if isinstance(accuracy, str) else 'custom'})"
    simulate.builtin = "engine"
    return simulate


def _resolve_solver(solver) -> Callable:
    if solver is None or (isinstance(solver, str) and solver == "reference"):
        return reference_forward()
    if isinstance(solver, str) and solver == "engine":
        return engine_forward()
    if callable(solver):
        return solver
    raise SceneError("solver", f"must be None, 'reference', 'engine' or a callable simulate(scene, end_time), "
                               f"got {solver!r}")


def _metric(result, quantity: str) -> float | None:
    """Read ``quantity`` off a forward result (reference, engine or user object)."""
    if quantity == "first_impact_duration" and not hasattr(result, "first_impact_duration"):
        impacts = getattr(result, "impacts", None)
        if not impacts:
            return None
        first = impacts[0]
        return float(first.duration) if hasattr(first, "duration") else float(first.end - first.start)
    value = getattr(result, quantity, None)
    return None if value is None else float(value)


# ------------------------------------------------------------------------------------- transforms
class _Transform:
    """Maps the free physical parameters to the optimiser's variables and back."""

    def __init__(self, names: Sequence[str], log_damping: bool):
        self.names = tuple(names)
        self.log_damping = log_damping

    def is_log(self, name: str) -> bool:
        return name == "stiffness" or (name == "damping_factor" and self.log_damping)

    def variable_name(self, name: str) -> str:
        return f"log10_{name}" if self.is_log(name) else name

    def to_u(self, values: Mapping[str, float]) -> np.ndarray:
        return np.array([math.log10(values[n]) if self.is_log(n) else values[n] for n in self.names])

    def to_p(self, u: np.ndarray) -> dict[str, float]:
        return {n: float(10.0 ** x if self.is_log(n) else x) for n, x in zip(self.names, u)}

    def dp_du(self, u: np.ndarray) -> np.ndarray:
        """Derivative of each physical parameter with respect to its variable."""
        return np.array([math.log(10.0) * 10.0 ** x if self.is_log(n) else 1.0 for n, x in zip(self.names, u)])


def _check_parameters(parameters) -> tuple[str, ...]:
    if isinstance(parameters, str):
        parameters = (parameters,)
    try:
        names = tuple(parameters)
    except TypeError:
        raise SceneError("parameters", f"must be a sequence of names from {', '.join(PARAMETERS)}") from None
    if not names:
        raise SceneError("parameters", f"empty: name at least one of {', '.join(PARAMETERS)}")
    for name in names:
        if name not in PARAMETERS:
            raise SceneError(f"parameters.{name}", f"unknown contact parameter {name!r}; allowed: "
                                                   f"{', '.join(PARAMETERS)}")
    if len(set(names)) != len(names):
        raise SceneError("parameters", f"repeated names in {names}")
    return tuple(n for n in PARAMETERS if n in names)  # canonical order


def _check_bounds(names, bounds, log_damping) -> dict[str, tuple[float, float]]:
    out = {n: DEFAULT_BOUNDS[n] for n in names}
    if bounds is not None:
        if not isinstance(bounds, Mapping):
            raise SceneError("bounds", "must be a mapping {parameter: (low, high)}")
        for name, pair in bounds.items():
            if name not in PARAMETERS:
                raise SceneError(f"bounds.{name}", f"unknown contact parameter; allowed: {', '.join(PARAMETERS)}")
            if name not in names:
                continue
            try:
                lo, hi = pair
            except (TypeError, ValueError):
                raise SceneError(f"bounds.{name}", f"must be a pair (low, high), got {pair!r}") from None
            lo = _finite_number(f"bounds.{name}", lo)
            hi = _finite_number(f"bounds.{name}", hi)
            if not lo < hi:
                raise SceneError(f"bounds.{name}", f"low must be < high, got ({lo:g}, {hi:g})")
            out[name] = (lo, hi)
    for name, (lo, hi) in out.items():
        if name in ("stiffness", "exponent") and not lo > 0:
            raise SceneError(f"bounds.{name}", f"low must be > 0, got {lo:g}")
        if name == "damping_factor" and lo < 0:
            raise SceneError(f"bounds.{name}", f"low must be >= 0, got {lo:g}")
        if name == "damping_factor" and log_damping and lo == 0:
            out[name] = (min(_LOG_DAMPING_FLOOR, hi / 10.0), hi)
    return out


def _check_observations(observations) -> list[Observation]:
    if isinstance(observations, Observation):
        observations = [observations]
    try:
        obs = list(observations)
    except TypeError:
        raise SceneError("observations", "must be a list of Observation") from None
    if not obs:
        raise SceneError("observations", "empty: give at least one Observation")
    for i, o in enumerate(obs):
        if not isinstance(o, Observation):
            raise SceneError(f"observations[{i}]", f"must be an Observation, got {type(o).__name__}")
    if all(o.weight == 0 for o in obs):
        raise SceneError("observations", "every observation has weight 0: nothing to fit")
    return obs


# ------------------------------------------------------------------------------------- result
def _clean(value):
    """JSON-ready copy: numpy scalars/arrays to Python, NaN/inf to None."""
    if isinstance(value, Mapping):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, np.ndarray):
        return _clean(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer, int)):
        return int(value)
    if isinstance(value, (np.floating, float)):
        value = float(value)
        return value if math.isfinite(value) else None
    return value


@dataclass
class CalibrationResult:
    """Outcome of :func:`calibrate_contact` (SI units).

    Attributes
    ----------
    parameters: fitted free parameters ``{name: value}`` (physical units).
    contact: the calibrated :class:`~mbs_models.scene.Contact` (the first observation's contact with the
        fitted values; its gap is that scene's gap).
    fixed: parameters held at the scenes' values ``{name: value}`` (from the first observation's scene).
    initial: starting values of the free parameters.
    residuals: one dict per observation: description, quantity, unit, target, value (fitted law),
        initial_value (starting law), relative_error ``(value - target) / target``, residual (weighted).
    cost: ``0.5 * sum(residual**2)`` at the solution.
    success: True when the optimiser converged *and* every fitted parameter is identifiable.
    converged: the optimiser's own success flag; ``message`` says why it stopped and what is not identified.
    forward_solves: number of forward simulations (including the finite-difference Jacobian).
    covariance: covariance of the optimiser variables (log10 k_c, n_c, lambda or log10 lambda), or None
        when not defined (rank-deficient Jacobian, or no degrees of freedom without ``absolute_sigma``).
    standard_errors: standard errors of the physical parameters (delta method), or None.
    correlation: correlation matrix of the variables, or None.
    identifiability: rank, condition number, singular values, near-null directions and a status per
        parameter (``"identifiable"``, ``"poorly determined"``, ``"not identifiable"``).
    """

    parameters: dict[str, float]
    contact: Contact
    fixed: dict[str, float]
    initial: dict[str, float]
    variables: list[str]
    residuals: list[dict[str, Any]]
    cost: float
    initial_cost: float
    success: bool
    converged: bool
    message: str
    optimizer_status: int
    forward_solves: int
    iterations: int
    covariance: list[list[float]] | None
    standard_errors: dict[str, float] | None
    correlation: list[list[float]] | None
    identifiability: dict[str, Any]
    solver: str
    wall_time: float
    jacobian: np.ndarray = field(repr=False, default=None)

    @property
    def identifiable(self) -> bool:
        """True when the Jacobian has full column rank (every fitted parameter is constrained by the data)."""
        return bool(self.identifiability.get("full_rank", False))

    @property
    def max_relative_error(self) -> float:
        """Largest |relative error| over the observations at the fitted law."""
        return max(abs(r["relative_error"]) for r in self.residuals)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (NaN and inf become None)."""
        c = self.contact
        return _clean({
            "parameters": self.parameters,
            "contact": {"law": c.law, "gap": c.gap, "stiffness": c.stiffness, "exponent": c.exponent,
                        "damping_factor": c.damping_factor},
            "fixed": self.fixed, "initial": self.initial, "variables": self.variables,
            "residuals": self.residuals, "cost": self.cost, "initial_cost": self.initial_cost,
            "success": self.success, "converged": self.converged, "identifiable": self.identifiable,
            "message": self.message, "optimizer_status": self.optimizer_status,
            "forward_solves": self.forward_solves, "iterations": self.iterations,
            "covariance": self.covariance, "standard_errors": self.standard_errors,
            "correlation": self.correlation, "identifiability": self.identifiability,
            "solver": self.solver, "wall_time": self.wall_time,
        })

    def summary(self) -> str:
        """A few human-readable lines."""
        lines = [f"contact calibration ({self.solver}): {'success' if self.success else 'NOT successful'} -- "
                 f"{self.message}"]
        for name, value in self.parameters.items():
            se = self.standard_errors.get(name) if self.standard_errors else None
            se_text = f" +- {se:.3g}" if se is not None and math.isfinite(se) else ""
            status = self.identifiability["parameters"][name]
            if name in self.identifiability.get("at_bounds", []):
                status += ", at the search bound"
            lines.append(f"  {_LABELS[name]:9s} = {value:.6g}{se_text} {_UNITS[name]}  [{status}]")
        for name, value in self.fixed.items():
            lines.append(f"  {_LABELS[name]:9s} = {value:.6g} {_UNITS[name]}  (fixed)")
        cond = self.identifiability.get("condition_number")
        lines.append(f"  Jacobian rank {self.identifiability['rank']} of {len(self.parameters)}, condition "
                     f"number {cond:.3g}" if cond is not None else
                     f"  Jacobian rank {self.identifiability['rank']} of {len(self.parameters)}")
        for r in self.residuals:
            lines.append(f"  {r['description']}: target {r['target']:.6g} {r['unit']}, fitted {r['value']:.6g} "
                         f"({100 * r['relative_error']:+.3f} %), start {r['initial_value']:.6g}")
        lines.append(f"  cost {self.cost:.3g} (start {self.initial_cost:.3g}), {self.forward_solves} forward "
                     f"solves, {self.wall_time:.1f} s")
        return "\n".join(lines)


# ------------------------------------------------------------------------------------- identifiability
def _identifiability(J: np.ndarray, names: Sequence[str], variables: Sequence[str], n_independent: int,
                     rank_tol: float) -> dict[str, Any]:
    m, n = J.shape
    out: dict[str, Any] = {"n_parameters": n, "n_observations": m, "n_independent_observations": n_independent,
                           "rank_tolerance": rank_tol}
    if not np.all(np.isfinite(J)):
        out.update(rank=0, full_rank=False, singular_values=[], condition_number=None, null_directions=[],
                   parameters={p: "not identifiable" for p in names},
                   message="the Jacobian is not finite; nothing can be said")
        return out
    _, s, vt = np.linalg.svd(J, full_matrices=True)
    s_full = np.zeros(n)
    s_full[:len(s)] = s
    smax = float(s_full.max()) if n else 0.0
    rank = int(np.sum(s_full > rank_tol * smax)) if smax > 0 else 0
    cond = float(smax / s_full.min()) if smax > 0 and s_full.min() > 0 else None
    status = {p: "identifiable" for p in names}
    directions = []
    for k in range(n):
        null = smax == 0 or s_full[k] <= rank_tol * smax
        weak = not null and s_full[k] * CONDITION_WARN < smax
        if not (null or weak):
            continue
        vec = vt[k]
        involved = {variables[j]: float(vec[j]) for j in range(n) if abs(vec[j]) > _NULL_COMPONENT}
        directions.append({"singular_value": float(s_full[k]), "relative": float(s_full[k] / smax) if smax else 0.0,
                           "kind": "null" if null else "weak", "direction": involved})
        for j in range(n):
            if abs(vec[j]) > _NULL_COMPONENT:
                if null:
                    status[names[j]] = "not identifiable"
                elif status[names[j]] == "identifiable":
                    status[names[j]] = "poorly determined"
    if rank < n:
        msg = (f"not identifiable: the Jacobian has rank {rank} for {n} parameters "
               f"({n_independent} independent observation{'s' if n_independent != 1 else ''}); "
               f"unconstrained: {', '.join(p for p in names if status[p] == 'not identifiable')}")
    elif cond is not None and cond > CONDITION_WARN:
        msg = (f"poorly conditioned (condition number {cond:.3g}): "
               f"{', '.join(p for p in names if status[p] != 'identifiable')} "
               f"are determined only in combination")
    else:
        msg = "all fitted parameters identifiable" + (f" (condition number {cond:.3g})" if cond else "")
    out.update(rank=rank, full_rank=rank == n, singular_values=[float(x) for x in s_full],
               condition_number=cond, null_directions=directions, parameters=status, message=msg)
    return out


# ------------------------------------------------------------------------------------- calibration
def calibrate_contact(observations: Iterable[Observation], parameters: Sequence[str] = PARAMETERS, initial:
                      Mapping[str, float] | None = None, bounds: Mapping[str, tuple[float, float]] | None = None,
                      solver: Callable | str | None = None, *, log_damping: bool = False,
                      diff_step: float | None = None, absolute_sigma: bool = False, max_iterations: int = 100,
                      rank_tol: float = RANK_TOL, ftol: float = 1e-12, xtol: float = 1e-10,
                      gtol: float = 1e-12) -> CalibrationResult:
    """Fit the Hunt-Crossley parameters ``parameters`` so that the observed quantities are reproduced.

    Parameters
    ----------
    observations: :class:`Observation` list (targets, scenes, quantities).
    parameters: the free parameters, any subset of ``("stiffness", "exponent", "damping_factor")``.
    initial: starting values ``{name: value}``; default the first observation's contact (clipped to bounds).
    bounds: ``{name: (low, high)}`` in physical units; defaults :data:`DEFAULT_BOUNDS`
        (k_c 1e5..1e13, n_c 1..2.5, lambda 0..5).
    solver: forward model: None / ``"reference"`` (scipy reference, rtol 1e-8), ``"engine"`` (Exudyn,
        accuracy ``"standard"``) or a callable ``simulate(scene, end_time)`` returning an object with the
        metric attributes (``impacts`` with ``duration`` for ``first_impact_duration``).
    log_damping: fit log10 lambda instead of lambda (lambda must then stay > 0).
    diff_step: relative finite-difference step of the Jacobian (default 1e-4 for the built-in reference,
        1e-3 for other forward models, whose metrics are noisier).
    absolute_sigma: treat each observation's ``scale / weight`` as its standard deviation (covariance
        ``(J^T J)^-1``); otherwise the covariance is scaled by the residual variance (needs more independent
        observations than parameters).
    max_iterations: cap on the optimiser's function evaluations.
    rank_tol: singular values below ``rank_tol * largest`` count as zero.
    ftol, xtol, gtol: :func:`scipy.optimize.least_squares` stopping tolerances.

    Raises
    ------
    SceneError: bad input (names the field: ``observations``, ``parameters.<name>``, ``initial.<name>``,
        ``bounds.<name>``, ``solver``...).
    SimulationError: a forward solve failed or lacks the requested metric (e.g. no impact before end_time).

    Warns
    -----
    CalibrationWarning: more free parameters than independent observations (the result then reports the
        parameters as not identifiable and ``success`` is False).
    """
    start = time.perf_counter()
    obs = _check_observations(observations)
    names = _check_parameters(parameters)
    simulate = _resolve_solver(solver)
    if diff_step is None:
        diff_step = 1e-4 if getattr(simulate, "builtin", None) == "reference" else 1e-3
    diff_step = _finite_number("diff_step", diff_step, positive=True)
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, int) or max_iterations < 1:
        raise SceneError("max_iterations", f"must be an integer >= 1, got {max_iterations!r}")
    box = _check_bounds(names, bounds, log_damping)
    tr = _Transform(names, log_damping)

    base = obs[0].scene.contact
    start_values = {n: float(getattr(base, n)) for n in names}
    if initial is not None:
        if not isinstance(initial, Mapping):
            raise SceneError("initial", "must be a mapping {parameter: value}")
        for name, value in initial.items():
            if name not in PARAMETERS:
                raise SceneError(f"initial.{name}", f"unknown contact parameter; allowed: {', '.join(PARAMETERS)}")
            if name in names:
                value = _finite_number(f"initial.{name}", value)
                lo, hi = box[name]
                if not lo <= value <= hi:
                    raise SceneError(f"initial.{name}", f"{value:g} lies outside the bounds [{lo:g}, {hi:g}]")
                start_values[name] = value
    for name in names:  # the scenes' values may lie outside user bounds: clip
        lo, hi = box[name]
        start_values[name] = min(max(start_values[name], lo), hi)

    # Observations sharing a scene and an end time share one forward solve.
    keys = [(o.scene, o.end_time) for o in obs]
    groups = list(dict.fromkeys(keys))
    n_independent = len({(o.scene, o.quantity, o.end_time) for o in obs if o.weight > 0})
    if len(names) > n_independent:
        warnings.warn(f"{len(names)} free contact parameters ({', '.join(names)}) but only {n_independent} "
                      f"independent observation{'s' if n_independent != 1 else ''}: the parameters cannot all be "
                      f"identified; the result will report which are not", CalibrationWarning, stacklevel=2)

    lower = tr.to_u({n: box[n][0] for n in names})
    upper = tr.to_u({n: box[n][1] for n in names})
    u0 = np.clip(tr.to_u(start_values), lower, upper)
    targets = np.array([o.target for o in obs])
    scales = np.array([o.residual_scale for o in obs])
    weights = np.array([o.weight for o in obs])
    counter = {"solves": 0}
    cache: dict[tuple, np.ndarray] = {}

    def values_at(u: np.ndarray) -> np.ndarray:
        key = tuple(np.asarray(u, dtype=float).tolist())
        if key in cache:
            return cache[key]
        p = tr.to_p(u)
        results = {}
        for scene, end_time in groups:
            changed = scene.with_changes(contact=replace(scene.contact, **p))
            counter["solves"] += 1
            try:
                results[(scene, end_time)] = simulate(changed, end_time)
            except SceneError:
                raise
            except Exception as exc:  # noqa: BLE001 - any forward failure is reported with the parameters
                raise SimulationError(f"forward solve of {scene.name!r} ({end_time:g} s) failed with "
                                      f"{_format(p)}: {exc}") from exc
        vals = np.empty(len(obs))
        for i, (o, key_i) in enumerate(zip(obs, keys)):
            v = _metric(results[key_i], o.quantity)
            if v is None or not math.isfinite(v):
                raise SimulationError(f"{o.description}: the forward model gives no finite {o.quantity} within "
                                      f"{o.end_time:g} s with {_format(p)} (no impact yet? increase "
                                      f"Observation.end_time)")
            vals[i] = v
        cache[key] = vals
        return vals

    def residual(u: np.ndarray) -> np.ndarray:
        return weights * (values_at(u) - targets) / scales

    r0 = residual(u0)
    initial_values = values_at(u0).copy()
    sol = least_squares(residual, u0, bounds=(lower, upper), method="trf", x_scale=1.0, diff_step=diff_step,
                        max_nfev=max_iterations, ftol=ftol, xtol=xtol, gtol=gtol)
    u = sol.x
    fitted = tr.to_p(u)
    final_values = values_at(u)
    r = residual(u)
    J = np.asarray(sol.jac, dtype=float)
    m, n = J.shape

    variables = [tr.variable_name(nm) for nm in names]
    ident = _identifiability(J, names, variables, n_independent, rank_tol)
    span = upper - lower
    at_bound = [nm for j, nm in enumerate(names)
                if sol.active_mask[j] != 0 or min(u[j] - lower[j], upper[j] - u[j]) <= 1e-6 * span[j]]
    ident["at_bounds"] = at_bound

    covariance = standard_errors = correlation = None
    if ident["full_rank"]:
        _, s, vt = np.linalg.svd(J, full_matrices=False)
        unit_cov = (vt.T / s ** 2) @ vt  # (J^T J)^-1
        unit_sd = np.sqrt(np.diag(unit_cov))
        corr = unit_cov / np.outer(unit_sd, unit_sd)
        correlation = corr.tolist()
        pairs = [(names[i], names[j], float(corr[i, j])) for i in range(n) for j in range(i + 1, n)
                 if abs(corr[i, j]) > STRONG_CORRELATION]
        ident["strongly_correlated"] = [{"parameters": [a, b], "correlation": c} for a, b, c in pairs]
        if pairs:
            ident["message"] += "; strongly correlated: " + ", ".join(
                f"{a}/{b} ({c:+.4f}: the data fix a combination better than each)" for a, b, c in pairs)
        dof = int(np.sum(weights > 0)) - n
        if absolute_sigma:
            s2 = 1.0
        elif dof > 0 and n_independent > n:
            s2 = float(np.sum(r ** 2) / dof)
        else:
            s2 = None
        if s2 is not None:
            cov = unit_cov * s2
            covariance = cov.tolist()
            standard_errors = {nm: float(sd * math.sqrt(s2) * d) for nm, sd, d in zip(names, unit_sd, tr.dp_du(u))}
    else:
        ident["strongly_correlated"] = []

    residual_rows = []
    for o, v, v0_, ri in zip(obs, final_values, initial_values, r):
        residual_rows.append({"description": o.description, "model": o.scene.model_label, "scene": o.scene.name,
                              "quantity": o.quantity, "unit": o.unit, "end_time": o.end_time,
                              "target": o.target, "value": float(v), "initial_value": float(v0_),
                              "relative_error": float((v - o.target) / o.target),
                              "initial_relative_error": float((v0_ - o.target) / o.target),
                              "residual": float(ri)})

    converged = bool(sol.success) and sol.status > 0
    success = converged and ident["full_rank"]
    message = f"optimizer: {sol.message}; identifiability: {ident['message']}"
    if at_bound:
        message += (f"; at the search bound: {', '.join(at_bound)} (the data push beyond it; its standard "
                    f"error describes the bounded fit only)")
    contact = replace(base, **fitted)
    fixed = {nm: float(getattr(base, nm)) for nm in PARAMETERS if nm not in names}
    return CalibrationResult(
        parameters=fitted, contact=contact, fixed=fixed, initial=tr.to_p(u0), variables=variables,
        residuals=residual_rows, cost=float(0.5 * np.sum(r ** 2)), initial_cost=float(0.5 * np.sum(r0 ** 2)),
        success=success, converged=converged, message=message, optimizer_status=int(sol.status),
        forward_solves=counter["solves"], iterations=int(sol.nfev), covariance=covariance,
        standard_errors=standard_errors, correlation=correlation, identifiability=ident,
        solver=getattr(simulate, "label", getattr(simulate, "__name__", "custom forward model")),
        wall_time=time.perf_counter() - start, jacobian=J)


def _format(p: Mapping[str, float]) -> str:
    return ", ".join(f"{_LABELS[n]} = {v:.6g}" for n, v in p.items())


# ------------------------------------------------------------------------------------- the paper
_SECTION22_QUANTITIES = ("peak_contact_force", "max_absorber_velocity", "time_of_max_absorber_velocity")


def paper_section22_observations(models: Sequence[str] = ("i", "ii"),
                                 quantities: Sequence[str] = _SECTION22_QUANTITIES,
                                 conventions: Conventions | None = None,
                                 end_time: float | None = None) -> list[Observation]:
    """The Section 2.2 numbers as observations: model (i) 114.4 kN, 1.082 m/s at 0.01484 s; model (ii)
    116.7 kN, 1.079 m/s at 0.01495 s (m = 1000 kg, gap 0), on Table 1 scenes (the starting law)."""
    builders = {"i": (model_i, paper.MODEL_I), "ii": (model_ii, paper.MODEL_II)}
    obs = []
    for model in models:
        key = str(model).strip().lower().replace("model", "").strip(" ()")
        if key not in builders:
            raise SceneError("models", f"unknown model {model!r}; allowed: 'i', 'ii'")
        build, label = builders[key]
        for quantity in quantities:
            try:
                pv = paper.published(quantity, label, 1000.0)
            except KeyError:
                raise SceneError("quantities", f"the paper publishes no {quantity!r} for {label}") from None
            scene = build(pv.absorber_mass, 0.0, conventions)
            obs.append(Observation(scene, quantity, pv.value, end_time=end_time,
                                   label=f"{label}: {quantity} ({pv.source})"))
    return obs


def paper_section22_calibration(parameters: Sequence[str] = ("stiffness", "damping_factor"), *,
                                models: Sequence[str] = ("i", "ii"),
                                quantities: Sequence[str] = _SECTION22_QUANTITIES,
                                conventions: Conventions | None = None, **options) -> CalibrationResult:
    """Calibrate the contact law on the paper's Section 2.2 results (six observations by default).

    Starts from Table 1 (k_c = 2.1e8, n_c = 1.3, lambda = 0.6); parameters not listed stay at Table 1.
    ``options`` go to :func:`calibrate_contact` (``initial``, ``bounds``, ``solver``, ...).
    """
    return calibrate_contact(paper_section22_observations(models, quantities, conventions), parameters, **options)


def predict_table2(contact: Contact | CalibrationResult, *, conventions: Conventions | None = None,
                   end_time: float = 10.0, solver: Callable | str | None = None,
                   masses: Sequence[float] = paper.TABLE2_MASSES) -> list[dict[str, Any]]:
    """Table 2 (maximum barrel displacement, gap 0, ``end_time`` s) for models (i) and (ii) with ``contact``.

    ``contact`` is a :class:`Contact` or a :class:`CalibrationResult`; its k_c, n_c, lambda are used (the gap
    is 0 as in Table 2).  The forward model defaults to the scipy reference at its default (tight)
    tolerances, stopped once the maximum is proven final (the full run's value; validation.reference.finality).  Returns one row per (model, absorber mass): ``model``, ``absorber_mass`` (kg),
    ``max_barrel_displacement`` (m), ``published`` (m), ``relative_error``.
    """
    if isinstance(contact, CalibrationResult):
        contact = contact.contact
    if not isinstance(contact, Contact):
        raise SceneError("contact", f"must be a Contact or a CalibrationResult, got {type(contact).__name__}")
    if solver is None:
        from ..reference import solve_reference

        def simulate(scene: Scene, end_time: float):  # only the maximum is read: stop once it is final
            return solve_reference(scene, end_time, stop_when_final=("max_barrel_displacement",))
    else:
        simulate = _resolve_solver(solver)
    law = replace(contact, gap=0.0)
    published = paper.table2()
    rows = []
    for build, label in ((model_i, paper.MODEL_I), (model_ii, paper.MODEL_II)):
        for mass in masses:
            scene = build(float(mass), 0.0, conventions)
            scene = scene.with_changes(contact=law)
            x = float(simulate(scene, end_time).max_barrel_displacement)
            pv = published.get((label, float(mass)))
            rows.append({"model": label, "absorber_mass": float(mass), "max_barrel_displacement": x,
                         "published": pv.value if pv else None,
                         "relative_error": (x - pv.value) / pv.value if pv else None})
    return rows
