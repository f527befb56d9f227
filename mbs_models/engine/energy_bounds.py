"""Energy bounds on everything a dissipative scene can still do, from the state at one instant.

The early stop (:mod:`.finality`), the reach of a scene (:mod:`.reach`) and the rest detection (:mod:`.rest`)
build on these bounds.

Energy
------
The mechanical energy (J) is ``E = sum_i m_i v_i^2 / 2 + sum_c U_c(d_c)``: the kinetic energy of every
body and the stored energy of every connector (springs ``k d^2 / 2``, contacts' elastic energy).  Its
rate is minus the dissipated power of the connectors, which is >= 0 for every element: dampers
``c d'^2``; every contact law ``(F - F_elastic) p' >= 0`` (damping during compression and restitution,
and where the force is clipped to 0 the elastic part ``-F_elastic p'`` with ``p' < 0``).  So **E never
increases** -- except under the paper's reading ``literal_lambda_sign``, which injects energy: then no
bound holds and :func:`dissipative` is False (such scenes always run to their end time).

Bounds (every term of E is >= 0, so each is <= E(t) at every later time)
-----------------------------------------------------------------------
* **Linear springs**: ``sum_c k_c (c.x)^2 <= 2E`` is a positive semi-definite quadratic form
  ``x^T K x <= 2E`` (x: body positions).  The largest value of a linear combination ``g.x`` under it is
  ``sqrt(2E g^T K^+ g)`` when g lies in the range of K (``K^+`` the pseudo-inverse), none otherwise.
  For the paper's models: ``x_M <= sqrt(2E/k)``; ``x_M - x_m <= sqrt(2E/k_r)`` (absorber on the barrel)
  or ``sqrt(2E (1/k + 1/k_r))`` (on the ground).
* **Contacts**: a contact's own elastic energy bounds its penetration, ``p <= ((n+1) E / k)^(1/(n+1))``;
  and ``p = d - offset <= (bound on d) - offset``: no contact is reachable once that is <= 0.  A recoil
  stop bounds ``x_M <= position + p_max`` too.
* **Velocities**: ``|v_i| <= sqrt(2E/m_i)``, ``|v_b - v_a| <= sqrt(2E (1/m_b + 1/m_a))``.  A body tied to
  the ground by springs and dampers only, whose contacts are unreachable, is a free damped oscillator
  whose own energy never increases: ``|v_i| <= sqrt(2 E_i / m_i)``.
* **Forces**: each connector bounds its force from the bounds on d and d' (a spring ``k |d|``, a damper
  ``c |d'|``, a contact ``k p^n (1 + lambda |p'|)``, with lambda = chi / minimum_impact_velocity for the
  restitution laws); the force on the mount by the sum over the connectors touching the ground.

A potential that is not a quadratic form (the recuperator's gas spring)
---------------------------------------------------------------------
A connector with ``quadratic_potential = False`` has a nonlinear potential that may be negative (the gas
spring ``U(d) = integral_0^d F``, with ``F > 0``, is negative where the preload holds the barrel forward of
battery), so "every term <= E" fails.  Such connectors between the ground and one body b, together with
b's contacts with the ground (the stops), form a **potential well** ``W(x_b) = sum U_c(+-x_b)``: convex
(each ``U_c`` is, its force being non-decreasing in ``d``), with a minimum ``W*`` at the static
equilibrium ``W'(x*) = 0`` (:class:`PotentialWell`).  Every other term of E is >= 0, and so is ``W - W*``;
so with the energy above the floor, ``E' = E - W*`` (>= 0), every bound above holds with E' in place of
E, and the well adds its own: ``W(x_b) <= W* + E'`` confines ``x_b`` to the sublevel interval
``[lo(E'), hi(E')]`` of W (found by root finding; ``hi < V0/A`` for the gas spring, whose potential
diverges there).  That interval bounds x_b (``x_M <= hi``), every member's coordinate (a stop's
penetration, the gas spring's stroke, hence their forces).  The numerical slack applies to E'.

Such a potential anywhere else (between two bodies, or from the ground to a second body) is a **loose
well** of its own coordinate: ``U_c(d) >= U*_c``, its minimum where ``F_c(d*, 0) = 0`` (a progressive spring
between the barrel and an absorber: ``U* = 0`` at d = 0).  The floor is then ``W* + sum_c U*_c``, E' the
energy above it, and ``U_c(d) <= U*_c + E'`` bounds the connector's d (its force bound, if it touches the
ground).  A potential without a minimum (or a well with none) leaves the scene without bounds: it runs to
its end time.  Both wells assume what the contract's conformance suite checks on samples: ``F(d, 0)``
non-decreasing (a convex U), so that Newton's method from outside a sublevel interval stays outside.

External inputs: a shot of a burst and a breech-force pulse add energy; the bounds are applied only
to states after the last of them (:attr:`Mechanism.last_input_time`); a load that never ends (gravity
along an inclined cradle) leaves the scene without a bound (:func:`dissipative` is False).

Numerical slack: a numerical solution dissipates energy only up to its integration error, so the
bounds use ``E (1 + ENERGY_SLACK)`` (``W* + E' (1 + ENERGY_SLACK)`` with a potential well).
:func:`mbs_models.simulate` trusts an early stop only if the solution's energy (above the well's floor)
rose by no more than that fraction anywhere in the simulated window (:func:`largest_energy_rise`), and
otherwise re-solves to the end time.
"""

