"""The step-end samples of a solve and their Hermite interpolation between samples.

Positions are interpolated from velocities and velocities from accelerations (cubic Hermite,
:mod:`mbs_models.results.hermite`); every body's state comes from one interval search and one set of
basis polynomials.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .hermite import HermiteStack, HermiteTrajectory


@dataclass
class Samples:
    """Step-end samples of one solve: time (s), per body position/velocity/acceleration (m, m/s, m/s^2),
    and the force (N) each recording connector (the contacts) had at each step end."""

    time: np.ndarray
    positions: dict[str, np.ndarray]
    velocities: dict[str, np.ndarray]
    accelerations: dict[str, np.ndarray]
    forces: dict[str, np.ndarray] = field(default_factory=dict)
    #: A carriage scene's other histories (:mod:`mbs_models.engine.planar`): ``carriage_x_position`` ... and each
    #: support's connector force ``support_NAME_connector_x``/``_y`` (N); empty otherwise.
    planar: dict[str, np.ndarray] = field(default_factory=dict)


class Interpolant:
    """Hermite interpolation of every body's state between samples.

    ``x[name]``, ``v[name]``: one body's position and velocity; :meth:`state` and :meth:`at_fractions`
    give every body's at once (one interval search and one set of basis polynomials for all; the same
    values as the single trajectories, bit for bit).
    """

    def __init__(self, s: Samples):
        self.time = s.time
        self.names = list(s.positions)
        self._samples = s
        self._stack = HermiteStack.chain(s.time, [[s.positions[n] for n in self.names],
                                                  [s.velocities[n] for n in self.names],
                                                  [s.accelerations[n] for n in self.names]])

    @cached_property
    def x(self) -> dict[str, HermiteTrajectory]:
        """Each body's position (m) interpolated from its velocity."""
        s = self._samples
        return {name: HermiteTrajectory(s.time, s.positions[name], s.velocities[name]) for name in self.names}

    @cached_property
    def v(self) -> dict[str, HermiteTrajectory]:
        """Each body's velocity (m/s) interpolated from its acceleration."""
        s = self._samples
        return {name: HermiteTrajectory(s.time, s.velocities[name], s.accelerations[name]) for name in self.names}

    def _split(self, values) -> tuple[dict, dict]:
        n = len(self.names)
        return ({name: values[i] for i, name in enumerate(self.names)},
                {name: values[n + i] for i, name in enumerate(self.names)})

    def state(self, t, bodies=None) -> tuple[dict, dict]:
        """Every body's position (m) and velocity (m/s) at times ``t`` (s, any shape); with ``bodies`` (names),
        only theirs (the same floats, at the cost of those bodies alone)."""
        if bodies is None:
            return self._split(self._stack(t))
        index = [self.names.index(name) for name in bodies]
        values = self._stack(t, index + [len(self.names) + k for k in index])
        return ({name: values[j] for j, name in enumerate(bodies)},
                {name: values[len(index) + j] for j, name in enumerate(bodies)})

    def accelerations(self, t) -> dict:
        """Every body's acceleration (m/s^2) at times ``t`` (s, any shape): the derivative of its velocity's
        interpolant (:meth:`~mbs_models.results.hermite.HermiteStack.derivative`; the sample at a sample time)."""
        n = len(self.names)
        values = self._stack.derivative(t, list(range(n, 2 * n)))
        return {name: values[i] for i, name in enumerate(self.names)}

    def at_fractions(self, fractions) -> tuple[dict, dict]:
        """Every body's position and velocity at ``t_i + f h_i``, shape (fractions, intervals) each."""
        return self._split(self._stack.at_fractions(fractions))

    def positions(self, t) -> dict:
        return self.state(t)[0]

    def velocities(self, t) -> dict:
        return self.state(t)[1]
