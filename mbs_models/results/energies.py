"""Energy histories of a solve: kinetic per body, stored and dissipated per connector, work per input.

Dissipated energies and the work of time-varying loads are integrated with 3-point Gauss-Legendre
quadrature in every sample interval, on the Hermite-interpolated state at the nodes
(``t_i + f h_i``, f = 1/2 -+ sqrt(15)/10 and 1/2, weights 5/18, 8/18, 5/18), then summed cumulatively.
Values at the nodes are arrays of shape (nodes, intervals): one row per node, the intervals innermost
(long inner loops for every operation on them, the quadrature's sum over nodes included).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .samples import Interpolant, Samples

# Gauss-Legendre nodes and weights on [0, 1], 3 points (exact for degree-5 polynomials).
_GL_NODES = 0.5 + 0.5 * np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
_GL_WEIGHTS = np.array([5.0, 8.0, 5.0]) / 18.0


def cumulative_quadrature(t: np.ndarray, power_at_nodes: np.ndarray, steps: np.ndarray | None = None) -> np.ndarray:
    """Cumulative integral (J) over the sample intervals from the power (W) at each interval's Gauss nodes
    (shape (nodes, intervals)): ``E_k = sum_{i<k} h_i sum_j w_j P(t_i + f_j h_i)``; ``steps``: the intervals'
    lengths h_i = ``np.diff(t)`` (s), if already at hand."""
    per_interval = (power_at_nodes * _GL_WEIGHTS[:, None]).sum(axis=0) * (np.diff(t) if steps is None else steps)
    return np.concatenate([[0.0], np.cumsum(per_interval)])


@dataclass
class Energies:
    """Energy histories at the samples (J): kinetic per body, stored and dissipated per connector, and the
    work done on the mechanism by each external input (a load by its name, the shots of a burst by
    their element's name).  ``kinetic + stored + dissipated - work`` stays the initial energy."""

    kinetic: dict[str, np.ndarray]
    stored: dict[str, np.ndarray]
    dissipated: dict[str, np.ndarray]
    work: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def kinetic_total(self) -> np.ndarray:
        return _sum(self.kinetic.values())

    @property
    def stored_total(self) -> np.ndarray:
        return _sum(self.stored.values())


def _sum(arrays) -> np.ndarray | None:
    total = None
    for array in arrays:
        total = array if total is None else total + array
    return total


def energies(mechanism, s: Samples, interp: Interpolant) -> Energies:
    """Kinetic energy per body, stored and dissipated energy per connector, in J at the samples.

    Dissipated energies are integrated with 3-point Gauss quadrature on the Hermite-interpolated state
    in every step (each connector's own :meth:`~mbs_models.elements.connector.Connector.dissipated_energy`:
    ``c d'^2`` for a damper, ``F p' - dU/dt`` for a contact).
    """
    t = s.time
    steps = np.diff(t)
    nodes_t = t[:-1] + _GL_NODES[:, None] * steps
    x_nodes, v_nodes = interp.at_fractions(_GL_NODES)
    kinetic = {body.name: 0.5 * body.mass * s.velocities[body.name] ** 2 for body in mechanism.bodies}
    stored: dict[str, np.ndarray] = {}
    dissipated: dict[str, np.ndarray] = {}

    def quadrature(power):
        return cumulative_quadrature(t, power, steps)

    for connector in mechanism.connectors:
        samples = None
        if connector.stores_energy:
            samples = connector.stored_energy(mechanism.relative(connector, s.positions))
            stored[connector.name] = samples
        if connector.dissipates:
            dissipated[connector.name] = connector.dissipated_energy(
                quadrature, mechanism.relative(connector, x_nodes), mechanism.relative(connector, v_nodes),
                nodes_t, samples)
    work: dict[str, np.ndarray] = {}
    for load in mechanism.loads:
        work[load.name] = load.work(quadrature, s.positions[load.body], v_nodes[load.body], nodes_t)
    for t_shot, body, _ in mechanism.impulses:
        jump = np.flatnonzero((t[:-1] == t_shot) & (t[1:] == t_shot))
        if not len(jump):
            continue  # after the end of the window (an early stop)
        j = int(jump[0]) + 1  # the sample after the velocity jump
        mass = mechanism.bodies[mechanism.body_index[body]].mass
        gain = 0.5 * mass * (s.velocities[body][j] ** 2 - s.velocities[body][j - 1] ** 2)
        name = mechanism.impulse_element[(t_shot, body)]
        history = work.setdefault(name, np.zeros_like(t))
        history[j:] += gain
    return Energies(kinetic, stored, dissipated, work)
