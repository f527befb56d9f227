"""Stop a solve at rest: prove that a dissipative scene stays within a tolerance of its rest state for ever.

A paper case comes to rest within a minute of simulated time; a run to 10,000 s would spend almost all its
time and memory integrating a mechanism at rest.  :func:`mbs_models.simulate` asks a :class:`RestWatch`
after each chunk of a long solve whether energy bounds prove that from some output sample ``t_r`` on every
body stays within ``tolerance`` (m) of its rest position and every velocity within ``tolerance`` (m/s),
for all later time.  Once proven, the solve stops; the Result holds the rest state from ``t_r`` to the
requested end time (``stop_reason == "at_rest"``; DESIGN.md, "Stop at rest").

The rest state
--------------
Velocities 0; positions ``x*`` with ``K x* = 0`` (every linear spring at ``d = 0``; K is the quadratic form of
:mod:`mbs_models.engine.energy_bounds`) and, with a potential well on body b (a recuperator against its
battery stop), ``x*_b = x_r``, the well's computed minimum; every contact outside the well open there
(``p <= 0``).  Without a well ``x* = 0``.  With a well, ``x* = x_r P e_b / |P e_b|^2`` (P: the projection on
K's null space): bodies tied to b by springs rest where b does.

The proof
---------
After the last input the mechanical energy E of a dissipative scene never increases
(:mod:`mbs_models.engine.energy_bounds`).  Split ``E = N + W(x_b)``: N (J) sums the kinetic energies, the
springs' ``k d^2 / 2`` and the contacts' elastic energies outside the well, every term >= 0; W is the well's
convex potential (W = 0 without one).  ``Q = E - W(x_r) = N + G(x_b)`` with ``G = W - W(x_r)`` never
increases either, so for every ``t >= t_r``, with ``gamma = W(x_r) - min W >= 0`` (``x_r`` is the minimum
only to round-off; gamma bounds the difference), ``N(t) <= Q(t_r) + gamma`` and ``G(x_b(t)) <= Q(t_r)``.
:meth:`RestState.energy_bound` bounds ``Q(t_r) + gamma`` by ``E_up``, computed without cancellation: N as its
sum of non-negative terms, and ``G(x) <= (x - x_r) W'(x)`` (convexity) with the round-off of W'.  Then for
every later time:

* ``|v_i| <= sqrt(2 E_up / m_i)`` (each kinetic energy is part of N);
* ``x^T K x <= 2 E_up``, so for body i, written ``e_i = u_i + alpha_i e_b`` with ``u_i`` in the range of K,
  ``|x_i - x*_i| <= sqrt(2 u_i^T K^+ u_i E_up) + |alpha_i| |x_b - x_r|`` (``alpha_i = 0`` without a well);
* ``|x_b - x_r| <= delta`` once ``E_up < L(delta)``: W is convex, so G at ``x_r +- delta`` is at least the
  lower Riemann sum of ``+-W'`` over ``[x_r, x_r +- delta]`` (``RIEMANN_PIECES`` pieces, each value less its
  round-off), L the smaller of the two sides.

:attr:`RestState.threshold` is the largest energy for which all of these are within ``tolerance`` (a body
with both terms gets half the tolerance for each); rest is proven at a sample where
``E_up (1 + ENERGY_SLACK) < threshold``.  The proof is about the scene's equations continued from the
computed state at ``t_r``: it needs no assumption on the integration error before ``t_r``, which is the
solver's.  Since ``x*`` is within ``tolerance`` of the solution at every later time, the held state is.

No rest stop (the solve runs to its end time) where none can be proven: a scene that injects energy or has a
load that never ends (:func:`~mbs_models.engine.energy_bounds.dissipative` is False); a connector that
:attr:`~mbs_models.elements.connector.Connector.sticks` (Coulomb friction: no single rest position); a body
no spring holds (a free absorber); a well whose body is held by a linear spring too (its rest is not the
well's minimum, so ``E - W(x_r)`` never falls below the threshold); a contact closed at ``x*`` outside the
well (an initial interference).  A scene that is damped too weakly (an undamped one, or a quadratic brake
alone, whose energy decays algebraically) never reaches the threshold: its histories grow with the end time.

When
----
A run no longer than :data:`CHECK_INTERVAL` is integrated in full, exactly as before.  A longer one is
solved in chunks ending at every multiple of :data:`CHECK_INTERVAL` after the last input (a restart of the
solver there, as at a shot); after each chunk ending before the end time, its last sample is checked,
and if it proves rest, the chunk's first sample that does (bisection over the samples after the last input)
is the rest time: the samples after it are dropped.  At most one chunk is integrated beyond rest, so a
run's time and memory stop growing with its end time once it rests.  Only adaptive solvers (a fixed-step
solve's output is thinned to a bounded number of samples anyway).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..results.samples import Samples
from .energy_bounds import ENERGY_SLACK, EnergyBounds, _QuadraticForm, connector_ends, dissipative
from .mechanism import Mechanism

#: Simulated time (s) of a chunk between rest checks; runs no longer than this are never stopped at rest.
#: Ten of the paper's 10-s windows: a paper case rests after ~35 s (standard preset), its 100 s cost ~0.1 s
#: and ~20,000 samples, and every recorded run (at most 100 s) is integrated as before.
CHECK_INTERVAL = 100.0
#: Pieces of the lower Riemann sums of a potential well's slope (:func:`well_energy`).
RIEMANN_PIECES = 16
#: Round-off (relative to the sum of the magnitudes of its terms) allowed on a sum of forces: a few flops
#: per term (a power, a quotient), with a margin.
ROUNDING = 16.0 * float(np.finfo(float).eps)
#: A null-space component below this (of unit vectors) counts as zero.
_NULL_TOLERANCE = 1e-9


class RestState:
    """The rest state of one scene and the energy bound that proves it reached (module docstring).

    Attributes: ``positions`` (m, body order: x*), ``tolerance`` (m and m/s), ``threshold`` (J).  Build it with
    :meth:`of`, which returns None for a scene whose rest cannot be proven.
    """

    def __init__(self, mechanism: Mechanism, tolerance: float, positions, threshold: float, well=None,
                 rest_well_position: float = 0.0, gamma: float = 0.0):
        self.mechanism = mechanism
        self.tolerance = float(tolerance)
        self.positions = tuple(float(x) for x in positions)
        self.threshold = float(threshold)
        self.well = well
        self._x_r, self._gamma = float(rest_well_position), float(gamma)
        self._kinetic = tuple((i, 0.5 * body.mass) for i, body in enumerate(mechanism.bodies))
        self._springs = tuple(connector_ends(mechanism, c) + (0.5 * c.quadratic_stiffness,)
                              for c in mechanism.connectors
                              if c.quadratic_potential and not c.is_contact and c.quadratic_stiffness > 0)
        self._elastic = tuple(connector_ends(mechanism, c) + (c.python_elastic,) for c in mechanism.contacts
                              if well is None or c not in well)

    @classmethod
    def of(cls, mechanism: Mechanism, tolerance: float, bounds: EnergyBounds | None = None) -> "RestState | None":
        """The rest state of ``mechanism`` for ``tolerance`` (m, m/s), or None where no rest can be proven
        (module docstring).  ``bounds``: the scene's :class:`EnergyBounds` if at hand (its potential well)."""
        if not dissipative(mechanism) or any(c.sticks for c in mechanism.connectors):
            return None
        bounds = bounds or EnergyBounds(mechanism)
        if bounds.loose:  # a potential given as a function outside the well: its rest state is not modelled here
            return None
        well = bounds.well
        n = len(mechanism.bodies)
        form = _QuadraticForm.of(mechanism)
        null = form.null_space()
        unit = np.eye(n)
        gamma, x_r = 0.0, 0.0
        if well is None:
            positions, alphas, b = np.zeros(n), np.zeros(n), None
        else:
            if not math.isfinite(well.minimum):
                return None
            b, x_r = well.body, well.argmin
            along_b = null.T @ unit[b]  # P e_b in the null space's basis
            norm2 = float(along_b @ along_b)
            if norm2 < _NULL_TOLERANCE:  # a linear spring holds the well's body: x* is not the well's minimum
                return None
            positions = x_r * (null @ along_b) / norm2
            alphas = np.array([float((null.T @ unit[i]) @ along_b) / norm2 for i in range(n)])
            positions[b], alphas[b] = x_r, 1.0  # (exactly: both are so up to round-off)
            gamma = _minimum_round_off(well, x_r, tolerance)
            if gamma is None:
                return None
        for contact in mechanism.contacts:
            if (well is None or contact not in well) and mechanism.relative_at(contact, positions) - contact.offset > 0.0:
                return None  # closed at rest outside the well (an initial interference)
        threshold = min(0.5 * body.mass * tolerance * tolerance for body in mechanism.bodies)
        for i in range(n):
            alpha = float(alphas[i]) if abs(alphas[i]) > _NULL_TOLERANCE else 0.0
            spring_part = unit[i] - alpha * unit[b] if alpha else unit[i]
            coefficient = form.coefficient(spring_part) if i != b else 0.0
            if not math.isfinite(coefficient):
                return None  # no spring holds body i
            if not alpha:
                threshold = min(threshold, tolerance * tolerance / coefficient)
                continue
            share = tolerance if coefficient == 0.0 else 0.5 * tolerance
            if coefficient > 0.0:
                threshold = min(threshold, share * share / coefficient)
            threshold = min(threshold, well_energy(well, x_r, share / abs(alpha)))
        if not threshold > 0.0:
            return None
        return cls(mechanism, tolerance, positions, threshold, well, x_r, gamma)

    def energy_bound(self, x, v) -> float:
        """``E_up`` (J): a bound on ``E - W(x_r) + gamma`` at the state (body positions m, velocities m/s, in body
        order; plain floats), hence on every non-negative term of the energy at every later time."""
        total = 0.0
        for i, half_mass in self._kinetic:
            total += half_mass * v[i] * v[i]
        for a, b, half_stiffness in self._springs:
            d = (x[b] if b is not None else 0.0) - (x[a] if a is not None else 0.0)
            total += half_stiffness * d * d
        for a, b, elastic in self._elastic:
            total += elastic((x[b] if b is not None else 0.0) - (x[a] if a is not None else 0.0))
        if self.well is not None:
            x_b = x[self.well.body]
            slope, magnitude = _slope(self.well, x_b)
            offset = x_b - self._x_r
            total += offset * slope + abs(offset) * ROUNDING * magnitude + self._gamma
        return total

    def reached(self, x, v) -> bool:
        """True if the state proves the scene within :attr:`tolerance` of its rest state for all later time
        (it must be after the last input)."""
        return self.energy_bound(x, v) * (1.0 + ENERGY_SLACK) < self.threshold


