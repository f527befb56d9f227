"""A run's time histories as one table: a column per quantity with its unit, a row per output time.

``recoil run --csv FILE`` writes it (:func:`write_histories_csv`).  Columns (SI units, named
``"<what> [<unit>]"``): ``time [s]``; every body's position, velocity and acceleration; every contact's
force and the force on the mount (N, positive in the recoil direction); on a carriage, its CG and pitch
(``carriage x [m]``, ``carriage y [m]``, ``carriage pitch [rad]``) and each support's normal and tangential force
(N) and height (m); the histories elements declare
(``<element> <name> [<unit>]``, :mod:`mbs_models.elements.declaration`); the energies (J): kinetic per body,
stored and dissipated per connector, the work of every external input, their totals and the
energy-balance error (:meth:`Result.energy_error`).

Rows: by default the densified histories (:mod:`mbs_models.results.dense`: the step-end samples and, in every
step longer than 1 ms, times no more than 1 ms apart on the interpolant and the laws); ``interval`` (s) sets that
gap, ``step_ends=True`` writes the solver's step-end samples alone (``recoil run --history-interval S``,
``--step-ends``).  The columns are the same either way.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ..outputs import atomic_write_text
from . import element_outputs
from .dense import output_histories
from .result import Result


def history_columns(result: Result) -> dict[str, np.ndarray]:
    """The table's columns in order: ``{"<what> [<unit>]": values at result.time}`` (module docstring), of the
    Result as it is (a densified one's rows are dense)."""
    columns: dict[str, np.ndarray] = {"time [s]": result.time}
    for name in result.positions:
        columns[f"{name} position [m]"] = result.positions[name]
        columns[f"{name} velocity [m/s]"] = result.velocities[name]
        columns[f"{name} acceleration [m/s^2]"] = result.accelerations[name]
    for contact in result.contacts.values():
        columns[f"{contact.name} force [N]"] = contact.force
    columns["support force [N]"] = result.support_force
    if result.carriage is not None:  # the planar model: the carriage and its ground reactions
        columns["carriage x [m]"] = result.carriage.position[:, 0]
        columns["carriage y [m]"] = result.carriage.position[:, 1]
        columns["carriage pitch [rad]"] = result.carriage.pitch
        for name, support in result.carriage.supports.items():
            columns[f"{name} normal force [N]"] = support.normal_force
            columns[f"{name} tangential force [N]"] = support.tangential_force
            columns[f"{name} height [m]"] = support.height
    for element, _table, outputs in element_outputs.declared(result.scene):
        for history in outputs.histories:
            columns[f"{element} {history.name} [{history.unit}]"] = result.element_histories[element][history.name]
    for name, history in result.kinetic_energy_histories.items():
        columns[f"{name} kinetic energy [J]"] = history
    for name, history in result.stored_energy_histories.items():
        columns[f"{name} stored energy [J]"] = history
    for name, history in result.dissipated_energy_history.items():
        columns[f"{name} dissipated energy [J]"] = history
    for name, history in result.work_histories.items():
        columns[f"{name} work [J]"] = history
    columns["kinetic energy [J]"] = result.kinetic_energy_history
    columns["stored energy [J]"] = result.stored_energy_history
    columns["dissipated energy [J]"] = sum(result.dissipated_energy_history.values(), np.zeros_like(result.time))
    if result.work_histories:
        columns["work [J]"] = result.work_history
    columns["energy balance error [J]"] = result.energy_error()
    n = len(result.time)
    for name, values in columns.items():
        if np.shape(values) != (n,):
            raise ValueError(f"history {name!r} has shape {np.shape(values)}, not ({n},)")
    return columns


def histories_csv(result: Result, interval: float | None = None, step_ends: bool = False) -> str:
    """The table as CSV text: a header row of column names with units, then one row per output time -- the
    densified histories' at ``interval`` (s; None: the default), the step-end samples' with ``step_ends`` (module
    docstring) -- (numbers written exactly: Python's shortest round-trip representation)."""
    columns = history_columns(output_histories(result, interval, step_ends))
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    writer.writerows(np.column_stack([np.asarray(v, dtype=float) for v in columns.values()]).tolist())
    return buffer.getvalue()


def write_histories_csv(result: Result, path: str | Path, interval: float | None = None,
                        step_ends: bool = False) -> Path:
    """Write :func:`histories_csv` (``interval`` s, ``step_ends``) to ``path`` atomically (temporary name, then
    rename)."""
    return atomic_write_text(path, histories_csv(result, interval, step_ends))