from __future__ import annotations

import math

import numpy as np

from ..elements.connector import GROUND
from ..scene import Scene
from .mechanism import Mechanism

#: Relative margin on the energy in every bound: covers the integration error of the solution's
#: energy (a relative rise of ~1e-9 per step at the presets' tolerances; see largest_energy_rise).
ENERGY_SLACK = 1e-4
#: Eigenvalues of the stiffness form below this fraction of the largest count as zero.
_RANK_TOLERANCE = 1e-12


def dissipative(scene: Scene | Mechanism) -> bool:
    """True when the scene's mechanical energy never increases after its last external input: every
    reading but literal_lambda_sign, and no load that acts for ever (gravity along an inclined cradle).
    Give the scene's :class:`Mechanism` if you have one (building one solves a preload's equilibrium)."""
    mechanism = scene if isinstance(scene, Mechanism) else None
    scene = mechanism.scene if mechanism is not None else scene
    if scene.conventions.literal_lambda_sign:
        return False
    return math.isfinite((mechanism or Mechanism(scene)).last_input_time)


def connector_ends(mechanism: Mechanism, connector) -> tuple[int | None, int | None]:
    """``(a, b)``: the body indices of a connector's ends, None for the ground, so that
    ``d = (x[b] if b is not None else 0.0) - (x[a] if a is not None else 0.0)`` is
    :meth:`Mechanism.relative_at` with the lookups done once."""
    index = mechanism.body_index
    return (None if connector.a == GROUND else index[connector.a], None if connector.b == GROUND else index[connector.b])


def _stiffness_matrix(mechanism: Mechanism) -> np.ndarray:
    """K (N/m, bodies x bodies) of the connectors with a quadratic potential: ``sum k g g^T``, g their direction."""
    n = len(mechanism.bodies)
    K = np.zeros((n, n))
    for connector in mechanism.connectors:
        k = connector.quadratic_stiffness if connector.quadratic_potential else 0.0
        if k > 0:
            g = mechanism.direction(connector)
            K += k * np.outer(g, g)
    return K