def _slope(well, x: float) -> tuple[float, float]:
    """``(W'(x), sum of |F_c|)`` in N: the well's slope and the magnitude its round-off scales with."""
    slope = magnitude = 0.0
    for c, s in zip(well.members, well.signs):
        force = c.python_force(s * x, 0.0)
        slope += s * force
        magnitude += abs(force)
    return slope, magnitude


def well_energy(well, x_r: float, delta: float) -> float:
    """A lower bound (J) of ``min(W(x_r - delta), W(x_r + delta)) - W(x_r)``: on each side the lower Riemann sum
    of the non-decreasing ``+-W'`` over ``[x_r, x_r +- delta]``, each value less its round-off; 0 where the
    interval leaves the well's domain."""
    low, high = well.domain
    if not (low < x_r - delta and x_r + delta < high):
        return 0.0
    piece = delta / RIEMANN_PIECES
    sides = []
    for side in (-1.0, 1.0):
        total = 0.0
        for j in range(RIEMANN_PIECES):
            slope, magnitude = _slope(well, x_r + side * j * piece)
            total += side * slope - ROUNDING * magnitude
        sides.append(total * piece)
    return max(min(sides), 0.0)


def _minimum_round_off(well, x_r: float, tolerance: float) -> float | None:
    """``gamma`` (J): a bound on ``W(x_r) - min W``.  The true minimum lies in ``(x_r - e, x_r + e)`` once the
    slope is negative at the left end and positive at the right beyond round-off, and then
    ``W(x_r) - min W <= |W'(x_r)| e <=`` the larger |slope| at the ends times e (convexity).  None if no such e
    up to ``tolerance``."""
    e = max(abs(x_r), tolerance) * 1e-15
    while e <= tolerance:
        left, left_magnitude = _slope(well, x_r - e)
        right, right_magnitude = _slope(well, x_r + e)
        left_bound, right_bound = left + ROUNDING * left_magnitude, right - ROUNDING * right_magnitude
        if left_bound < 0.0 < right_bound:
            return e * max(abs(left) + ROUNDING * left_magnitude, abs(right) + ROUNDING * right_magnitude)
        e *= 2.0
    return None


