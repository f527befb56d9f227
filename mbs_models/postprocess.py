"""From sampled states to metrics: refined extrema, the list of impacts, and the energy balance.

Everything here works on the step-end samples of a solve (any solver) and needs no Exudyn.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import forces
from .final_metrics import FINAL_METRICS
from .peaks import HermiteTrajectory, refine_crossing, refine_function_maximum, refine_maximum, runs_of_true
from .result import Impact
from .scene import Scene

# Gauss-Legendre nodes and weights on [0, 1], 3 points (exact for degree-5 polynomials).
_GL_NODES = 0.5 + 0.5 * np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
_GL_WEIGHTS = np.array([5.0, 8.0, 5.0]) / 18.0


@dataclass
class Samples:
    """Step-end samples of one solve: time (s), and per body position/velocity/acceleration."""

    time: np.ndarray
    barrel_position: np.ndarray
    barrel_velocity: np.ndarray
    barrel_acceleration: np.ndarray
    absorber_position: np.ndarray | None = None
    absorber_velocity: np.ndarray | None = None
    absorber_acceleration: np.ndarray | None = None


class _Interpolant:
    """Hermite interpolation of the full state between samples."""

    def __init__(self, s: Samples):
        self.barrel_x = HermiteTrajectory(s.time, s.barrel_position, s.barrel_velocity)
        self.barrel_v = HermiteTrajectory(s.time, s.barrel_velocity, s.barrel_acceleration)
        if s.absorber_position is not None:
            self.absorber_x = HermiteTrajectory(s.time, s.absorber_position, s.absorber_velocity)
            self.absorber_v = HermiteTrajectory(s.time, s.absorber_velocity, s.absorber_acceleration)


def contact_force_at(scene: Scene, interp: _Interpolant, t):
    """Contact force (N) evaluated on the interpolated state at times ``t``."""
    relative_position = interp.barrel_x(t) - interp.absorber_x(t)
    relative_velocity = interp.barrel_v(t) - interp.absorber_v(t)
    return forces.hunt_crossley_force(relative_position, relative_velocity, scene.contact, scene.conventions,
                                      forces.NUMPY_OPS)


def find_impacts(scene: Scene, s: Samples, contact_force: np.ndarray, interp: _Interpolant,
                 threshold: float) -> list[Impact]:
    """Contact episodes (maximal intervals with force > 0) whose peak exceeds ``threshold`` (N)."""
    t = s.time
    impacts: list[Impact] = []

    def force_positive(times: np.ndarray) -> np.ndarray:
        return contact_force_at(scene, interp, times) > 0.0

    for i0, i1 in runs_of_true(contact_force > 0.0):
        k = i0 + int(np.argmax(contact_force[i0:i1 + 1]))
        peak, t_peak = refine_function_maximum(lambda x: contact_force_at(scene, interp, x), t, k)
        peak = max(peak, float(contact_force[k]))
        if peak <= threshold:
            continue
        start = t[i0] if i0 == 0 else refine_crossing(force_positive, t[i0 - 1], t[i0])
        end = t[i1] if i1 == len(t) - 1 else refine_crossing(lambda x: ~force_positive(x), t[i1], t[i1 + 1])
        impacts.append(Impact(start=float(start), end=float(end), peak_force=float(peak),
                              time_of_peak_force=float(t_peak)))
    return impacts


def _cumulative_quadrature(t: np.ndarray, power_at_nodes: np.ndarray) -> np.ndarray:
    """Cumulative integral over the sample intervals from the power at each interval's Gauss nodes."""
    per_interval = (power_at_nodes * _GL_WEIGHTS[None, :]).sum(axis=1) * np.diff(t)
    return np.concatenate([[0.0], np.cumsum(per_interval)])


