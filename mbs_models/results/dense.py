"""Densified output: a run's histories on a fine time grid, for plots and history files (not for metrics).

The solver's steps grow to the preset's maximum step (20 ms at ``draft`` and ``standard``) where the motion is
slow; drawn or written as they are, the step-end samples make visible straight chords there.  :func:`densify`
returns the same run (:class:`~mbs_models.results.result.Result`) with its histories at

* every step-end sample (so no sample -- no peak, no impact, no jump of a shot -- is lost), and
* in each step longer than the interval, ``n - 1`` equally spaced times, ``n = ceil(h / interval)``: no gap
  between neighbouring times exceeds the interval (up to rounding of the times, a few ulp) -- but after the rest
  time of a run stopped at rest, where the rest state is held (constant: nothing to draw between).

The interval is 1 ms by default (:func:`default_interval`: finer for a window under 2 s, coarser beyond 1000 s);
10 us to 1 s may be asked for.

Between the samples every quantity comes from the cubic Hermite interpolant of the step-end samples, the one the
metrics are refined on (:mod:`mbs_models.results.samples`): positions and velocities are the interpolant
(:meth:`Result.state_at <mbs_models.results.result.Result.state_at>`), accelerations the derivative of the
velocity's interpolant (third-order accurate; not the equations of motion); every force is its connector's law on
the interpolated state, as the refinement evaluates it (a contact's force with the onset rate its solve captured,
:func:`~mbs_models.results.refinement.contact_force_function`; the force on the mount,
:func:`~mbs_models.results.postprocess.support_force_samples`; a carriage's ground reactions,
:func:`~mbs_models.results.carriage.carriage_output`; the histories elements declare); energies are computed as
at the samples (:func:`~mbs_models.results.energies.energies`), the dissipated energies and the work integrated on
the dense intervals and each one anchored to its value at the step end before (so it equals the step-end history
at every sample).  At the samples every history is the step-end one.

Every metric of the dense Result is the step-end Result's (copied, never recomputed); its ``step_ends`` is that
Result.  The cost is paid only when asked for: :func:`~mbs_models.engine.simulation.simulate` never densifies
(sweeps and metrics read the step-end samples); the plots and ``recoil run --csv`` do.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..errors import SceneError
from .carriage import carriage_output, coordinate_samples
from .element_outputs import compute_histories
from .energies import energies
from .postprocess import support_force_samples
from .refinement import contact_force_function
from .samples import Interpolant, Samples

#: The largest gap (s) between the times of densified histories by default: 1 ms, below every time scale the
#: plots show outside impacts (impacts are sampled by the solver's own small steps) ...
DENSE_INTERVAL = 1e-3
#: ... or a smaller gap for a short window (window / PLOT_POINTS: under half a pixel of a 900-pixel-wide plot) ...
PLOT_POINTS = 2000
#: ... or a larger one for a window over 1000 s (window / MAX_ROWS: at most this many rows).
MAX_ROWS = 1_000_000
#: The allowed intervals (s): from 10 us (a 10 s run then has a million rows) to 1 s.
INTERVAL_RANGE = (1e-5, 1.0)


def default_interval(window: float) -> float:
    """The default largest gap (s) for a window of ``window`` s integrated:
    ``max(min(DENSE_INTERVAL, window / PLOT_POINTS), window / MAX_ROWS)`` -- 1 ms from 2 s to 1000 s."""
    return max(min(DENSE_INTERVAL, window / PLOT_POINTS), window / MAX_ROWS)


def check_interval(interval, key: str = "interval") -> float:
    """``interval`` (s) as a float; SceneError naming ``key`` unless it is a number in :data:`INTERVAL_RANGE`."""
    low, high = INTERVAL_RANGE
    try:
        value = float(interval)
    except (TypeError, ValueError):
        value = math.nan
    if isinstance(interval, bool) or not low <= value <= high:
        raise SceneError(key, f"the largest gap between output times must be from {low:g} to {high:g} s, "
                              f"got {interval!r}")
    return value


def dense_times(time: np.ndarray, interval: float, held_from: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(times, rows)``: the step-end ``time`` (s) with equally spaced times inserted in every step longer than
    ``interval`` (module docstring; none in a zero-length step, the jump of a shot, nor in a step from
    ``held_from`` on, a rest state held constant), and the row of each sample among them (the times there are
    the samples' own)."""
    time = np.asarray(time, dtype=float)
    h = np.diff(time)
    pieces = np.where(h > interval, np.ceil(h / interval), 1.0)
    if held_from is not None:
        pieces[time[:-1] >= held_from] = 1.0
    pieces = pieces.astype(np.int64)
    rows = np.concatenate([[0], np.cumsum(pieces)])
    step = np.repeat(np.arange(len(h)), pieces)  # the step each row but the last begins or lies in
    fraction = (np.arange(rows[-1]) - rows[:-1][step]) / pieces[step]
    times = np.append(time[step] + h[step] * fraction, time[-1])
    times[rows] = time
    return times, rows


def output_histories(result, interval: float | None = None, step_ends: bool = False):
    """What a plot or a history file shows of ``result``: :func:`densify` at ``interval`` (s; None: the
    default, :func:`default_interval`), or with ``step_ends`` the step-end samples themselves (the step-end
    Result of a densified one)."""
    if step_ends:
        return result if result.step_ends is None else result.step_ends
    return densify(result, interval)