class _QuadraticForm:
    """``x^T K x <= 2E`` of the linear springs: bound coefficients ``2 g^T K^+ g`` of linear combinations.

    :meth:`of` gives the form of a mechanism, the same object for the same K (a sweep's points share their
    springs: the eigendecomposition and the coefficients are computed once for them)."""

    #: K (its shape and bytes) -> the form, the :data:`_KEPT` latest
    _kept: dict[tuple, "_QuadraticForm"] = {}
    _KEPT = 64

    @classmethod
    def of(cls, mechanism: Mechanism) -> "_QuadraticForm":
        """The form of the mechanism's linear springs (a kept one for the same K)."""
        K = _stiffness_matrix(mechanism)
        key = (len(K), K.tobytes())
        form = cls._kept.get(key)
        if form is None:
            if len(cls._kept) >= cls._KEPT:
                del cls._kept[next(iter(cls._kept))]
            form = cls._kept[key] = cls(K)
        return form

    def __init__(self, springs: Mechanism | np.ndarray):
        """The form of a mechanism's linear springs, or of the stiffness matrix K (N/m, bodies x bodies)."""
        K = _stiffness_matrix(springs) if isinstance(springs, Mechanism) else np.asarray(springs, dtype=float)
        n = len(K)
        values, vectors = np.linalg.eigh(K)
        scale = max(float(np.max(np.abs(values))), 0.0) if n else 0.0
        self._keep = values > _RANK_TOLERANCE * scale if scale > 0 else np.zeros(n, dtype=bool)
        self._values, self._vectors = values, vectors
        self._coefficients: dict[tuple[float, ...], float] = {}  # g -> coefficient(g): connectors share directions

    def coefficient(self, g: np.ndarray) -> float:
        """``2 g^T K^+ g`` (so that ``|g.x| <= sqrt(coefficient E)``), or inf if g is not in K's range."""
        key = tuple(g.tolist())
        if key not in self._coefficients:
            self._coefficients[key] = self._coefficient(g)
        return self._coefficients[key]

    def _coefficient(self, g: np.ndarray) -> float:
        components = self._vectors.T @ g
        outside = components[~self._keep]
        if outside.size and float(np.max(np.abs(outside))) > 1e-9 * max(float(np.max(np.abs(g))), 1.0):
            return math.inf
        inside = components[self._keep]
        with np.errstate(over="ignore"):  # a spring too weak for double precision: no bound (inf)
            return 2.0 * float(np.sum(inside * inside / self._values[self._keep]))

    def null_space(self) -> np.ndarray:
        """Orthonormal columns spanning K's null space (the position changes no spring resists), shape
        (bodies, dimension)."""
        return self._vectors[:, ~self._keep]


def general_potentials(mechanism: Mechanism) -> list:
    """The connectors whose potential is given as a function (not a quadratic form, not a contact's)."""
    return [c for c in mechanism.connectors if c.stores_energy and not c.is_contact and not c.quadratic_potential]