class RestWatch:
    """The rest stop of one solve: where to split it, when rest is proven, and the held tail.

    :attr:`time` is the rest time (s) once :meth:`settle` proved it (None before).
    """

    def __init__(self, state: RestState, end_time: float):
        self.state = state
        self.end_time = float(end_time)
        mechanism = state.mechanism
        self.after = mechanism.last_input_time
        self.time: float | None = None
        self._names = [(f"{body.name}_position", f"{body.name}_velocity") for body in mechanism.bodies]

    @classmethod
    def of(cls, mechanism: Mechanism, tolerance: float | None, end_time: float,
           bounds: EnergyBounds | None = None) -> "RestWatch | None":
        """The watch of a solve to ``end_time`` (s), or None if it is never stopped at rest: no ``tolerance``
        (not asked, or a fixed-step solver), a run no longer than :data:`CHECK_INTERVAL`, or no provable rest."""
        if tolerance is None or not end_time > CHECK_INTERVAL:
            return None
        state = RestState.of(mechanism, tolerance, bounds)
        return None if state is None else cls(state, end_time)

    @property
    def tolerance(self) -> float:
        """The proven bound: m on every position, m/s on every velocity."""
        return self.state.tolerance

    def split(self, plan: list[tuple[float, float, object]]) -> list[tuple[float, float, object]]:
        """The segments ``(start s, end s, settings)`` of ``plan`` cut at every multiple of :data:`CHECK_INTERVAL`,
        those from the last input on (before it no chunk could prove anything; and no chunk ends at a shot)."""
        out = []
        for t0, t1, settings in plan:
            if t0 < self.after:
                out.append((t0, t1, settings))
                continue
            cut = (math.floor(t0 / CHECK_INTERVAL) + 1) * CHECK_INTERVAL
            while cut < t1:
                out.append((t0, cut, settings))
                t0, cut = cut, cut + CHECK_INTERVAL
            out.append((t0, t1, settings))
        return out

    def _state(self, values: dict, j: int) -> tuple[list[float], list[float]]:
        return ([float(values[p][j]) for p, _ in self._names], [float(values[v][j]) for _, v in self._names])

    def settle(self, start: float, end: float, segment: tuple[np.ndarray, dict]):
        """After a segment from ``start`` to ``end`` (s) with samples ``(time, values by sensor name)``: the
        segment cut at the first sample that proves rest (:attr:`time` set), or None (go on).

        Checked only for a segment that starts at or after the last input (its first sample holds a shot's
        velocity jump; a segment ending at a shot ends before it), ends from :data:`CHECK_INTERVAL` on and
        before the end time: the last sample first, then a bisection for the first sample that proves rest
        (the energy decreases, so the proving samples are the last ones; any sample found is a proof)."""
        if not (CHECK_INTERVAL <= end < self.end_time and start >= self.after):
            return None
        time, values = segment
        last = len(time) - 1
        if last < 0 or not self.state.reached(*self._state(values, last)):
            return None
        low, high = 0, last
        while low < high:
            middle = (low + high) // 2
            if self.state.reached(*self._state(values, middle)):
                high = middle
            else:
                low = middle + 1
        self.time = float(time[high])
        return time[:high + 1], {name: data[:high + 1] for name, data in values.items()}

    def hold(self, samples: Samples) -> Samples:
        """``samples`` (ending at :attr:`time`) with the rest state appended at :attr:`time` (a jump of at most
        the tolerance, over a zero-length interval) and at the end time: positions x*, velocities and
        accelerations 0, each recorded force at x* and rest."""
        mechanism = self.state.mechanism
        rest = self.state.positions
        tail_time = np.array([self.time, self.end_time])

        def tail(history: np.ndarray, value: float) -> np.ndarray:
            return np.concatenate([history, [value, value]])

        forces = {name: tail(history, float(mechanism.connector[name].python_force(
            mechanism.relative_at(mechanism.connector[name], rest), 0.0))) for name, history in samples.forces.items()}
        return replace(samples, time=np.concatenate([samples.time, tail_time]),
                       positions={b.name: tail(samples.positions[b.name], rest[i])
                                  for i, b in enumerate(mechanism.bodies)},
                       velocities={name: tail(history, 0.0) for name, history in samples.velocities.items()},
                       accelerations={name: tail(history, 0.0) for name, history in samples.accelerations.items()},
                       forces=forces)
