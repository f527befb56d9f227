"""The construction of a :class:`~mbs_models.results.result.Result`, once, from a :class:`RunRecord`.

The driver (:mod:`mbs_models.engine.driver`) solves, the run policy (:mod:`mbs_models.engine.run_policy`) says why
the run ended and which metrics are final; :class:`RunRecord` holds all of it, and :func:`build_result` turns it
into the (immutable) Result: the post-processing (:func:`~mbs_models.results.postprocess.analyse`), the version-1
metrics over all absorbers, the checks of the solution (no non-finite metric; the energy balance,
:func:`~mbs_models.engine.stability.check_energy_balance`), and every metric not proven final set to None.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, replace

import numpy as np

from ..errors import SimulationError
from ..results import element_outputs
from ..results.postprocess import Samples, analyse
from ..results.result import ContactOutput, Result, total_history
from ..scene import Scene
from ..stop_reason import StopReason
from . import stability
from .accuracy import SolverSettings
from .mechanism import Mechanism

#: The version-1 metrics checked for non-finite values before a Result is built.
CHECKED_METRICS = ("max_barrel_displacement", "max_absorber_velocity", "peak_contact_force", "peak_support_force")


@dataclass(frozen=True)
class RunRecord:
    """Everything a run collected and decided, from which its Result is built.

    ``samples``: the histories (up to ``end_time``; a run at rest holds its rest state to it); ``end_time`` (s) the
    window's end, ``requested_end_time`` (s) the one asked for (larger only after an early stop); ``stop_reason``,
    ``final_metrics`` (the metrics whose values are those of a run to the requested end time), ``rest_time`` (s)
    and ``rest_tolerance`` (m and m/s) at rest (else None); ``steps``: Exudyn's; ``wall_started``, ``started``,
    ``assembled``, ``solved``: ``time.perf_counter()`` (s) at the call's start, this solve's start, once assembled,
    once solved.
    """

    scene: Scene
    settings: SolverSettings
    mechanism: Mechanism
    samples: Samples
    impact_threshold: float
    requested_end_time: float
    end_time: float
    stop_reason: StopReason
    final_metrics: tuple[str, ...]
    rest_time: float | None
    rest_tolerance: float | None
    steps: int
    wall_started: float
    started: float
    assembled: float
    solved: float


def build_result(record: RunRecord) -> Result:
    """The Result of ``record``; SimulationError for a non-finite metric or an energy balance off by more than
    :mod:`~mbs_models.engine.stability` accepts (an AccuracyWarning beyond its warning level)."""
    mechanism, samples, final = record.mechanism, record.samples, record.final_metrics
    metrics = analyse(mechanism, samples, record.impact_threshold, final)  # unproven ones: not computed
    fields = _fields(mechanism, samples, metrics)
    for name in CHECKED_METRICS:
        value = fields[name]
        if value is not None and not math.isfinite(value):
            raise SimulationError(f"post-processing produced a non-finite {name.replace('_', ' ')}")
    _check_energy_balance(record, fields)
    _drop_unproven(fields, final)
    if record.stop_reason == StopReason.METRICS_FINAL:  # a shorter window: only window-wide declared metrics hold
        fields["element_metrics"] = element_outputs.unproven(fields["element_metrics"], record.scene)
    t_end = _time.perf_counter()
    return Result(scene=record.scene, settings=record.settings, end_time=record.end_time, time=samples.time,
                  impact_threshold=record.impact_threshold, requested_end_time=record.requested_end_time,
                  stop_reason=record.stop_reason, final_metrics=final, rest_time=record.rest_time,
                  rest_tolerance=record.rest_tolerance, steps=record.steps, wall_time=t_end - record.wall_started,
                  timings={"assembly": record.assembled - record.started, "solve": record.solved - record.assembled,
                           "postprocess": t_end - record.solved},
                  samples=samples, mechanism=mechanism, **fields)


def _largest(candidates) -> tuple[float | None, float | None]:
    """(value, time) with the largest value, the earliest on ties; (None, None) if there is none."""
    candidates = [c for c in candidates if c[0] is not None]
    if not candidates:
        return None, None
    return max(candidates, key=lambda c: (c[0], -(c[1] if c[1] is not None else 0.0)))


def _fields(mechanism: Mechanism, samples: Samples, metrics) -> dict:
    """The Result's histories, the version-1 metrics over all absorbers and the per-element outputs of a solve."""
    absorber_contacts = [metrics.contacts[c.name] for c in mechanism.absorber_contacts if c.name in metrics.contacts]
    has_absorbers = bool(mechanism.absorber_contacts)
    peak = time_of_peak = None
    impacts = None
    if has_absorbers and absorber_contacts:
        peak, time_of_peak = _largest((c.peak_force, c.time_of_peak_force) for c in absorber_contacts)
        if peak == 0.0:
            time_of_peak = None
        if all(c.impacts is not None for c in absorber_contacts):
            impacts = sorted((i for c in absorber_contacts for i in c.impacts), key=lambda i: i.start)
    elif not has_absorbers:
        impacts = []
    v_max, t_v = _largest(metrics.max_velocity.values()) if metrics.max_velocity else (None, None)
    energies = metrics.energies
    element_of = {body.name: body.element or body.name for body in mechanism.bodies}
    element_of.update({c.name: c.element for c in mechanism.connectors})
    element_of.update({load.name: load.element for load in mechanism.loads})
    return dict(
        positions=samples.positions, velocities=samples.velocities, accelerations=samples.accelerations,
        contacts=metrics.contacts, support_force=metrics.support_force,
        max_barrel_displacement=metrics.max_barrel_displacement,
        time_of_max_barrel_displacement=metrics.time_of_max_barrel_displacement,
        peak_contact_force=peak, time_of_peak_contact_force=time_of_peak,
        max_absorber_velocity=v_max, time_of_max_absorber_velocity=t_v, impacts=impacts,
        dissipated_energy={name: float(history[-1]) for name, history in energies.dissipated.items()},
        peak_support_force=metrics.peak_support_force, time_of_peak_support_force=metrics.time_of_peak_support_force,
        max_velocities=dict(metrics.max_velocity), dissipated_energy_history=energies.dissipated,
        stored_energy_histories=energies.stored, kinetic_energy_histories=energies.kinetic, element_of=element_of,
        work_histories=energies.work, element_histories=metrics.element_histories,
        element_metrics=metrics.element_metrics, carriage=metrics.carriage)