def energies(scene: Scene, s: Samples, interp: _Interpolant) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]:
    """Dissipated energy histories per element, stored (spring + contact) energy and kinetic energy, in J.

    Dissipated powers, integrated with 3-point Gauss quadrature on the Hermite-interpolated state
    in every step: recoil damper ``c(v) v^2``; absorber damper ``c_r v_rel^2``; contact
    ``F p_dot - d/dt(k_c p^(n+1)/(n+1))`` (the part of the contact work not stored elastically).
    """
    t = s.time
    dissipated: dict[str, np.ndarray] = {}
    damper = scene.recoil_damper
    barrel_v = interp.barrel_v.on_intervals(_GL_NODES)
    if damper.recoil > 0 or damper.counter_recoil > 0:
        power = forces.recoil_damper_force(barrel_v, damper, forces.NUMPY_OPS) * barrel_v
        dissipated["recoil_damper"] = _cumulative_quadrature(t, power)
    kinetic = 0.5 * scene.barrel.mass * s.barrel_velocity ** 2
    stored = 0.5 * scene.recoil_spring.stiffness * s.barrel_position ** 2
    absorber = scene.absorber
    if absorber is not None:
        mounted_on_barrel = absorber.mount == "barrel"

        def absorber_relative(barrel_value, absorber_value):
            return (barrel_value - absorber_value) if mounted_on_barrel else absorber_value

        absorber_v = interp.absorber_v.on_intervals(_GL_NODES)
        if absorber.damping > 0:
            power = absorber.damping * absorber_relative(barrel_v, absorber_v) ** 2
            dissipated["absorber_damper"] = _cumulative_quadrature(t, power)
        relative_velocity = barrel_v - absorber_v
        relative_position_nodes = interp.barrel_x.on_intervals(_GL_NODES) - interp.absorber_x.on_intervals(_GL_NODES)
        force = forces.hunt_crossley_force(relative_position_nodes, relative_velocity, scene.contact,
                                           scene.conventions, forces.NUMPY_OPS)
        relative_position = s.barrel_position - s.absorber_position
        elastic = forces.contact_elastic_energy(relative_position, scene.contact, scene.conventions)
        dissipated["contact"] = _cumulative_quadrature(t, force * relative_velocity) - (elastic - elastic[0])
        kinetic = kinetic + 0.5 * absorber.mass * s.absorber_velocity ** 2
        spring_extension = absorber_relative(s.barrel_position, s.absorber_position)
        stored = stored + 0.5 * absorber.stiffness * spring_extension ** 2 + elastic
    return dissipated, stored, kinetic


@dataclass
class Metrics:
    """All scalar results of one solve (see :class:`~mbs_models.result.Result`)."""

    max_barrel_displacement: float | None
    time_of_max_barrel_displacement: float | None
    peak_contact_force: float | None = None
    time_of_peak_contact_force: float | None = None
    max_absorber_velocity: float | None = None
    time_of_max_absorber_velocity: float | None = None
    impacts: list[Impact] | None = None
    dissipated_energy_history: dict[str, np.ndarray] | None = None
    stored_energy_history: np.ndarray | None = None
    kinetic_energy_history: np.ndarray | None = None


def analyse(scene: Scene, s: Samples, contact_force: np.ndarray | None, impact_threshold: float,
            wanted: tuple[str, ...] = FINAL_METRICS) -> Metrics:
    """Compute the metrics of a solve from its samples: those in ``wanted``, and always the energies.

    Metrics left out are None (the contact force peak and the impacts share one search: asking for
    either computes both).
    """
    interp = _Interpolant(s)
    metrics = Metrics(max_barrel_displacement=None, time_of_max_barrel_displacement=None)
    if "max_barrel_displacement" in wanted:
        metrics.max_barrel_displacement, metrics.time_of_max_barrel_displacement = refine_maximum(
            s.time, s.barrel_position, s.barrel_velocity)
    if scene.absorber is None:
        metrics.impacts = []
    else:
        if "max_absorber_velocity" in wanted:
            v_max, t_v = refine_maximum(s.time, s.absorber_velocity, s.absorber_acceleration)
            metrics.max_absorber_velocity, metrics.time_of_max_absorber_velocity = v_max, t_v
        if "impacts" in wanted or "peak_contact_force" in wanted:
            _contact_metrics(scene, s, contact_force, interp, impact_threshold, metrics)
    (metrics.dissipated_energy_history, metrics.stored_energy_history,
     metrics.kinetic_energy_history) = energies(scene, s, interp)
    return metrics


def _contact_metrics(scene: Scene, s: Samples, contact_force: np.ndarray, interp: _Interpolant,
                     impact_threshold: float, metrics: Metrics) -> None:
    """The impacts and the refined peak contact force, into ``metrics``."""
    metrics.impacts = find_impacts(scene, s, contact_force, interp, impact_threshold)
    k = int(np.argmax(contact_force))
    if metrics.impacts and max(i.peak_force for i in metrics.impacts) >= contact_force[k]:
        strongest = max(metrics.impacts, key=lambda i: i.peak_force)  # already refined
        metrics.peak_contact_force, metrics.time_of_peak_contact_force = (strongest.peak_force,
                                                                          strongest.time_of_peak_force)
    elif contact_force[k] > 0:
        peak, t_peak = refine_function_maximum(lambda x: contact_force_at(scene, interp, x), s.time, k)
        metrics.peak_contact_force, metrics.time_of_peak_contact_force = max(peak, float(contact_force[k])), t_peak
    else:
        metrics.peak_contact_force, metrics.time_of_peak_contact_force = 0.0, None  # no contact at all