class PotentialWell:
    """The potential well ``W(x) = sum_c U_c(s_c x)`` of one body b (module docstring): its connectors to the
    ground whose potential is not a quadratic form, and its contacts with the ground; ``s_c = +1`` for
    ground -> b (``d = x``), -1 for b -> ground (``d = -x``).  W is convex; ``W'(x) = sum_c s_c F_c(s_c x)``,
    each connector's force at rest.

    :meth:`of` returns None for a scene without such a connector, and a well with :attr:`minimum` ``-inf``
    (no bound at all) where one exists but no well can be formed or W has no minimum.
    """

    #: Largest |x| (m) searched for a minimum or a sublevel end: beyond it the well has no bound.
    REACH = 1e6

    def __init__(self, mechanism: Mechanism, general: list):
        self.body = None
        self.members: list = []
        self.minimum = -math.inf
        ends = {c.b if c.a == GROUND else c.a for c in general}
        if any(GROUND not in (c.a, c.b) for c in general) or len(ends) != 1:
            return
        body = ends.pop()
        self.body = mechanism.body_index[body]
        self.members = general + [c for c in mechanism.contacts if {c.a, c.b} == {GROUND, body}]
        self.signs = [1.0 if c.a == GROUND else -1.0 for c in self.members]
        low, high = -math.inf, math.inf
        for c, s in zip(self.members, self.signs):
            d_low, d_high = c.coordinate_range
            low, high = (max(low, d_low), min(high, d_high)) if s > 0 else (max(low, -d_high), min(high, -d_low))
        self.domain = (low, high)
        self._ends: dict[float, tuple[float, float]] = {}   # side -> (excess, end) of the last call
        found = self._minimise()
        if found is not None:
            self.argmin, self.minimum = found
            self._ends = {-1.0: (0.0, self.argmin), 1.0: (0.0, self.argmin)}

    @classmethod
    def of(cls, mechanism: Mechanism) -> "PotentialWell | None":
        """The well of the general potentials between the ground and one body (the body of the first such
        connector; those of other bodies are :meth:`loose`); None without any."""
        grounded = [c for c in general_potentials(mechanism) if GROUND in (c.a, c.b)]
        if not grounded:
            return None
        first = grounded[0].b if grounded[0].a == GROUND else grounded[0].a
        return cls(mechanism, [c for c in grounded if first in (c.a, c.b)])

    @classmethod
    def loose(cls, mechanism: Mechanism, well: "PotentialWell | None") -> list["PotentialWell"]:
        """One well per general potential outside ``well`` (between two bodies, or from the ground to another
        body): ``W(d) = U_c(d)`` in the connector's own coordinate (:meth:`of_connector`)."""
        return [cls.of_connector(c) for c in general_potentials(mechanism) if well is None or c not in well]

    @classmethod
    def of_connector(cls, connector) -> "PotentialWell":
        """The well ``W(d) = U(d)`` of one connector in its own coordinate d (sign +1, no body): its minimum
        ``U*`` at ``F(d*, 0) = 0`` (-inf where U has none), its sublevel interval bounding d."""
        well = cls.__new__(cls)
        well.body, well.members, well.signs = None, [connector], [1.0]
        well.minimum = -math.inf
        well.domain = connector.coordinate_range
        well._ends = {}
        found = well._minimise()
        if found is not None:
            well.argmin, well.minimum = found
            well._ends = {-1.0: (0.0, well.argmin), 1.0: (0.0, well.argmin)}
        return well

    def __contains__(self, connector) -> bool:
        return any(connector is c for c in self.members)

    def sign(self, connector) -> float:
        """``s_c``: +1 if the connector's d is x_b, -1 if it is -x_b."""
        return next(s for c, s in zip(self.members, self.signs) if c is connector)

    def potential(self, x: float) -> float:
        """W(x) in J."""
        return sum(c.python_stored_energy(s * x) for c, s in zip(self.members, self.signs))

    def slope(self, x: float) -> float:
        """W'(x) in N: the members' forces at rest, ``sum s_c F_c(s_c x, 0)``."""
        return sum(s * c.python_force(s * x, 0.0) for c, s in zip(self.members, self.signs))

    def _towards(self, start: float, direction: float, done) -> tuple[float, float] | None:
        """(last point where ``done`` is False, first point where it is True) walking from ``start`` in
        ``direction`` by doubling steps, or towards a domain end in halving gaps; None if never True."""
        previous, step = start, 1e-9
        edge = self.domain[1] if direction > 0 else self.domain[0]
        for _ in range(200):
            if math.isfinite(edge):
                x = previous + 0.5 * (edge - previous) if abs(edge - start) <= step else start + direction * step
            else:
                x = start + direction * step
            if abs(x) > self.REACH or x == previous:
                return None
            if done(x):
                return previous, x
            previous, step = x, 2.0 * step
        return None

    def _minimise(self) -> tuple[float, float] | None:
        """(x*, W*): the root of the non-decreasing W' (Brent's method to round-off), None without one."""
        if not self.domain[0] < 0.0 < self.domain[1]:
            return None
        start = 0.0
        if self.slope(start) == 0.0:
            return start, self.potential(start)
        direction = -1.0 if self.slope(start) > 0 else 1.0
        found = self._towards(start, direction, lambda x: self.slope(x) * direction >= 0.0)
        if found is None:
            return None
        a, b = sorted(found)
        from scipy.optimize import brentq  # here: scipy.optimize costs ~0.4 s to import, and few scenes get here

        x = brentq(self.slope, a, b, xtol=1e-300, rtol=4.0 * np.finfo(float).eps, maxiter=500)
        return x, self.potential(x)

    def end(self, direction: float, excess: float) -> float:
        """The end (m) of the sublevel interval ``W(x) <= W* + excess`` (J, the energy above the floor) on
        the side ``direction`` (-1: lo, +1: hi); infinite where W never reaches that level.

        W is convex, so Newton's method started outside the interval (where W >= the level) stays outside
        and converges to the end from there: the result is a bound, not an estimate.  The start is the
        previous end on that side when the level fell since (the energy mostly decreases), else the first
        point outside found by doubling steps from there (or from x*).
        """
        if not excess > 0.0:
            return self.argmin
        if not math.isfinite(excess):
            return direction * math.inf
        last_excess, last = self._ends[direction]
        if excess == last_excess:
            return last
        level = self.minimum + excess

        def above(x: float) -> float:
            return self.potential(x) - level

        x = last if math.isfinite(last) else self.argmin
        if not self.domain[0] < x < self.domain[1]:  # the last end was the law's singularity
            if excess >= last_excess:
                self._ends[direction] = (excess, x)
                return x
            x = self.argmin
        value = above(x)
        if value < 0.0:
            found = self._towards(x, direction, lambda y: above(y) >= 0.0)
            if found is None:
                self._ends[direction] = (excess, direction * math.inf)
                return direction * math.inf
            x = found[1]
            if not self.domain[0] < x < self.domain[1]:  # within round-off of the law's singularity
                self._ends[direction] = (excess, x)
                return x
            value = above(x)
        for _ in range(200):
            slope = direction * self.slope(x)
            if not (value > 0.0 and slope > 0.0):
                break
            trial = x - direction * value / slope
            trial_value = above(trial)
            if trial_value < 0.0:  # converged: round-off put the step inside; the end is a few ulps outward
                for _ in range(64):
                    trial = math.nextafter(trial, direction * math.inf)
                    if above(trial) >= 0.0:
                        if direction * (x - trial) > 0.0:
                            x = trial
                        break
                break
            if trial == x:
                break
            x, value = trial, trial_value
        self._ends[direction] = (excess, x)
        return x

    def interval(self, excess: float) -> tuple[float, float]:
        """``[lo, hi]`` (m): where ``W(x) <= W* + excess`` (J; see :meth:`end`)."""
        return self.end(-1.0, excess), self.end(1.0, excess)

    def upper(self, connector, excess: float) -> float:
        """Bound (m) on a member's d = s x (the upper end of s [lo, hi])."""
        return self.end(1.0, excess) if self.sign(connector) > 0 else -self.end(-1.0, excess)

    def magnitude(self, connector, excess: float) -> float:
        """Bound (m) on a member's |d|: ``max(|lo|, |hi|)``."""
        low, high = self.interval(excess)
        return max(abs(low), abs(high))


