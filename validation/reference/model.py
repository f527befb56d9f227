"""The reference's mechanism: bodies, connectors, modes and the right-hand side, effect-free.

Written from DESIGN.md ("Bodies and connectors").  Every body moves on the recoil axis (x positive in
the recoil direction, 0 at battery; a body starts at its ``initial_position``: 0 unless a preload holds
the barrel against its battery stop, DESIGN.md "Initial state").  Every force is a :class:`Connector` between points ``a`` and
``b`` (bodies, or the ground :data:`GROUND`) with relative coordinate ``d = x_b - x_a`` (m) and rate
``d' = v_b - v_a`` (m/s); its force ``F`` (N) pushes ``b`` towards -x and ``a`` towards +x::

    m_i x_i'' = sum_{connectors with a = i} F  -  sum_{connectors with b = i} F
    S         = sum_{connectors with a = ground} F  -  sum_{connectors with b = ground} F   (support force)

State vector ``y``: ``[x_0, v_0, x_1, v_1, ..., D_0, D_1, ..., W_0, W_1, ...]`` -- position (m) and
velocity (m/s) of every body (the barrel first, then the absorbers in scene order), then the dissipated
energy ``D_j`` (J) of every dissipating connector, ``dD_j/dt = F d' - dU_j/dt`` (W), then the work
``W_k`` (J) of every external input (:class:`Load`, :class:`Impulse`; none in the paper's scenes).

**External inputs** act on one body and are not transmitted to the ground (no share of S):

* a :class:`Load` is a force ``L(t)`` (N, a function of time alone, positive in the recoil direction)
  added to its body's force: ``m_i x_i'' = ... + L(t)``; its work ``dW/dt = L(t) v_i`` (W).  Its
  *breakpoints* (times where L or dL/dt jumps) are time events of the solver: every segment integrates
  one smooth *piece* of the law, fixed in the segment's :class:`Mode` (``mode.loads``);
* an :class:`Impulse` adds a velocity jump ``dv`` (m/s) to its body at given times (the shots of a burst):
  the solver stops there, jumps the state and restarts; the work of a jump is
  ``m ((v + dv)^2 - v^2) / 2`` (J).

Energy balance: ``sum kinetic + sum U + sum D - sum W = E(0)``.

What a connector does is written in the term modules (:mod:`validation.reference.terms`); this module
only runs them:

* a **mode** (:class:`Mode`) fixes every connector's discrete state for one smooth segment (a contact's
  phase, the damper's branch), so that the right-hand side is smooth inside a segment;
* a connector's **equations** for a state (:class:`Equations`) give its force ``F`` (and dissipated power)
  as a few lines of Python source from the positions and velocities of its ends;
  :mod:`validation.reference.codegen` joins them, per mode, into one straight-line function that adds
  ``+F`` to the force on ``a`` and ``-F`` to the force on ``b`` (the ground's collects S): the
  right-hand side on Python floats, and the same code on numpy rows for post-processing.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import abc
import bisect
import functools
import math

import numpy as np
from scipy.integrate import quad

from .codegen import compile_mode

#: The name of the ground as a connector end.
GROUND = "ground"
#: The barrel's body name (always body 0).
BARREL = "barrel"


class ReferenceModelError(ValueError):
    """The scene cannot be modelled by the reference (a table without a reference term, a bad name)."""


@dataclass(frozen=True)
class Body:
    """A mass on the recoil axis: ``name``, ``mass`` (kg), ``initial_velocity`` (m/s), ``initial_position`` (m,
    0 unless a preload holds the body elsewhere at t = 0)."""

    name: str
    mass: float
    initial_velocity: float = 0.0
    initial_position: float = 0.0


def _difference(ia: int | None, ib: int | None) -> Callable:
    """``y -> y[ib] - y[ia]`` with ``None`` standing for the ground (0): works on (n,) and (n, N)."""
    if ia is None:
        return lambda y: y[ib]
    if ib is None:
        return lambda y: -y[ia]
    return lambda y: y[ib] - y[ia]


@dataclass(frozen=True)
class Equations:
    """One connector's force in one state, as Python source for :mod:`validation.reference.codegen`.

    ``code``: lines that set ``{F}`` (N) and, for a dissipating connector, ``{P}`` (W: ``F d' - dU/dt``)
    from ``{xa}``, ``{xb}``, ``{va}``, ``{vb}`` (positions, velocities of a and b; ``0.0`` for the ground)
    and, for a ``constraint`` (computed after all the others), the forces ``{fa}``, ``{fb}`` on a and b so
    far.  Every other ``{name}`` is a number of ``constants``, or a function (a callable constant: the default
    equations call the connector's law); temporaries are plain names; the functions ``abs`` and ``copysign`` are
    available.
    """

    code: str
    constants: dict = field(default_factory=dict)
    constraint: bool = False


class Connector(abc.ABC):
    """A force between points ``a`` and ``b`` (body names or :data:`GROUND`): the reference's side of the element
    contract (DESIGN.md, "The element contract"), written from its equations.

    The force law ``F(d, d')`` (N) is the connector: :meth:`law`, the one mandatory part.  A term whose
    connector has no law cannot be instantiated (TypeError while the reference model is built), never a silent
    zero force.  Everything else is derived from the law unless the term gives it in closed form, which
    ``tests/validation/reference/test_term_conformance.py`` checks against the derived one::

        conservative part   F_c(d)   = F(d, 0)                     (static_force)
        stored energy       U(d)     = integral_0^d F_c(s) ds      (stored_energy: scipy's quad on a float,
                                                                    on arrays between the sorted samples,
                                                                    summed outward from 0; piece by piece
                                                                    between the kinks)
        dissipated power    P(d, d') = (F(d, d') - F_c(d)) d'      (dissipated_power; = F d' - dU/dt)
        force bound         B(D, V) >= max |F(d, d')| over |d| <= D, |d'| <= V   (force_bound)

    To add a term (a connector with a law of its own)
    --------------------------------------------------
    1. Subclass :class:`Connector` and implement :meth:`law` ``(d, rate, state=None) -> F`` in N, on floats and
       on numpy arrays; a contact's law is its physical force (clipped to >= 0).
    2. Call ``super().__init__(name, a, b)``.
    3. Declare what holds for the law (class or instance attributes; the defaults are the safe ones):
       :attr:`stores_energy` (False only where ``F(d, 0) = 0`` for every d: a damper, friction),
       :attr:`dissipates` (False only where ``F(d, d') = F(d, 0)``: a spring), :attr:`kinks` (the d where
       ``F(d, 0)`` or its slope jumps), :attr:`d_limit`, :attr:`injects_energy`, :attr:`is_contact`,
       :attr:`nonlinear_potential` (its potential is neither ``k d^2 / 2`` nor >= 0: the early stop bounds it
       with its body's stops, :mod:`validation.reference.finality`; derived by default: every potential that is
       not declared quadratic by :attr:`linear_stiffness` nor a contact's).
    4. Optionally give closed forms, each replacing a derived default and checked against it:
       :meth:`stored_energy`, :meth:`static_force`, :meth:`force_bound`, :attr:`linear_stiffness` (the
       stiffness of an always-acting linear spring: the energy bounds' quadratic form), :meth:`force_rate`
       (dF/dt; None, the default, has the result find peaks numerically).
    5. Optionally give :meth:`equations`, the law of one mode as Python source (the solver's speed; the
       default calls :meth:`law`), and, for a law with discrete states (pieces, branches, contact phases),
       :meth:`provisional`, :meth:`classify`, :meth:`events` and :attr:`classify_pass`.
    6. Add the term module (``TABLES``, ``build``) to :mod:`validation.reference.terms`, or register it from
       outside with :func:`validation.reference.terms.register_term`.

    Class attributes (flags):

    * ``is_contact`` -- a contact (episodes, impacts, onsets are reported for it);
    * ``dissipates`` -- it has a dissipated-energy state (set per instance where it depends on values);
    * ``stores_energy`` -- it has a potential U(d);
    * ``injects_energy`` -- its law can add energy (the early stop has no bound then);
    * ``classify_pass`` -- 0: no discrete state; 1: decided on the accelerations *without* its own force
      (contacts); 2: decided on the accelerations of the classified mode (velocity-sign switches);
    * ``nonlinear_potential`` -- see step 3; ``d_limit`` (m) is the largest d where its law is defined.
    """

    is_contact = False
    dissipates = True
    stores_energy = True
    classify_pass = 0
    injects_energy = False
    d_limit = float("inf")
    #: Samples per axis of the box in the derived force bound.
    BOUND_SAMPLES = 41

    def __init__(self, name: str, a: str, b: str):
        if a == b:
            raise ReferenceModelError(f"connector {name!r} joins {a!r} to itself")
        self.name, self.a, self.b = name, a, b

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r}, {self.a} -> {self.b})"

    # ------------------------------------------------------------------ set by the model
    def bind(self, index: int, bodies: dict[str, int], masses: list[float], ground_slot: int,
             dissipation_slot: int | None) -> None:
        """Store the connector's place in the state: indices into ``s`` (``x`` at ``ia``/``ib``, ``v`` one
        after), force slots ``fa``/``fb``, the dissipation index ``di``, the body indices (None = ground)
        ``body_a``/``body_b`` and their masses (None = ground)."""
        self.index = index
        self.body_a = None if self.a == GROUND else bodies[self.a]
        self.body_b = None if self.b == GROUND else bodies[self.b]
        self.ia = ground_slot if self.body_a is None else 2 * self.body_a
        self.ib = ground_slot if self.body_b is None else 2 * self.body_b
        nb = len(masses)
        self.fa = nb if self.body_a is None else self.body_a
        self.fb = nb if self.body_b is None else self.body_b
        self.mass_a = None if self.body_a is None else masses[self.body_a]
        self.mass_b = None if self.body_b is None else masses[self.body_b]
        self.di = dissipation_slot
        xa = None if self.body_a is None else 2 * self.body_a
        xb = None if self.body_b is None else 2 * self.body_b
        #: d(y) and d'(y) on a state or a batch of states (m, m/s)
        self.d_of = _difference(xa, xb)
        self.rate_of = _difference(None if xa is None else xa + 1, None if xb is None else xb + 1)

    @property
    def support_sign(self) -> float:
        """+1 if ``a`` is the ground, -1 if ``b`` is, 0 between two bodies (its share of S is sign * F)."""
        return 1.0 if self.a == GROUND else (-1.0 if self.b == GROUND else 0.0)

    @property
    def inverse_reduced_mass(self) -> float:
        """``1/m_a + 1/m_b`` in 1/kg (the ground counts as infinitely heavy)."""
        return sum(1.0 / m for m in (self.mass_a, self.mass_b) if m is not None)

    # ------------------------------------------------------------------ the law (mandatory)
    @abc.abstractmethod
    def law(self, d, rate, state=None):
        """The force F (N) at relative coordinate ``d`` (m) and rate ``rate`` (m/s), floats or numpy arrays.

        ``state`` is the connector's discrete state in a mode (what :meth:`classify` gives); it matters only
        for a law with memory (a restitution contact's episode), None otherwise."""

    def equations(self, state) -> Equations | None:
        """The force in ``state`` as source (:class:`Equations`): by default the law itself, called with
        ``d = x_b - x_a``, ``d' = v_b - v_a`` and ``state``, and, for a connector that dissipates, the power
        ``(F - F(d, 0)) d'``.  None: no force, no power."""
        law = functools.partial(self.law, state=state)
        if not self.dissipates:
            return Equations("{F} = {law}({xb} - {xa}, {vb} - {va})", dict(law=law))
        return Equations("""
            d = {xb} - {xa}
            rate = {vb} - {va}
            {F} = {law}(d, rate)
            {P} = ({F} - {law}(d, 0.0 * rate)) * rate""", dict(law=law))

    def reported(self, force):
        """The force as reported (N): the law's value; contacts clip it to >= 0."""
        return force

    def force_rate(self, state, d, rate, acceleration):
        """dF/dt (N/s) in ``state`` from d (m), d' (m/s), d'' (m/s^2) (numpy); None: not analytic (the
        result then finds a peak of the force numerically)."""
        return None

    # ------------------------------------------------------------------ derived unless closed form
    def static_force(self, d: float) -> float:
        """``F_c(d) = F(d, 0)`` (N) at ``d`` (m, a float): the force at rest (the static equilibrium at t = 0, the
        early stop's potential well)."""
        return float(self.law(float(d), 0.0))

    def dissipated_power(self, d, rate, state=None):
        """``P = (F(d, d') - F(d, 0)) d'`` (W) on floats or arrays: the law's power not stored."""
        return (self.law(d, rate, state) - self.law(d, 0.0 * rate, state)) * rate

    @property
    def kinks(self) -> tuple[float, ...]:
        """The d (m) where ``F(d, 0)`` or its slope jumps: the derived stored energy integrates between them."""
        return ()

    def stored_energy(self, d):
        """``U(d) = integral_0^d F(s, 0) ds`` (J) on a float or an array (0 for a connector that stores none):
        :meth:`derived_stored_energy` unless closed form."""
        if not self.stores_energy:
            return 0.0 * d
        return self.derived_stored_energy(d)

    def derived_stored_energy(self, d):
        """``integral_0^d F(s, 0) ds`` (J) by scipy's adaptive ``quad`` (relative 1e-12) on each piece between
        0, the :attr:`kinks` and d; on an array, the distinct values, 0 and the kinks sorted, each piece between
        neighbours integrated so and summed outward from 0 (no cancellation near 0).  inf beyond
        :attr:`d_limit`."""
        if np.ndim(d) == 0:
            return self._energy_by_quad(float(d))
        values = np.asarray(d, dtype=float)
        flat = values.ravel()
        mask = flat < self.d_limit
        inside = flat[mask]
        lo, hi = (min(float(inside.min()), 0.0), max(float(inside.max()), 0.0)) if inside.size else (0.0, 0.0)
        points = np.unique(np.concatenate((inside, [0.0], [k for k in self.kinks if lo < k < hi])))
        pieces = np.array([self._piece(float(a), float(b)) for a, b in zip(points[:-1], points[1:])])
        zero = int(np.searchsorted(points, 0.0))
        cumulative = np.zeros(points.size)
        cumulative[zero + 1:] = np.cumsum(pieces[zero:])
        cumulative[:zero] = -np.cumsum(pieces[:zero][::-1])[::-1]
        out = np.full(flat.shape, np.inf)
        out[mask] = cumulative[np.searchsorted(points, inside)]
        return out.reshape(values.shape)

    def _piece(self, start: float, end: float) -> float:
        """``integral_start^end F(s, 0) ds`` (J) by scipy's ``quad``, relative 1e-12."""
        return quad(lambda s: float(self.law(s, 0.0)), start, end, epsabs=0.0, epsrel=1e-12, limit=200)[0]

    def _energy_by_quad(self, d: float) -> float:
        """:meth:`derived_stored_energy` on one float."""
        if d >= self.d_limit:
            return math.inf
        inner = sorted((k for k in self.kinks if min(0.0, d) < k < max(0.0, d)), reverse=d < 0.0)
        edges = [0.0] + inner + [d]
        return sum(self._piece(start, end) for start, end in zip(edges, edges[1:]))

    # ------------------------------------------------------------------ modes (overridden by switching laws)
    def provisional(self, s: list, previous):
        """A first guess of the state from the signs of ``s`` alone (others use it while one classifies)."""
        return None

    def classify(self, restart) -> Any:
        """The state on restart (:class:`validation.reference.switching.Restart`)."""
        return None

    def events(self, state, restart) -> list[tuple]:
        """Switching surfaces watched in ``state``: ``(event, g(t, y), positive, rate, noise)`` each."""
        return []

    def rough_events(self, state) -> tuple[str, ...]:
        """Events of ``state`` across which the segment's right-hand side is only C^1 (the solver then
        integrates the step that crosses one again in short steps)."""
        return ()

    # ------------------------------------------------------------------ bounds
    @property
    def nonlinear_potential(self) -> bool:
        """True where the potential is bounded by the early stop's potential well, not by its quadratic form: by
        default every potential that is neither declared ``k d^2 / 2`` (:attr:`linear_stiffness` > 0) nor a
        contact's (bounded by its penetration) -- so a term that forgets to say so is never left out of the
        bounds.  A term declares it as a class attribute to say so explicitly."""
        return bool(self.stores_energy) and not self.is_contact and not self.linear_stiffness > 0

    @property
    def linear_stiffness(self) -> float:
        """Stiffness (N/m) of an always-acting linear spring ``k d^2 / 2`` (the energy bounds' quadratic form); 0
        for any other law (its potential is then bounded otherwise: a contact's penetration, a potential well)."""
        return 0.0

    def force_bound(self, d_bound: float, rate_bound: float, penetration_bound: float) -> float:
        """Bound (N) on |F| given ``|d| <= d_bound`` (m), ``|d'| <= rate_bound`` (m/s) and, for a contact,
        its penetration ``p <= penetration_bound`` (m): :meth:`derived_force_bound` unless closed form."""
        return self.derived_force_bound(d_bound, rate_bound)

    def derived_force_bound(self, d_bound: float, rate_bound: float) -> float:
        """The largest |F| on a :attr:`BOUND_SAMPLES` x :attr:`BOUND_SAMPLES` grid of the box ``|d| <= D``,
        ``|d'| <= V`` (its corners and edges included) plus the largest change of F between neighbouring grid
        points (a bound for a law monotone on each grid cell); inf for an unbounded box, one reaching
        :attr:`d_limit` or a law not finite on it."""
        D, V = abs(float(d_bound)), abs(float(rate_bound))
        if not (math.isfinite(D) and math.isfinite(V)) or D >= self.d_limit:
            return math.inf
        d, rate = np.meshgrid(np.linspace(-D, D, self.BOUND_SAMPLES), np.linspace(-V, V, self.BOUND_SAMPLES),
                              indexing="ij")
        with np.errstate(all="ignore"):
            F = np.asarray(self.law(d, rate), dtype=float) * np.ones_like(d)
        if not np.all(np.isfinite(F)):
            return math.inf
        step = max(float(np.abs(np.diff(F, axis=axis)).max(initial=0.0)) for axis in (0, 1))
        return float(np.abs(F).max()) + step


class Load:
    """An external force ``L(t)`` (N, positive in the recoil direction) on ``body``, a function of time alone.

    It is added to the body's force and not transmitted to the ground (no share of the support force);
    its work is ``W(t) = integral_0^t L v_body dt`` (J).  Subclasses give the law:

    * :meth:`force` -- L at times ``t`` (float or numpy array), right-continuous at a jump;
    * :attr:`breakpoints` -- times (s) where L or dL/dt is discontinuous: segment boundaries of the solve;
    * :meth:`piece` / :meth:`equations` -- the smooth law on ``[t, next breakpoint]`` as Python source for
      :mod:`validation.reference.codegen` (``{L}`` from ``t``), None where L is 0 there;
    * :attr:`last_input_time` -- time (s) after which L is 0 (inf if it never ends: the early stop then has
      no energy bound); :meth:`impulse` -- ``integral L dt`` (N s) over an interval.
    """

    def __init__(self, name: str, body: str):
        self.name, self.body = name, body

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r} on {self.body})"

    def force(self, t):
        """L (N) at ``t`` (s)."""
        raise NotImplementedError

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return ()

    def piece(self, t: float):
        """Key (hashable) of the smooth piece of the law on ``[t, next breakpoint)``."""
        return 0

    def equations(self, piece) -> str | None:
        """Source lines setting ``{L}`` (N) from ``t`` on ``piece``; None: L is 0 on it."""
        raise NotImplementedError

    @property
    def last_input_time(self) -> float:
        raise NotImplementedError

    def impulse(self, t0: float = -math.inf, t1: float = math.inf) -> float:
        raise NotImplementedError


class ConstantLoad(Load):
    """``L = value`` (N) at all times (gravity along an inclined cradle): no breakpoints, never ends (unless
    0); its work is ``value (x(t) - x(0))``, minus the change of the potential ``-value x``."""

    def __init__(self, name: str, body: str, value: float):
        super().__init__(name, body)
        self.value = float(value)

    def force(self, t):
        return self.value + 0.0 * np.asarray(t, dtype=float) if np.ndim(t) else self.value

    def equations(self, piece) -> str | None:
        return None if self.value == 0.0 else f"{{L}} = {self.value!r}"

    @property
    def last_input_time(self) -> float:
        return math.inf if self.value != 0.0 else 0.0

    def impulse(self, t0: float = -math.inf, t1: float = math.inf) -> float:
        return self.value * (t1 - t0) if self.value != 0.0 else 0.0


class PiecewiseLinearLoad(Load):
    """``L(t)`` linear between consecutive ``points`` ``(t s, L N)`` (sorted by time; a repeated time is a
    jump, from the first value to the last of that time), 0 before the first and after the last point.

    Between consecutive distinct times ``T_i < T_(i+1)`` (piece ``i + 1``; piece 0 is before ``T_0``)::

        L(t) = L_i + (L_(i+1) - L_i) (t - T_i) / (T_(i+1) - T_i)

    with ``L_i`` the last value at ``T_i`` and ``L_(i+1)`` the first value at ``T_(i+1)``.  Every ``T_i``
    is a breakpoint.  ``integral L dt`` over a piece is exact by the trapezoidal rule.
    """

    def __init__(self, name: str, body: str, points):
        super().__init__(name, body)
        points = [(float(t), float(f)) for t, f in points]
        if len(points) < 2 or any(b[0] < a[0] for a, b in zip(points, points[1:])):
            raise ReferenceModelError(f"load {name!r}: needs at least two points in time order")
        self.points = points
        self.times = tuple(sorted({t for t, _ in points}))
        first = {}
        last = {}
        for t, f in points:
            first.setdefault(t, f)
            last[t] = f
        #: per piece i (1 .. len(times) - 1): (start time, value at the start, slope N/s)
        self._pieces = {}
        for i in range(1, len(self.times)):
            a, b = self.times[i - 1], self.times[i]
            start, end = last[a], first[b]
            self._pieces[i] = (a, start, (end - start) / (b - a), end, b)
        tail = [self._pieces.get(i, (0.0, 0.0, 0.0, 0.0, 0.0)) for i in range(len(self.times) + 1)]
        self._start = np.array([p[0] for p in tail])
        self._value = np.array([p[1] for p in tail])
        self._slope = np.array([p[2] for p in tail])

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return self.times

    def piece(self, t: float) -> int:
        """The number of breakpoints at or before ``t``: 0 before the first, ``len(times)`` after the last."""
        return bisect.bisect_right(self.times, t)

    def equations(self, piece) -> str | None:
        if piece not in self._pieces:
            return None
        start, value, slope, end, _ = self._pieces[piece]
        if value == 0.0 and end == 0.0:
            return None
        if slope == 0.0:
            return f"{{L}} = {value!r}"
        return f"{{L}} = {value!r} + {slope!r} * (t - {start!r})"

    def force(self, t):
        ta = np.asarray(t, dtype=float)
        i = np.searchsorted(np.asarray(self.times), ta, side="right")
        out = self._value[i] + self._slope[i] * (ta - self._start[i])
        return float(out) if np.ndim(t) == 0 else out

    @property
    def last_input_time(self) -> float:
        return self.times[-1]

    def impulse(self, t0: float = -math.inf, t1: float = math.inf) -> float:
        """``integral_{t0}^{t1} L dt`` (N s), exact (each piece clipped to the interval, trapezoidal)."""
        total = 0.0
        for start, value, slope, _, end in self._pieces.values():
            a, b = max(start, t0), min(end, t1)
            if b > a:
                fa, fb = value + slope * (a - start), value + slope * (b - start)
                total += 0.5 * (fa + fb) * (b - a)
        return total


@dataclass(frozen=True)
class Impulse:
    """Velocity jumps of one body: at each of ``times`` (s) the velocity of ``body`` gains ``jump`` (m/s), an
    impulse ``m jump`` (N s); the work of a jump from v is ``m ((v + jump)^2 - v^2) / 2`` (J)."""

    name: str
    body: str
    times: tuple
    jump: float

    @property
    def last_input_time(self) -> float:
        return max(self.times, default=0.0)


@dataclass(frozen=True)
class Mode:
    """The discrete state of every connector in one smooth segment (``mode[name]``; None: stateless), and
    the piece of every load's law (``loads``, one key per :attr:`Model.loads`, from :meth:`Load.piece`).

    A mode without ``loads`` (``()``) of a model with loads evaluates each load's whole law
    (:meth:`Load.force`) instead of one smooth piece: right for a state at a given time, not for
    integrating across a breakpoint.
    """

    names: tuple[str, ...]
    states: tuple
    loads: tuple = ()

    def __getitem__(self, name: str):
        return self.states[self.names.index(name)]

    def __repr__(self) -> str:
        inner = ", ".join(f"{n}={s!r}" for n, s in zip(self.names, self.states) if s is not None)
        pieces = f"; load pieces {list(self.loads)}" if self.loads else ""
        return f"Mode({inner}{pieces})"


@dataclass(frozen=True)
class AbsorberRole:
    """An absorber: its body, its actuator connector (None if k_r = c_r = 0) and its contact (names)."""

    name: str
    body: str
    actuator: str | None
    contact: str


@dataclass
class Evaluation:
    """What the equations give at a state (floats) or a batch (arrays): ``forces[j]``, the raw force of
    connector j (N, unclipped: the segment's smooth law); ``accelerations[i]`` (m/s^2); ``support``: S
    (N) from the raw forces."""

    forces: list
    accelerations: list
    support: Any


class Model:
    """Bodies (barrel first), connectors (scene order), roles (absorbers, stops), external inputs (loads,
    impulses) and the shot times of one scene.

    ``shot_times``: the times (s) the shots of a burst fire (None without a burst: one shot at t = 0): the
    per-shot outputs of the result are taken between them, and every one is a time event of the solve.
    """

    def __init__(self, name: str, bodies, connectors, absorbers=(), stops=(), loads=(), impulses=(),
                 shot_times=None):
        self.name = name
        self.bodies = tuple(bodies)
        self.connectors = tuple(connectors)
        self.absorbers = tuple(absorbers)
        self.stops = tuple(stops)
        self.loads = tuple(loads)
        self.impulses = tuple(impulses)
        self.shot_times = None if shot_times is None else tuple(float(t) for t in shot_times)
        if not self.bodies or self.bodies[0].name != BARREL:
            raise ReferenceModelError("the barrel must be the first body")
        names = [b.name for b in self.bodies]
        inputs = [i.name for i in self.loads + self.impulses]
        for pool, what in ((names, "body"), ([c.name for c in self.connectors], "connector"),
                           (inputs, "external input")):
            duplicate = next((n for n in pool if pool.count(n) > 1), None)
            if duplicate is not None:
                raise ReferenceModelError(f"{duplicate!r} names two {what}s")
        self.body_index = {n: i for i, n in enumerate(names)}
        for item in self.loads + self.impulses:
            if item.body not in self.body_index:
                raise ReferenceModelError(f"{item.name!r} acts on {item.body!r}, which is not a body")
        self.masses = [b.mass for b in self.bodies]
        self.n_bodies = len(self.bodies)
        self.dissipating = tuple(c for c in self.connectors if c.dissipates)
        #: index of the work state of every load and impulse, by name
        first_work = 2 * self.n_bodies + len(self.dissipating)
        self.work_slot = {name: first_work + k for k, name in enumerate(inputs)}
        self.n_states = first_work + len(inputs)
        slots = {c.name: 2 * self.n_bodies + k for k, c in enumerate(self.dissipating)}
        for j, c in enumerate(self.connectors):
            for end in (c.a, c.b):
                if end != GROUND and end not in self.body_index:
                    raise ReferenceModelError(f"connector {c.name!r} ends at {end!r}, which is not a body")
            c.bind(j, self.body_index, self.masses, self.n_states, slots.get(c.name))
        self.connector_index = {c.name: j for j, c in enumerate(self.connectors)}
        self.names = tuple(c.name for c in self.connectors)
        self.contacts = tuple(c for c in self.connectors if c.is_contact)
        self._compiled: dict = {}

    # ------------------------------------------------------------------ state
    @property
    def axis_states(self) -> int:
        """Length of the axis' state (the 1-D layout): all of it here; the first part of a planar state
        (:mod:`validation.reference.planar`)."""
        return self.n_states

    def initial_state(self) -> np.ndarray:
        """y(0): every body at its initial position (0 but for a preload's hold) with its initial velocity, no
        dissipated energy."""
        y = np.zeros(self.n_states)
        for i, body in enumerate(self.bodies):
            y[2 * i] = body.initial_position
            y[2 * i + 1] = body.initial_velocity
        return y

    def connector(self, name: str) -> Connector:
        """The connector called ``name`` (KeyError naming the known ones)."""
        if name not in self.connector_index:
            raise KeyError(f"no connector {name!r}; the scene has: {', '.join(self.names) or 'none'}")
        return self.connectors[self.connector_index[name]]

    def body(self, name: str) -> int:
        """The index of body ``name`` (KeyError naming the known ones)."""
        if name not in self.body_index:
            raise KeyError(f"no body {name!r}; the scene has: {', '.join(self.body_index)}")
        return self.body_index[name]

    # ------------------------------------------------------------------ external inputs
    def load_pieces(self, t: float) -> tuple:
        """The piece of every load's law on ``[t, next breakpoint)`` (the ``loads`` of a segment's mode)."""
        return tuple(load.piece(t) for load in self.loads)

    @property
    def time_events(self) -> tuple[float, ...]:
        """Times (s, > 0, sorted) where the solve is split: the loads' breakpoints, the impulses' times and
        the shot times (a restart there, the mode classified again)."""
        times = set(self.shot_times or ())
        for load in self.loads:
            times.update(load.breakpoints)
        for impulse in self.impulses:
            times.update(impulse.times)
        return tuple(sorted(t for t in times if t > 0.0))

    @property
    def last_input_time(self) -> float:
        """Time (s) after which no external input acts (0 without; inf under a load that never ends): energy
        bounds hold only after it."""
        return max([0.0] + [item.last_input_time for item in self.loads + self.impulses])

    def apply_impulses(self, t: float, y: np.ndarray) -> np.ndarray:
        """The state after the velocity jumps firing at ``t`` (s), their work added to their work states."""
        y = np.array(y, dtype=float)
        for impulse in self.impulses:
            if t in impulse.times:
                i = self.body_index[impulse.body]
                v, dv = y[2 * i + 1], impulse.jump
                y[2 * i + 1] = v + dv
                y[self.work_slot[impulse.name]] += 0.5 * self.masses[i] * ((v + dv) ** 2 - v ** 2)
        return y

    # ------------------------------------------------------------------ compiled equations
    def compiled(self, mode: Mode, kind: str, omit: int | None = None) -> Callable:
        """The compiled equations of ``mode`` (:func:`validation.reference.codegen.compile_mode`), cached."""
        key = (mode, kind, omit)
        function = self._compiled.get(key)
        if function is None:
            function = self._compiled[key] = compile_mode(self, mode, kind, omit)
        return function

    def rhs(self, mode: Mode) -> Callable:
        """``f(t, y) -> dy/dt`` in ``mode`` on Python floats (an overflow gives inf, as numpy would)."""
        return self.compiled(mode, "rhs")

    def evaluate(self, mode: Mode, y, omit: int | None = None, t=None) -> Evaluation:
        """Forces, accelerations and support force at a state ``y`` (n,) -- on Python floats -- or a batch
        (n, N) -- on numpy rows.  ``omit``: leave out connector ``omit``'s force.  ``t``: the time (s, a
        float or an array of N; needed, and only read, when the model has loads)."""
        y = np.asarray(y, dtype=float)
        function = self.compiled(mode, "scalar" if y.ndim == 1 else "array", omit)
        if not self.loads:
            return Evaluation(*function(y))
        if t is None:
            raise ValueError(f"the model has loads ({', '.join(load.name for load in self.loads)}): "
                             "evaluate needs the time t")
        return Evaluation(*function(y, t if y.ndim == 1 else np.asarray(t, dtype=float)))

    def relative_acceleration(self, connector: Connector, evaluation: Evaluation):
        """d'' = a_b - a_a (m/s^2) of ``connector`` (the ground does not accelerate)."""
        acc = evaluation.accelerations
        a_b = 0.0 if connector.body_b is None else acc[connector.body_b]
        a_a = 0.0 if connector.body_a is None else acc[connector.body_a]
        return a_b - a_a

    # ------------------------------------------------------------------ energy
    def kinetic_energies(self, y) -> dict[str, Any]:
        """``m v^2 / 2`` per body (J)."""
        return {b.name: 0.5 * b.mass * y[2 * i + 1] ** 2 for i, b in enumerate(self.bodies)}

    def stored_energies(self, y) -> dict[str, Any]:
        """U(d) per connector that stores energy (J)."""
        return {c.name: c.stored_energy(c.d_of(y)) for c in self.connectors if c.stores_energy}

    def dissipated_energies(self, y) -> dict[str, Any]:
        """D per dissipating connector (J): the state's last entries."""
        return {c.name: y[c.di] for c in self.dissipating}

    def works(self, y) -> dict[str, Any]:
        """W per load and impulse (J): the work done on the bodies so far (states after the dissipations)."""
        return {name: y[slot] for name, slot in self.work_slot.items()}

    def mechanical_energy(self, y):
        """Kinetic + stored energy (J) of a state or a batch."""
        return sum(self.kinetic_energies(y).values()) + sum(self.stored_energies(y).values())