class _OnDenseIntervals:
    """The step-end samples' interpolant asked at fractions of the dense grid's intervals (for the quadratures of
    :func:`~mbs_models.results.energies.energies`): the interpolant of the solve, not one of the dense values."""

    def __init__(self, interpolant: Interpolant, time: np.ndarray):
        self.interpolant, self.time = interpolant, time

    def state(self, t, bodies=None):
        return self.interpolant.state(t, bodies)

    def at_fractions(self, fractions) -> tuple[dict, dict]:
        t0 = self.time[:-1]
        return self.interpolant.state(t0 + np.asarray(fractions, dtype=float)[:, None] * (self.time[1:] - t0))


def _merged(rows: np.ndarray, between: np.ndarray, sampled, values) -> np.ndarray:
    """A dense history: ``sampled`` at the samples' ``rows``, ``values`` at the other rows (``between``)."""
    out = np.empty(len(between))
    out[rows] = sampled
    out[between] = values
    return out


def _anchored(dense: np.ndarray, sampled: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """A cumulative history (J) integrated on the dense intervals, anchored to its step-end value at the sample
    before each time: ``E(t) = E_samples(t_i) + (E_dense(t) - E_dense(t_i))``, ``t_i`` the last sample <= t."""
    before = np.searchsorted(rows, np.arange(len(dense)), side="right") - 1
    return sampled[before] + (dense - dense[rows][before])


def densify(result, interval: float | None = None):
    """``result`` with every history on the dense grid of ``interval`` (s; None: :func:`default_interval` of the
    window integrated, up to the rest time of a run at rest; module docstring): a Result whose metrics are
    ``result``'s and whose ``step_ends`` is the step-end Result.  SceneError naming ``interval`` outside
    :data:`INTERVAL_RANGE`; ValueError for a Result without its samples and laws (not built by a solve)."""
    base = result if result.step_ends is None else result.step_ends
    s, mechanism = base.samples, base.mechanism
    if s is None or mechanism is None:
        raise ValueError("densify: the Result has no step-end samples and laws (it was not built by a solve)")
    integrated = base.rest_time if base.rest_time is not None else float(s.time[-1])
    interval = default_interval(integrated - float(s.time[0])) if interval is None else check_interval(interval)
    time, rows = dense_times(s.time, interval, base.rest_time)
    between = np.ones(len(time), dtype=bool)
    between[rows] = False
    interp = Interpolant(s)
    inner = time[between]
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        x, v = interp.state(inner)
        a = interp.accelerations(inner)
        forces = {name: contact_force_function(mechanism, mechanism.connector[name])(x, v, inner) for name in s.forces}
        dense = Samples(time=time,
                        positions={n: _merged(rows, between, s.positions[n], x[n]) for n in s.positions},
                        velocities={n: _merged(rows, between, s.velocities[n], v[n]) for n in s.velocities},
                        accelerations={n: _merged(rows, between, s.accelerations[n], a[n]) for n in s.accelerations},
                        forces={n: _merged(rows, between, s.forces[n], forces[n]) for n in s.forces},
                        planar=_dense_planar(s, rows, between, inner))
        support = support_force_samples(mechanism, dense)
        dense_interp = _OnDenseIntervals(interp, time)
        energy = energies(mechanism, dense, dense_interp)
        carriage = base.carriage
        if s.planar:  # the carriage's histories (its metrics stay the step-end ones) and planar energies
            carriage = _dense_carriage(base.carriage, carriage_output(mechanism, dense, dense_interp, energy))
        element_histories = compute_histories(mechanism, dense, interp)
    return replace(base, time=time, positions=dense.positions, velocities=dense.velocities,
                   accelerations=dense.accelerations,
                   contacts={name: replace(c, force=dense.forces[name]) for name, c in base.contacts.items()},
                   support_force=support, kinetic_energy_histories=energy.kinetic,
                   stored_energy_histories=energy.stored,
                   dissipated_energy_history={n: _anchored(h, base.dissipated_energy_history[n], rows)
                                              for n, h in energy.dissipated.items()},
                   work_histories={n: _anchored(h, base.work_histories[n], rows) for n, h in energy.work.items()},
                   element_histories=element_histories, carriage=carriage, step_ends=base)


def _dense_planar(s: Samples, rows: np.ndarray, between: np.ndarray, inner: np.ndarray) -> dict[str, np.ndarray]:
    """A carriage scene's other histories on the dense grid: its coordinates (``carriage_x_position`` ...) on
    their interpolant, and each support's ``lam`` and touchdown ``anchor`` as in force in each step (set at its
    start: the value of the step's end sample, as the planar energies read them); the recorded connector forces
    are not carried over (nothing reads them)."""
    if not s.planar:
        return {}
    coordinates = Interpolant(coordinate_samples(s))
    q, v = coordinates.state(inner)
    a = coordinates.accelerations(inner)
    step_end = np.searchsorted(rows, np.flatnonzero(between), side="right")  # the sample ending each inner row's step
    out = {}
    for name, values in s.planar.items():
        coordinate, _, kind = name.rpartition("_")
        if coordinate in coordinates.names and kind in ("position", "velocity", "acceleration"):
            inside = {"position": q, "velocity": v, "acceleration": a}[kind][coordinate]
        elif name.endswith(("_lam", "_anchor")):
            if np.ndim(values) == 0:
                out[name] = values
                continue
            inside = np.asarray(values)[step_end]
        else:
            continue
        out[name] = _merged(rows, between, values, inside)
    return out


def _dense_carriage(step_end, dense):
    """The step-end CarriageOutput with the dense one's histories (position, pitch, each support's forces and
    height): its metrics stay the step-end ones."""
    supports = {name: replace(support, normal_force=dense.supports[name].normal_force,
                              tangential_force=dense.supports[name].tangential_force,
                              height=dense.supports[name].height)
                for name, support in step_end.supports.items()}
    return replace(step_end, position=dense.position, pitch=dense.pitch, supports=supports)