class EnergyBounds:
    """The bounds of the module docstring for one scene, as functions of the energy ``E`` (J) now.

    Every bound holds at *every later time* of a :func:`dissipative` scene (``math.inf`` where none
    exists, e.g. along a direction without a spring).  States are body positions ``x`` and velocities
    ``v`` in body order (m, m/s; plain sequences).  The scene's numbers are folded into a few
    coefficients once, so that a call costs microseconds.
    """

    def __init__(self, scene: Scene | Mechanism):
        mechanism = scene if isinstance(scene, Mechanism) else Mechanism(scene)
        self.mechanism = mechanism
        self.scene = mechanism.scene
        form = _QuadraticForm.of(mechanism)
        index = mechanism.body_index
        self.masses = [b.mass for b in mechanism.bodies]
        self._half_masses = [0.5 * m for m in self.masses]
        # energy terms, grouped by element as they are summed (see energy())
        self._groups = []
        for element in mechanism.elements:
            kinetic = [index[b.name] for b in element.bodies]
            springs = [c for c in element.connectors if c.stores_energy and not c.is_contact and c.quadratic_potential]
            contacts = [c for c in element.connectors if c.is_contact]
            general = [c for c in element.connectors
                       if c.stores_energy and not c.is_contact and not c.quadratic_potential]
            self._groups.append((kinetic, springs, contacts, general))
        #: :meth:`energy`'s terms with their numbers looked up once, element by element (elements without a
        #: term left out: they add nothing): ``(kinetic, springs, potentials)`` with kinetic ``(i, m_i / 2)``,
        #: springs ``(a, b, k / 2)`` and potentials ``(a, b, U)`` (the contacts' elastic energy, then the
        #: other potentials); ``a``, ``b``: :func:`connector_ends`.
        self._energy_terms = tuple(
            (tuple((i, self._half_masses[i]) for i in kinetic),
             tuple(connector_ends(mechanism, c) + (0.5 * c.quadratic_stiffness,) for c in springs),
             tuple(connector_ends(mechanism, c) + (c.python_elastic,) for c in contacts)
             + tuple(connector_ends(mechanism, c) + (c.python_stored_energy,) for c in general))
            for kinetic, springs, contacts, general in self._groups if kinetic or springs or contacts or general)
        #: the potential well of a connector whose potential is not a quadratic form (None: there is none)
        self.well = PotentialWell.of(mechanism)
        #: one well per general potential outside :attr:`well` (module docstring: their minima join the floor)
        self.loose = PotentialWell.loose(mechanism, self.well)
        self._floor = (0.0 if self.well is None else self.well.minimum) + sum(w.minimum for w in self.loose)
        self._barrel_coefficient = form.coefficient(np.eye(len(self.masses))[0]) if self.masses else math.inf
        self.contacts = mechanism.contacts
        self._contact_coefficients = [form.coefficient(mechanism.direction(c)) for c in self.contacts]
        self._rate_coefficients = [self._rate_coefficient(c) for c in self.contacts]
        self._barrel_stops = [c for c in self.contacts if c.a == GROUND and c.b == mechanism.bodies[0].name]
        #: the recoil stops outside the potential well (the well's interval bounds the others): barrel_displacement
        self._barrel_stops_outside_well = [c for c in self._barrel_stops if not self._in_well(c)]
        #: a potential well of the barrel's (its upper end bounds x_M): barrel_displacement
        self._well_on_barrel = self.well is not None and self.well.body == 0
        ground = [c for c in mechanism.connectors if GROUND in (c.a, c.b)]
        self._ground = [(c, form.coefficient(mechanism.direction(c)), self._rate_coefficient(c)) for c in ground]
        self._free_oscillators = self._find_free_oscillators(mechanism)
        self._loose_of = {id(w.members[0]): w for w in self.loose}

    def _rate_coefficient(self, connector) -> float:
        """``2 (1/m_b + 1/m_a)`` (the ground's term left out): ``|d'| <= sqrt(coefficient E)``."""
        m = self.mechanism
        inverse = 0.0
        for point in (connector.b, connector.a):
            if point != GROUND:
                inverse += 1.0 / m.bodies[m.body_index[point]].mass
        return 2.0 * inverse

    @staticmethod
    def _find_free_oscillators(mechanism: Mechanism) -> dict[int, tuple[list, list]]:
        """Bodies tied to the ground only, by connectors whose potential is a quadratic form or none (besides
        contacts): index -> (their connectors, their contacts).  (A potential given as a function may be
        negative: the body's own energy would then bound nothing.)"""
        out = {}
        for i, body in enumerate(mechanism.bodies):
            touching = [c for c in mechanism.connectors if body.name in (c.a, c.b)]
            contacts = [c for c in touching if c.is_contact]
            others = [c for c in touching if not c.is_contact]
            if i > 0 and all(GROUND in (c.a, c.b) and (c.quadratic_potential or not c.stores_energy)
                             for c in others):
                out[i] = (others, contacts)
        return out

    # ---------------------------------------------------------------------------- the state
    def energy(self, x, v) -> float:
        """E in J at the state (body positions m, velocities m/s, in body order).

        Summed element by element (an element's bodies and springs first, then its contacts).
        Every term is evaluated as ``m_i / 2 * v_i * v_i``, ``k / 2 * d * d`` (``d = x_b - x_a``, 0 for the
        ground), in this order, so that the sum is the same float whatever calls it.
        """
        energy = 0.0
        for kinetic, springs, potentials in self._energy_terms:
            if kinetic or springs:
                part = None
                for i, half_mass in kinetic:
                    term = half_mass * v[i] * v[i]
                    part = term if part is None else part + term
                for a, b, half_stiffness in springs:
                    d = (x[b] if b is not None else 0.0) - (x[a] if a is not None else 0.0)
                    term = half_stiffness * d * d
                    part = term if part is None else part + term
                energy += part
            for a, b, potential in potentials:
                energy += potential((x[b] if b is not None else 0.0) - (x[a] if a is not None else 0.0))
        return energy

    # ---------------------------------------------------------------------------- the energy above the floor
    @property
    def energy_floor(self) -> float:
        """A lower bound (J) of the stored energy over all states: 0, or the minima of the potential wells
        (the well's W* plus every loose potential's U*; -inf where one has none)."""
        return self._floor

    def with_slack(self, energy: float) -> float:
        """The energy (J) the bounds are evaluated at: ``E (1 + ENERGY_SLACK)``, or ``floor + (E - floor) (1 +
        ENERGY_SLACK)`` with potential wells (the integration error scales with the energy above the floor)."""
        if self.well is None and not self.loose:
            return energy * (1.0 + ENERGY_SLACK)
        if not math.isfinite(self._floor):
            return energy
        return self._floor + (energy - self._floor) * (1.0 + ENERGY_SLACK)

    def _excess(self, energy: float) -> float:
        """``E' = E - floor`` (J, >= 0): the bound on every non-negative term of E (``max(E, 0)`` without a
        well; inf where a potential given as a function has no minimum)."""
        if self.well is None and not self.loose:
            return max(energy, 0.0)
        if not math.isfinite(self._floor):
            return math.inf
        return max(energy - self._floor, 0.0)

    def contact_force(self, contact, x, v) -> float:
        """The force (N) of a contact at the state, with its current onset rate."""
        m = self.mechanism
        return contact.python_force(m.relative_at(contact, x), m.relative_at(contact, v))

    def support_force(self, x, v) -> float:
        """The force on the mount (N, positive in the recoil direction) at the state."""
        m = self.mechanism
        total = 0.0
        for c, _, _ in self._ground:
            total += c.support_sign * c.python_force(m.relative_at(c, x), m.relative_at(c, v))
        return total

    def oscillator_energy(self, i: int, x, v) -> float:
        """Energy (J) of body ``i`` with its ground connectors: its own, if it is a free oscillator."""
        connectors, _ = self._free_oscillators[i]
        m = self.mechanism
        energy = self._half_masses[i] * v[i] * v[i]
        for c in connectors:
            if c.stores_energy:
                d = m.relative_at(c, x)
                energy += 0.5 * c.quadratic_stiffness * d * d
        return energy

    # ---------------------------------------------------------------------------- bounds
    def _in_well(self, connector) -> bool:
        return self.well is not None and connector in self.well

    def barrel_displacement(self, energy: float) -> float:
        """Bound (m) on x_M: the springs', every recoil stop's and a potential well's; inf without any."""
        e = self._excess(energy)
        bound = math.sqrt(self._barrel_coefficient * e)
        for stop in self._barrel_stops_outside_well:
            bound = min(bound, stop.offset + stop.penetration_bound(e))
        if self._well_on_barrel:
            bound = min(self.well.end(1.0, e), bound)  # (bound is nan for inf * 0: no spring on the barrel, E' = 0)
        return bound

    def body_velocity(self, i: int, energy: float) -> float:
        """Bound (m/s) on ``|v_i|``."""
        return math.sqrt(2.0 / self.masses[i] * self._excess(energy))

    def velocity_from_own_energy(self, i: int, own: float) -> float:
        """Bound (m/s) on ``|v_i|`` of a free oscillator from its own energy ``own`` (J, >= 0)."""
        return math.sqrt(2.0 / self.masses[i] * max(own, 0.0))

    def contact_coordinate(self, j: int, energy: float) -> float:
        """Bound (m) on contact ``j``'s relative coordinate ``|d|`` (= x_M - x_m for an absorber) from the springs
        (from its potential well: ``max(|lo|, |hi|)``)."""
        if self._in_well(self.contacts[j]):
            return self.well.magnitude(self.contacts[j], self._excess(energy))
        return math.sqrt(self._contact_coefficients[j] * self._excess(energy))

    def _upper(self, j: int, energy: float) -> float:
        """Bound (m) on contact ``j``'s d (signed: a well member's upper end of d)."""
        if self._in_well(self.contacts[j]):
            return self.well.upper(self.contacts[j], self._excess(energy))
        return math.sqrt(self._contact_coefficients[j] * self._excess(energy))

    def contact_reach(self, j: int, energy: float) -> float:
        """Bound (m) on contact ``j``'s relative coordinate d at every later time (the contact closes where
        ``d > offset``): ``sqrt(2E g^T K^+ g)`` from the springs, a potential well's end, inf without a bound."""
        return self._upper(j, energy)

    def contact_reachable(self, j: int, energy: float) -> bool:
        """Can contact ``j`` (index in :attr:`contacts`) close (p > 0) ever again?"""
        return self._upper(j, energy) > self.contacts[j].offset

    def penetration(self, j: int, energy: float) -> float:
        """Bound (m) on contact ``j``'s penetration (0 if it cannot close)."""
        e = self._excess(energy)
        relative = self._upper(j, energy)
        contact = self.contacts[j]
        if not relative > contact.offset:
            return 0.0
        if self._in_well(contact):  # its own potential is part of the well's: the interval bounds it
            return relative - contact.offset
        return min(contact.penetration_bound(e), relative - contact.offset)

    def penetration_rate(self, j: int, energy: float) -> float:
        """Bound (m/s) on contact ``j``'s ``|p'|``."""
        return math.sqrt(self._rate_coefficients[j] * self._excess(energy))

    def contact_force_bound(self, j: int, energy: float) -> float:
        """Bound (N) on contact ``j``'s force (0 if it cannot close)."""
        p = self.penetration(j, energy)
        if p <= 0.0:
            return 0.0
        return self.contacts[j].force_bound(p, self.penetration_rate(j, energy), energy)

    def support_force_bound(self, energy: float) -> float:
        """Bound (N) on ``|S|``: the sum of the force bounds of the connectors touching the ground."""
        e = self._excess(energy)
        total = 0.0
        contact_index = {id(c): j for j, c in enumerate(self.contacts)}
        for c, coefficient, rate_coefficient in self._ground:
            if c.is_contact:
                total += self.contact_force_bound(contact_index[id(c)], energy)
            elif self._in_well(c):  # |d| <= max(|lo|, |hi|) of the well's interval
                total += c.force_bound(self.well.magnitude(c, e), math.sqrt(rate_coefficient * e), e)
            elif id(c) in self._loose_of:  # |d| <= its own sublevel interval (and the springs' bound)
                d_bound = min(self._loose_of[id(c)].magnitude(c, e), math.sqrt(coefficient * e))
                total += c.force_bound(d_bound, math.sqrt(rate_coefficient * e), e)
            else:
                total += c.force_bound(math.sqrt(coefficient * e), math.sqrt(rate_coefficient * e), e)
        return total


def mechanical_energy(scene: Scene, x, v) -> float:
    """E in J at a state of ``scene`` (body positions m, velocities m/s, in body order); see :class:`EnergyBounds`."""
    return EnergyBounds(scene).energy(x, v)


def largest_energy_rise(energy) -> float:
    """Largest relative rise ``max_{i <= j} (E_j - E_i) / E_i`` of a sampled energy history (J).

    0 for a non-increasing history; inf if the energy rises from exactly 0.  This is the assumption
    behind every bound, checked on the simulated window.
    """
    e = np.asarray(energy, dtype=float)
    if e.size < 2:
        return 0.0
    future_max = np.maximum.accumulate(e[::-1])[::-1]
    rise = future_max - e
    if np.any((rise > 0) & (e <= 0)):
        return math.inf
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = np.where(rise > 0, rise / np.where(e > 0, e, 1.0), 0.0)
    return float(np.max(relative))