def _check_energy_balance(record: RunRecord, fields: dict) -> None:
    """:func:`~mbs_models.engine.stability.check_energy_balance` of the solve: kinetic + stored + dissipated - work
    - initial energy (J) over time, against the mechanism's energy scale plus the largest |work| (J)."""
    time, mechanism = record.samples.time, record.mechanism
    initial, scale = mechanism.initial_energy_and_scale()
    if fields["carriage"] is not None:  # the supports' static penetrations store energy at t = 0 (gravity's: 0)
        supports = [h[0] for name, h in fields["stored_energy_histories"].items() if name.startswith("support.")]
        initial += sum(supports)
        scale += sum(abs(u) for u in supports)
    energy_error = (total_history(fields["kinetic_energy_histories"].values(), time)
                    + total_history(fields["stored_energy_histories"].values(), time)
                    + sum(fields["dissipated_energy_history"].values()) - initial)
    if fields["work_histories"]:
        work = total_history(fields["work_histories"].values(), time)
        energy_error = energy_error - work
        scale += float(np.max(np.abs(work)))
    stability.check_energy_balance(record.scene, time, energy_error, f"Exudyn {record.settings.label()}", scale)


def _drop_unproven(fields: dict, final: tuple[str, ...]) -> None:
    """Set every metric not proven final (and its time) to None in ``fields``: a shorter window's value is no
    result.  The contacts' outputs are replaced by copies without them (the post-processing's are not changed)."""
    contact_changes: dict = {}
    if "max_barrel_displacement" not in final:
        fields.update(max_barrel_displacement=None, time_of_max_barrel_displacement=None)
    if "peak_contact_force" not in final:
        fields.update(peak_contact_force=None, time_of_peak_contact_force=None)
        contact_changes.update(peak_force=None, time_of_peak_force=None)
    if "max_absorber_velocity" not in final:
        fields.update(max_absorber_velocity=None, time_of_max_absorber_velocity=None,
                      max_velocities={name: (None, None) for name in fields["max_velocities"]})
    if "impacts" not in final:
        fields["impacts"] = None
        contact_changes["impacts"] = None
    if "peak_support_force" not in final:
        fields.update(peak_support_force=None, time_of_peak_support_force=None)
    if contact_changes:
        contacts: dict[str, ContactOutput] = fields["contacts"]
        fields["contacts"] = {name: replace(output, **contact_changes) for name, output in contacts.items()}
