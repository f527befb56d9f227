"""The reference's mechanism: bodies, connectors, modes and the right-hand side, effect-free.

Written from DESIGN.md ("Bodies and connectors").  Every body moves on the recoil axis (x positive in
the recoil direction, 0 at the start).  Every force is a :class:`Connector` between points ``a`` and
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
* a connector's **kernel** for a state, ``apply(s, f, out) -> F``, reads positions and velocities from
  the list ``s`` (the state followed by the ground's ``x = v = 0``), adds ``+F`` to ``f[a]`` and ``-F`` to
  ``f[b]`` (``f`` has one slot per body and a last one for the ground, which so collects S), writes its
  dissipated power to ``out`` and returns ``F``.  The same kernel runs
  on Python floats (the integrator's right-hand side: ~10^4-10^5 calls per run, numpy scalar arithmetic
  would be 5x slower) and on numpy rows (post-processing): only the few operations in :data:`SCALAR` and
  :data:`ARRAY` differ.  A kernel marked ``constraint`` (a sliding contact) runs after the others: its
  force depends on theirs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

#: The name of the ground as a connector end.
GROUND = "ground"
#: The barrel's body name (always body 0).
BARREL = "barrel"


class ReferenceModelError(ValueError):
    """The scene cannot be modelled by the reference (a table without a reference term, a bad name)."""


class _ScalarOps:
    """Operations on Python floats (the right-hand side)."""

    name = "scalar"

    @staticmethod
    def spow(p, n):
        """``sign(p) |p|^n`` (m^n)."""
        return math.copysign(abs(p) ** n, p)


class _ArrayOps:
    """The same operations on numpy arrays (post-processing, event functions on the dense output)."""

    name = "array"

    @staticmethod
    def spow(p, n):
        """``sign(p) |p|^n`` (m^n)."""
        return np.copysign(np.abs(p) ** n, p)


SCALAR = _ScalarOps()
ARRAY = _ArrayOps()


@dataclass(frozen=True)
class Body:
    """A mass on the recoil axis: ``name``, ``mass`` (kg), ``initial_velocity`` (m/s); it starts at x = 0."""

    name: str
    mass: float
    initial_velocity: float = 0.0


def _difference(ia: int | None, ib: int | None) -> Callable:
    """``y -> y[ib] - y[ia]`` with ``None`` standing for the ground (0): works on (n,) and (n, N)."""
    if ia is None:
        return lambda y: y[ib]
    if ib is None:
        return lambda y: -y[ia]
    return lambda y: y[ib] - y[ia]


class Connector:
    """A force between points ``a`` and ``b`` (body names or :data:`GROUND`); see the module docstring.

    Subclasses (in the term modules) give the law: :meth:`kernel` per state, and what the solver, the
    result and the early stop need.  Class attributes:

    * ``is_contact`` -- a contact (episodes, impacts, onsets are reported for it);
    * ``dissipates`` -- it has a dissipated-energy state (set per instance where it depends on values);
    * ``stores_energy`` -- it has a potential U(d);
    * ``injects_energy`` -- its law can add energy (the early stop has no bound then);
    * ``classify_pass`` -- 0: no discrete state; 1: decided on the accelerations *without* its own force
      (contacts); 2: decided on the accelerations of the classified mode (velocity-sign switches).
    """

    is_contact = False
    dissipates = False
    stores_energy = False
    classify_pass = 0
    injects_energy = False

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
    def kernel(self, state, ops) -> Callable | None:
        """``apply(s, f, out) -> F`` in ``state`` (see the module docstring); None: no force, no power."""
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
    """Everything the kernels give at a state (floats) or a batch (arrays).

    ``forces[j]``: raw force of connector j (N, unclipped: the segment's smooth law); ``accelerations[i]``
    (m/s^2); ``powers``: the time derivative of the state (only the dissipated powers, W, are filled at
    their indices); ``support``: S (N) from the raw forces.
    """

    forces: list
    accelerations: list
    powers: list
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
        self._kernels: dict = {}

    # ------------------------------------------------------------------ state
    def initial_state(self) -> np.ndarray:
        """y(0): every body at 0 with its initial velocity, no dissipated energy."""
        y = np.zeros(self.n_states)
        for i, body in enumerate(self.bodies):
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

    # ------------------------------------------------------------------ kernels
    def kernels(self, mode: Mode, ops) -> list[tuple[int, Callable]]:
        """``(connector index, apply)`` of every force-giving connector in ``mode``, constraints last."""
        key = (mode, ops.name)
        cached = self._kernels.get(key)
        if cached is None:
            pairs = [(j, c.kernel(state, ops)) for j, (c, state) in enumerate(zip(self.connectors, mode.states))]
            pairs = [(j, k) for j, k in pairs if k is not None]
            cached = ([p for p in pairs if not getattr(p[1], "constraint", False)]
                      + [p for p in pairs if getattr(p[1], "constraint", False)])
            self._kernels[key] = cached
        return cached

    def rhs(self, mode: Mode) -> Callable:
        """``f(t, y) -> dy/dt`` in ``mode`` on Python floats (an overflow gives inf, as numpy would)."""
        applies = [k for _, k in self.kernels(mode, SCALAR)]
        n, nb, masses = self.n_states, self.n_bodies, self.masses
        nf, body_end = nb + 1, 2 * nb
        ground = [0.0, 0.0]

        def rhs(t, y):
            try:
                s = y.tolist()
                s += ground
                f = [0.0] * nf
                out = [0.0] * n
                for apply in applies:
                    apply(s, f, out)
                out[0:body_end:2] = s[1:body_end:2]
                out[1:body_end:2] = [fi / m for fi, m in zip(f, masses)]
                return np.array(out)
            except OverflowError:
                # a rejected trial step of an explicit method on a stiff contact: numpy gave inf here, and
                # so does this; the integrator rejects the step (its error estimate is inf)
                return np.full(n, np.inf)
        return rhs

    def evaluate(self, mode: Mode, y, omit: int | None = None) -> Evaluation:
        """Forces, accelerations, dissipated powers and support force at a state ``y`` (n,) -- on Python
        floats -- or a batch (n, N) -- on numpy rows.  ``omit``: leave out connector ``omit``'s force."""
        scalar = np.ndim(y) == 1
        ops = SCALAR if scalar else ARRAY
        s = np.asarray(y, dtype=float).tolist() if scalar else list(np.asarray(y, dtype=float))
        s += [0.0, 0.0]
        nb = self.n_bodies
        f = [0.0] * (nb + 1)
        out = [0.0] * self.n_states
        forces = [0.0] * len(self.connectors)
        for j, apply in self.kernels(mode, ops):
            if j != omit:
                forces[j] = apply(s, f, out)
        accelerations = [fi / m for fi, m in zip(f, self.masses)]
        return Evaluation(forces, accelerations, out, f[nb])

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
