"""Reading a solve's sensors: :func:`read_segment` (one Exudyn solve) and :func:`collect` (the
:class:`~mbs_models.results.postprocess.Samples` of a run, its segments joined).

The engine's sensors store every output step; NaN or inf anywhere is a SimulationError naming the sensor and the
time, duplicate time stamps are dropped, and the accelerations Exudyn records as 0 at a solve's start are replaced
by the true ones (:func:`~mbs_models.engine.driver._initial_accelerations`).
"""

from __future__ import annotations

import numpy as np

from ..errors import SimulationError
from ..results.postprocess import Samples
from .accuracy import SolverSettings
from .assembly import Assembly



class NonFiniteSolve(SimulationError):
    """A solve's sensors hold NaN or inf: the solve diverged (the driver re-solves an adaptive one with a smaller
    maximum step, :data:`~mbs_models.engine.driver.MAX_DIVERGENCE_RETRIES` times at most)."""

def _stored(assembly: Assembly, name: str) -> np.ndarray:
    return np.asarray(assembly.mbs.GetSensorStoredData(assembly.sensors[name]), dtype=float)


def read_segment(assembly: Assembly, settings: SolverSettings, start_time: float = 0.0,
                  initial_accelerations: dict[str, float] | None = None) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The sensors of the last solve: (time s, values by sensor name), duplicate time stamps dropped;
    SimulationError for NaN/inf."""
    columns = {name: _stored(assembly, name) for name in assembly.sensors}
    if assembly.columns:  # outputs that are columns of a sensor of several (the carriage's tree node)
        wide = {sensor for sensor, _ in assembly.columns.values()}
        for name, (sensor, k) in assembly.columns.items():
            columns[name] = columns[sensor][:, [0, 1 + k]]
        for sensor in wide:
            del columns[sensor]
    for body, value in (initial_accelerations or {}).items():
        data = columns[f"{body}_acceleration"]
        if len(data) and data[0, 0] == start_time:
            data[0, 1] = value  # Exudyn records 0 at the start (see driver._initial_accelerations)
    finite = np.isfinite(np.concatenate([data.ravel() for data in columns.values()])).all()  # (each below: to name one)
    for name, data in columns.items():
        if not finite and not np.isfinite(data).all():
            first = int(np.flatnonzero(~np.all(np.isfinite(data), axis=1))[0])
            raise NonFiniteSolve(f"Exudyn {settings.solver} produced a non-finite {name.replace('_', ' ')} at "
                                  f"t = {data[first, 0]:.6g} s (the solve diverged; try a smaller step or "
                                  "tighter tolerance)")
    time = columns["barrel_position"][:, 0]
    later = time[1:] > time[:-1]
    rows = slice(None) if later.all() else np.concatenate([[True], later])  # drop duplicate time stamps, if any
    return (np.ascontiguousarray(time[rows]),
            {name: np.ascontiguousarray(data[rows, 1]) for name, data in columns.items()})


def collect(assembly: Assembly, end_time: float, settings: SolverSettings,
             initial_accelerations: dict[str, float] | None = None, segments: list | None = None) -> Samples:
    """Read the sensors into :class:`Samples`; raise SimulationError for NaN/inf or missing output.

    ``segments``: the ``(time, values)`` of every segment of a segmented run (:func:`~mbs_models.engine.driver._run_segments`),
    joined in order; the sample at a segment boundary appears twice, before and after it (a velocity
    jump of a shot, a jump of the breech force): a zero-length interval the post-processing skips.
    """
    if segments is None:
        segments = [read_segment(assembly, settings, 0.0, initial_accelerations)]
    if len(segments) == 1:
        time, values = segments[0]
    else:
        time = np.concatenate([t for t, _ in segments])
        values = {name: np.concatenate([v[name] for _, v in segments]) for name in segments[0][1]}
    if len(time) < 2:
        raise SimulationError(f"Exudyn {settings.solver} produced fewer than two output samples")
    if abs(time[-1] - end_time) > 1e-6 * max(1.0, end_time):
        raise SimulationError(f"Exudyn {settings.solver} output ends at t = {time[-1]:.6g} s, not at {end_time:g} s")
    bodies = [body.name for body in assembly.mechanism.bodies]
    planar = {name: values[name] for name in assembly.columns
              if not any(name == f"{b}_{q}" for b in bodies for q in ("position", "velocity", "acceleration"))}
    if assembly.planar is not None:  # the touchdown anchors in force at the samples
        for support, capture in assembly.planar.anchors.items():
            planar[f"support_{support}_anchor"] = capture.anchor_at(time)
        for support, capture in assembly.planar.onsets.items():  # a restitution law's lam in force
            planar[f"support_{support}_lam"] = capture.lam_at(time)
    return Samples(time=time, positions={b: values[f"{b}_position"] for b in bodies},
                   velocities={b: values[f"{b}_velocity"] for b in bodies},
                   accelerations={b: values[f"{b}_acceleration"] for b in bodies},
                   forces={c.name: values[f"{c.name}_force"] for c in assembly.mechanism.connectors
                           if c.records_force},
                   planar=planar)
