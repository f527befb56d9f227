"""What a simulation returns: :class:`Result` (time histories + metrics) and :class:`Impact`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .accuracy import SolverSettings
from .final_metrics import FINAL_METRICS
from .scene import Scene


@dataclass(frozen=True)
class Impact:
    """One contact episode between wall A and the absorber whose peak force exceeds the threshold.

    Attributes: ``start`` and ``end`` (s) bound the interval where the contact force is > 0;
    ``peak_force`` (N) is its maximum, reached at ``time_of_peak_force`` (s).
    """

    start: float
    end: float
    peak_force: float
    time_of_peak_force: float

    @property
    def duration(self) -> float:
        """Contact duration in s."""
        return self.end - self.start

    def to_dict(self) -> dict[str, float]:
        return {"start": self.start, "end": self.end, "peak_force": self.peak_force,
                "time_of_peak_force": self.time_of_peak_force}


@dataclass
class Result:
    """Time histories (numpy arrays at the solver's output steps, SI units) and metrics of one run.

    Absorber and contact quantities are ``None`` for a scene without an absorber (the simplified
    model), never zeros.  Metrics are refined between output samples (see :mod:`mbs_models.peaks`).

    Time histories: ``time`` (s); ``barrel_position`` x_M (m), ``barrel_velocity`` (m/s),
    ``barrel_acceleration`` (m/s^2); the same for the absorber x_m; ``contact_force`` F_ct (N, >= 0).

    Metrics: ``max_barrel_displacement`` (m, Table 2) and its time (s); ``peak_contact_force`` (N)
    and its time; ``max_absorber_velocity`` (m/s, Section 2.2) and its time; ``impacts``;
    ``dissipated_energy`` (J, per dissipative element, at the end time).

    Window: the histories cover ``[0, end_time]`` s.  ``requested_end_time`` is what was asked for;
    ``end_time`` is smaller only when ``simulate(..., stop_when_final=...)`` stopped the solve because
    the named metrics were proven final (``stop_reason == "metrics_final"``, see
    :mod:`mbs_models.final_metrics`).  ``final_metrics`` names the metrics whose values are those of
    a run to ``requested_end_time``; every other metric (with its time) is None -- ``impacts`` too.
    """

    scene: Scene
    settings: SolverSettings
    end_time: float
    time: np.ndarray
    barrel_position: np.ndarray
    barrel_velocity: np.ndarray
    barrel_acceleration: np.ndarray
    absorber_position: np.ndarray | None
    absorber_velocity: np.ndarray | None
    absorber_acceleration: np.ndarray | None
    contact_force: np.ndarray | None
    max_barrel_displacement: float | None
    time_of_max_barrel_displacement: float | None
    peak_contact_force: float | None
    time_of_peak_contact_force: float | None
    max_absorber_velocity: float | None
    time_of_max_absorber_velocity: float | None
    impacts: list[Impact] | None
    impact_threshold: float
    dissipated_energy: dict[str, float]
    dissipated_energy_history: dict[str, np.ndarray] = field(repr=False, default_factory=dict)
    stored_energy_history: np.ndarray | None = field(repr=False, default=None)
    kinetic_energy_history: np.ndarray | None = field(repr=False, default=None)
    wall_time: float = 0.0
    timings: dict[str, float] = field(default_factory=dict)
    steps: int = 0
    requested_end_time: float | None = None
    stop_reason: str = "end_time"
    final_metrics: tuple[str, ...] = FINAL_METRICS

    def __post_init__(self):
        if self.requested_end_time is None:
            self.requested_end_time = self.end_time

    @property
    def total_dissipated_energy(self) -> float:
        """Energy dissipated by all dampers and the contact up to the end time, in J."""
        return float(sum(self.dissipated_energy.values()))

    def energy_error(self) -> np.ndarray:
        """Energy balance residual over time, in J: kinetic + stored + dissipated - initial energy.

        The initial energy is the kinetic energy at t = 0 plus the elastic contact energy of an initial
        interference (``literal_gap_sign``).  Zero for an exact solution; its size measures the
        integration (and quadrature) error.
        """
        dissipated = sum(self.dissipated_energy_history.values())
        initial = self.kinetic_energy_history[0] + self.stored_energy_history[0]
        return self.kinetic_energy_history + self.stored_energy_history + dissipated - initial

    def metrics(self) -> dict[str, Any]:
        """The scalar results as a JSON-ready dict (keys of DESIGN.md's ``recoil run --json``)."""
        return {
            "scene": self.scene.name,
            "model": self.scene.model_label,
            "initial_velocity": self.scene.initial_velocity,
            "end_time": self.end_time,
            "requested_end_time": self.requested_end_time,
            "stop_reason": self.stop_reason,
            "final_metrics": list(self.final_metrics),
            "solver": self.settings.label(),
            "max_barrel_displacement": self.max_barrel_displacement,
            "time_of_max_barrel_displacement": self.time_of_max_barrel_displacement,
            "peak_contact_force": self.peak_contact_force,
            "time_of_peak_contact_force": self.time_of_peak_contact_force,
            "max_absorber_velocity": self.max_absorber_velocity,
            "time_of_max_absorber_velocity": self.time_of_max_absorber_velocity,
            "impact_threshold": self.impact_threshold,
            "impacts": None if self.impacts is None else [impact.to_dict() for impact in self.impacts],
            "dissipated_energy": dict(self.dissipated_energy),
            "steps": self.steps,
            "wall_time": self.wall_time,
        }

    def summary(self) -> str:
        """A few human-readable lines."""
        window = f"{self.end_time:g} s"
        if self.stop_reason != "end_time":
            window += f" of {self.requested_end_time:g} s requested ({self.stop_reason.replace('_', ' ')})"
        lines = [f"{self.scene.name} ({self.scene.model_label}), {window}, {self.settings.label()}"]
        not_final = "not proven final (run stopped early)"
        if self.max_barrel_displacement is not None:
            lines.append(f"  max barrel displacement  {self.max_barrel_displacement:.6f} m at "
                         f"{self.time_of_max_barrel_displacement:.5f} s")
        else:
            lines.append(f"  max barrel displacement  {not_final}")
        if self.scene.absorber is not None:
            if self.peak_contact_force is None:
                lines.append(f"  peak contact force       {not_final}")
            elif self.time_of_peak_contact_force is None:
                lines.append("  peak contact force       0 (no contact)")
            else:
                lines.append(f"  peak contact force       {self.peak_contact_force / 1e3:.3f} kN at "
                             f"{self.time_of_peak_contact_force:.5f} s")
            if self.max_absorber_velocity is None:
                lines.append(f"  max absorber velocity    {not_final}")
            else:
                lines.append(f"  max absorber velocity    {self.max_absorber_velocity:.5f} m/s at "
                             f"{self.time_of_max_absorber_velocity:.5f} s")
            impacts = not_final if self.impacts is None else len(self.impacts)
            lines.append(f"  impacts (> {self.impact_threshold / 1e3:g} kN)      {impacts}")
        lines.append(f"  energy dissipated        {self.total_dissipated_energy:.2f} J of "
                     f"{self.scene.initial_kinetic_energy:.2f} J")
        lines.append(f"  wall time                {self.wall_time * 1e3:.1f} ms ({self.steps} steps)")
        return "\n".join(lines)
