"""The reference's mechanism: bodies, connectors, modes and the right-hand side, effect-free.

Written from DESIGN.md ("Bodies and connectors").  Every body moves on the recoil axis (x positive in
the recoil direction, 0 at battery; a body starts at its ``initial_position``: 0 unless a preload holds
the barrel against its battery stop, DESIGN.md "Initial state").  Every force is a :class:`Connector` between points ``a`` and
``b`` (bodies, or the ground :data:`GROUND`) with relative coordinate ``d = x_b - x_a`` (m) and rate
``d' = v_b - v_a`` (m/s); its force ``F`` (N) pushes ``b`` towards -x and ``a`` towards +x::

    m_i x_i'' = sum_{connectors with a = i} F  -  sum_{connectors with b = i} F
    S         = sum_{connectors with a = ground} F  -  sum_{connectors with b = ground} F   (support force)

State vector ``y``: ``[x_0, v_0, x_1, v_1, ..., D_0, D_1, ...]`` -- position (m) and velocity (m/s) of
every body (the barrel first, then the absorbers in scene order), then the dissipated energy ``D_j`` (J)
of every dissipating connector, ``dD_j/dt = F d' - dU_j/dt`` (W).

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

import numpy as np

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
    far.  Every other ``{name}`` is a number of ``constants``; temporaries are plain names; the functions
    ``abs`` and ``copysign`` are available.
    """

    code: str
    constants: dict = field(default_factory=dict)
    constraint: bool = False


class Connector:
    """A force between points ``a`` and ``b`` (body names or :data:`GROUND`); see the module docstring.

    Subclasses (in the term modules) give the law: :meth:`equations` per state, and what the solver, the
    result and the early stop need.  Class attributes:

    * ``is_contact`` -- a contact (episodes, impacts, onsets are reported for it);
    * ``dissipates`` -- it has a dissipated-energy state (set per instance where it depends on values);
    * ``stores_energy`` -- it has a potential U(d);
    * ``injects_energy`` -- its law can add energy (the early stop has no bound then);
    * ``classify_pass`` -- 0: no discrete state; 1: decided on the accelerations *without* its own force
      (contacts); 2: decided on the accelerations of the classified mode (velocity-sign switches);
    * ``nonlinear_potential`` -- its potential is neither a linear spring's ``k d^2 / 2`` nor >= 0 (the
      recuperator's gas spring): the early stop bounds it together with its body's stops
      (:mod:`validation.reference.finality`); ``d_limit`` (m) is the largest d where its law is defined.
    """

    is_contact = False
    dissipates = False
    stores_energy = False
    classify_pass = 0
    injects_energy = False
    nonlinear_potential = False
    d_limit = float("inf")

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

    # ------------------------------------------------------------------ the law (overridden)
    def equations(self, state) -> Equations | None:
        """The force in ``state`` (:class:`Equations`); None: no force, no power."""
        return None

    def reported(self, force):
        """The force as reported (N): the law's value; contacts clip it to >= 0."""
        return force

    def force_rate(self, state, d, rate, acceleration):
        """dF/dt (N/s) in ``state`` from d (m), d' (m/s), d'' (m/s^2) (numpy); None if not analytic."""
        return 0.0 * rate

    def stored_energy(self, d):
        """Stored (potential) energy U(d) in J (numpy or float)."""
        return 0.0 * d

    def static_force(self, d: float) -> float:
        """The force (N) at rest (d' = 0) at ``d`` (m, a float): ``dU/dd`` of a connector with a potential, 0 for
        a damper (the static equilibrium at t = 0, the early stop's potential well)."""
        return 0.0

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

    # ------------------------------------------------------------------ bounds (overridden)
    @property
    def linear_stiffness(self) -> float:
        """Stiffness (N/m) of an always-acting linear spring ``k d^2 / 2`` (the energy bounds' quadratic form)."""
        return 0.0

    def force_bound(self, d_bound: float, rate_bound: float, penetration_bound: float) -> float:
        """Bound (N) on |F| given ``|d| <= d_bound`` (m), ``|d'| <= rate_bound`` (m/s) and, for a contact,
        its penetration ``p <= penetration_bound`` (m)."""
        return 0.0


@dataclass(frozen=True)
class Mode:
    """The discrete state of every connector in one smooth segment (``mode[name]``; None: stateless)."""

    names: tuple[str, ...]
    states: tuple

    def __getitem__(self, name: str):
        return self.states[self.names.index(name)]

    def __repr__(self) -> str:
        inner = ", ".join(f"{n}={s!r}" for n, s in zip(self.names, self.states) if s is not None)
        return f"Mode({inner})"


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
    """Bodies (barrel first), connectors (scene order) and roles (absorbers, stops) of one scene."""

    def __init__(self, name: str, bodies, connectors, absorbers=(), stops=()):
        self.name = name
        self.bodies = tuple(bodies)
        self.connectors = tuple(connectors)
        self.absorbers = tuple(absorbers)
        self.stops = tuple(stops)
        if not self.bodies or self.bodies[0].name != BARREL:
            raise ReferenceModelError("the barrel must be the first body")
        names = [b.name for b in self.bodies]
        for pool, what in ((names, "body"), ([c.name for c in self.connectors], "connector")):
            duplicate = next((n for n in pool if pool.count(n) > 1), None)
            if duplicate is not None:
                raise ReferenceModelError(f"{duplicate!r} names two {what}s")
        self.body_index = {n: i for i, n in enumerate(names)}
        self.masses = [b.mass for b in self.bodies]
        self.n_bodies = len(self.bodies)
        self.dissipating = tuple(c for c in self.connectors if c.dissipates)
        self.n_states = 2 * self.n_bodies + len(self.dissipating)
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

    def evaluate(self, mode: Mode, y, omit: int | None = None) -> Evaluation:
        """Forces, accelerations and support force at a state ``y`` (n,) -- on Python floats -- or a batch
        (n, N) -- on numpy rows.  ``omit``: leave out connector ``omit``'s force."""
        y = np.asarray(y, dtype=float)
        return Evaluation(*self.compiled(mode, "scalar" if y.ndim == 1 else "array", omit)(y))

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

    def mechanical_energy(self, y):
        """Kinetic + stored energy (J) of a state or a batch."""
        return sum(self.kinetic_energies(y).values()) + sum(self.stored_energies(y).values())
