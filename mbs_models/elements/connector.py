"""Bodies and connectors: what every element is made of, and what the engine iterates over.

A recoil mechanism here is one-dimensional: every :class:`Body` moves along the recoil axis
(position positive in the recoil direction, 0 at battery; a body starts at its ``initial_position``, 0
unless an element holds it elsewhere, see :meth:`~mbs_models.elements.table.Table.initial_positions`),
and every force acts between two points
of that axis -- two bodies, or a body and the ground (:data:`GROUND`).  Such a force is a
:class:`Connector` between point ``a`` and point ``b``::

    d  = x_b - x_a        relative coordinate (m)        d' = v_b - v_a  its rate (m/s)
    F  = force(d, d')     N, positive: pushes b towards -x and a towards +x (a stretched spring, a
                          compressed contact whose penetration grows with d)

exactly as Exudyn's ``ObjectConnectorCoordinateSpringDamper`` with markers ``[a, b]`` applies its
force.  From these two definitions everything generic follows and is written once:

* the force on the ground, positive in the recoil direction: ``+F`` if ``a`` is the ground, ``-F`` if
  ``b`` is (:attr:`Connector.support_sign`); the support force is their sum;
* stored energy ``U(d) = integral_0^d F(s, 0) ds`` and dissipated power ``(F(d, d') - F(d, 0)) d'``; their
  integrals close the energy balance per connector;
* each connector's share of the energy bounds of the early stop (a quadratic potential's stiffness, or
  its potential as a function) and its force bound given bounds on ``d`` and ``d'``.

Element modules subclass :class:`Connector` with a law of their own (the asymmetric recoil damper, the
contact laws) -- the law is the one mandatory part, the rest is derived from it (see :class:`Connector`) --
and use :class:`LinearSpringDamper`, Exudyn's built-in linear spring-damper, otherwise.
"""

from __future__ import annotations

import abc
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .ops import NUMPY_OPS, PYTHON_OPS, Ops, make_user_function, ops_for

#: The name of the ground as a connector end.
GROUND = "ground"


@dataclass(frozen=True)
class Body:
    """A mass on the recoil axis: ``name``, ``mass`` (kg), ``initial_velocity`` (m/s), ``initial_position`` (m;
    0 unless an element holds the body elsewhere at t = 0, e.g. a preload against the battery stop)."""

    name: str
    mass: float
    initial_velocity: float = 0.0
    element: str = ""
    initial_position: float = 0.0


#: ``quadrature(power_at_nodes) -> cumulative energy`` over the output samples (J): see
#: :func:`mbs_models.results.postprocess.cumulative_quadrature`.
Quadrature = Callable[[np.ndarray], np.ndarray]


class Connector(abc.ABC):
    """A force between points ``a`` and ``b`` of the recoil axis (see the module docstring): the element contract.

    The force law is the connector: everything else the engine, the post-processing and the early stop
    need is derived from it, unless the element gives it in closed form (which the conformance suite,
    ``tests/elements/test_conformance.py``, then checks against the derived one).

    To add a connector (a law of your own)
    ---------------------------------------
    1. Subclass :class:`Connector` and implement :meth:`law` ``(d, rate, ops) -> F`` in N, written over the
       backend ops (:mod:`.ops`: plain floats, numpy arrays, Exudyn symbolic expressions) so that one law runs
       in all three.  It is the one mandatory part: a subclass without it cannot be instantiated (TypeError
       when the scene is assembled), never a silent zero force.
    2. Call ``super().__init__(name, element, a, b)``.
    3. Declare what holds for your law (class attributes; the defaults are the safe ones):
       :attr:`monotone` (F non-decreasing in d and in rate: the force bound is then exact from two
       evaluations), :attr:`stores_energy` (False only if ``F(d, 0) = 0`` for every d: a pure damper),
       :attr:`coordinate_range` (where the law is defined).
    4. Optionally give closed forms, each of which replaces a derived default and is checked against it:
       :meth:`python_stored_energy` / :meth:`stored_energy` (default: the quadrature of ``F(s, 0)``),
       :meth:`tangent_stiffness` (default: a central difference), :meth:`force_bound` (default: the law at the
       corners of the box for a monotone law, else a dense sampling with a margin), and a quadratic potential
       (:attr:`quadratic_potential` with :attr:`quadratic_stiffness`: the energy bounds of the early stop then
       use it in their quadratic form; otherwise the potential enters them as a function).
       For sweeps (optional, nothing to do by default): :attr:`offset_in_item` if the law reads an ``offset``
       attribute only as ``d - offset`` and ``d > offset`` (its recording then serves every offset), and
       :attr:`law_state_ignores` naming attributes the law does not read (a kept item's recording serves any
       connector equal in the rest; :mod:`mbs_models.engine.law_state`).
    5. Write its reference term in ``validation/reference/terms`` (or register one from your module,
       :func:`validation.reference.terms.register_term`) and register the element's table
       (:func:`mbs_models.register_element` from outside the package).

    Derived pieces (the equations; DESIGN.md "The element contract")::

        conservative part   F_c(d)     = F(d, 0)
        stored energy       U(d)       = integral_0^d F_c(s) ds
        dissipated power    P(d, d')   = (F(d, d') - F_c(d)) d'
        tangent stiffness   k_t(d)     = dF_c/dd,  tangent damping  c_t = dF/dd' at (0, 0)
        force bound         B(D, V)   >= max |F(d, d')| over |d| <= D, |d'| <= V

    Attributes
    ----------
    name: unique id in the scene: the key of its energies and outputs (``"recoil_spring"``, ``"contact"``).
    element: the name of the scene element it belongs to (the per-element energy table groups by it).
    a, b: body names (or :data:`GROUND`) at the connector's two markers.
    records_force: a sensor records the force at every step (contacts: their force is an output).
    """

    #: The law runs as Exudyn's spring-force user function (False only for a law Exudyn has built in).
    needs_user_function = True
    records_force = False
    is_contact = False
    #: True for a law that can hold its bodies at rest anywhere in a band of positions (Coulomb friction): the
    #: scene then has no single rest state, and a solve is not stopped at rest (:mod:`mbs_models.engine.rest`).
    sticks = False
    #: True when ``F(d, d')`` is non-decreasing in ``d`` and in ``d'``: the derived force bound is then exact
    #: (the law at the box's corners ``(D, V)`` and ``(-D, -V)``).  False: a dense sampling with a margin.
    monotone = False
    #: True when the stored energy is the quadratic form ``quadratic_stiffness d^2 / 2`` (or none): the energy
    #: bounds of the early stop then use it as such.  False (the default) for any other potential, which the
    #: bounds take as a function (:class:`~mbs_models.engine.energy_bounds.PotentialWell`).
    quadratic_potential = False
    #: False only for a law whose conservative part ``F(d, 0)`` vanishes everywhere (a pure damper, friction).
    stores_energy = True
    #: True if the connector may dissipate energy (the default: the derived dissipated power is then integrated).
    dissipates = True
    #: True for a law whose ``offset`` attribute (m) enters only as ``d - offset`` and ``d > offset``: the Exudyn
    #: item then holds the offset and passes it to the user function, :meth:`user_function_law` returns
    #: ``f(d, rate, offset)``, and a sweep's kept item serves another offset without recording the law again
    #: (:mod:`mbs_models.engine.law_state`).  False (the default): ``f(d, rate)`` with every number in the law.
    offset_in_item = False
    #: Attributes the law does not read (kept for other uses: the table it was made from, say), left out when a
    #: sweep decides whether a kept item's recorded law serves this connector (:mod:`mbs_models.engine.law_state`).
    #: Leave empty unless every number the law reads is an attribute of its own (tested for the contacts).
    law_state_ignores: frozenset = frozenset()

    def __init__(self, name: str, element: str, a: str, b: str):
        if a == b:
            raise ValueError(f"connector {name!r} joins {a!r} to itself")
        self.name, self.element, self.a, self.b = name, element, a, b

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r}, {self.a} -> {self.b})"

    # ------------------------------------------------------------------ geometry
    @property
    def support_sign(self) -> float:
        """+1 if ``a`` is the ground, -1 if ``b`` is, 0 for a connector between two bodies."""
        return 1.0 if self.a == GROUND else (-1.0 if self.b == GROUND else 0.0)

    # ------------------------------------------------------------------ the law (mandatory)
    @abc.abstractmethod
    def law(self, d, rate, ops: Ops):
        """The force in N at relative coordinate ``d`` (m) and rate ``rate`` (m/s), over ``ops``."""

    def user_function_law(self, ops: Ops) -> Callable:
        """``f(d, rate)`` to record as Exudyn's spring-force user function (see :meth:`law`); ``f(d, rate,
        offset)`` for a connector with :attr:`offset_in_item`."""
        return lambda d, rate: self.law(d, rate, ops)

    def force(self, d, rate, t=None):
        """The force (N) on arrays of ``d`` (m), ``rate`` (m/s) at times ``t`` (s): numpy backend."""
        return self.law(d, rate, NUMPY_OPS)

    def python_force(self, d: float, rate: float) -> float:
        """The force (N) at one state (plain floats)."""
        return self.law(d, rate, PYTHON_OPS)

    def conservative_force(self, d: float) -> float:
        """``F_c(d) = F(d, 0)`` in N: the force at rest, whose integral is the stored energy."""
        return self.python_force(d, 0.0)

    # ------------------------------------------------------------------ Exudyn
    def builtin_coefficients(self) -> tuple[float, float]:
        """``(stiffness N/m, damping N s/m)`` of Exudyn's built-in linear law (0, 0 where a user function acts)."""
        return 0.0, 0.0

    def add_items(self, mbs, marker_a, marker_b, user_functions: str = "symbolic"):
        """Add the connector to an Exudyn system between two coordinate markers; return its ObjectIndex.

        An ``ObjectConnectorCoordinateSpringDamper`` with markers ``[marker_a, marker_b]``: Exudyn's
        built-in linear law (:meth:`builtin_coefficients`), or :meth:`user_function_law` as its spring-force
        user function (``user_functions``: ``"symbolic"`` -- recorded once, evaluated in C++ -- or
        ``"python"``).  The connector keeps the user function alive (:attr:`index` is the item).
        """
        index = add_connector_item(mbs, marker_a, marker_b, *self.builtin_coefficients())
        if self.offset_in_item:
            mbs.SetObjectParameter(index, "offset", self.offset)
        self._set_user_function(mbs, index, user_functions)
        self.index = index
        return index

    def update_items(self, mbs, index, user_functions: str = "symbolic") -> None:
        """Write this connector's numbers into ``index``, the item :meth:`add_items` made for a connector of
        the same class and ends (an earlier point of a sweep; :mod:`mbs_models.engine.reuse`).

        Afterwards the item is what :meth:`add_items` would have made: the built-in coefficients set, the
        user function (if any) recorded anew from this connector's law.  A subclass that adds other items
        overrides both methods.
        """
        stiffness, damping = self.builtin_coefficients()
        mbs.SetObjectParameter(index, "stiffness", stiffness)
        mbs.SetObjectParameter(index, "damping", damping)
        if self.offset_in_item:
            mbs.SetObjectParameter(index, "offset", self.offset)
        self._set_user_function(mbs, index, user_functions)
        self.index = index

    def _set_user_function(self, mbs, index, user_functions: str) -> None:
        """Record :meth:`user_function_law` as the item's spring-force user function (if the law needs one)."""
        if not self.needs_user_function:
            return
        self._user_function = record_spring_force_law(mbs, index, self.user_function_law(ops_for(user_functions)),
                                                      user_functions, with_offset=self.offset_in_item)

    # ------------------------------------------------------------------ energy (derived unless closed form)
    def python_stored_energy(self, d: float) -> float:
        """Stored energy ``U(d)`` in J at one ``d`` (m): :meth:`derived_stored_energy` unless closed form."""
        return self.derived_stored_energy(d)

    def stored_energy(self, d):
        """Stored energy in J at the ``d`` (m, an array or a float): :meth:`derived_stored_energy_array` unless
        closed form."""
        return self.derived_stored_energy_array(d)

    def derived_stored_energy(self, d: float) -> float:
        """``U(d) = integral_0^d F(s, 0) ds`` (J) by adaptive Gauss-Kronrod quadrature (scipy's ``quad``, to a
        relative 1e-12) on the pieces between the :attr:`kinks`; 0 for a connector that stores none, inf outside
        :attr:`coordinate_range`."""
        d = float(d)
        if not self.stores_energy or d == 0.0:
            return 0.0
        low, high = self.coordinate_range
        if not low < d < high:
            return math.inf
        from scipy.integrate import quad

        kinks = sorted(k for k in self.kinks if min(0.0, d) < k < max(0.0, d))
        value = 0.0
        for start, end in zip([0.0] + kinks if d > 0 else [0.0] + kinks[::-1], (kinks if d > 0 else kinks[::-1]) + [d]):
            piece, _ = quad(self.conservative_force, start, end, epsabs=0.0, epsrel=1e-12, limit=200)
            value += piece
        return float(value)

    def derived_stored_energy_array(self, d):
        """:meth:`derived_stored_energy` over an array of ``d`` (m) at once: the distinct values and 0 sorted,
        ``F(s, 0)`` integrated between neighbours (the :attr:`kinks` among them) by 8-point Gauss-Legendre (exact
        for a polynomial force up to degree 15) and summed outward from ``d = 0``."""
        array = np.asarray(d, dtype=float)
        if not self.stores_energy:
            return np.zeros_like(array)
        values = array.ravel()
        kinks = [k for k in self.kinks if values.size and float(np.min(values)) < k < float(np.max(values))]
        points, inverse = np.unique(np.concatenate((values, [0.0], kinks)), return_inverse=True)
        zero = int(np.searchsorted(points, 0.0))
        nodes, weights = np.polynomial.legendre.leggauss(8)
        left, right = points[:-1], points[1:]
        half = 0.5 * (right - left)
        s = (0.5 * (left + right))[:, None] + half[:, None] * nodes[None, :]
        forces = np.asarray(self.law(s, np.zeros_like(s), NUMPY_OPS), dtype=float) * np.ones_like(s)
        pieces = half * (forces @ weights)
        energy = np.zeros(points.size)  # summed outward from 0 on each side (no cancellation near d = 0)
        energy[zero + 1:] = np.cumsum(pieces[zero:])
        energy[:zero] = -np.cumsum(pieces[:zero][::-1])[::-1]
        return energy[inverse[:values.size]].reshape(array.shape)

    @property
    def coordinate_range(self) -> tuple[float, float]:
        """(lowest, highest) d in m where the law is defined (all of it, but for a gas spring's singularity)."""
        return -math.inf, math.inf

    @property
    def kinks(self) -> tuple[float, ...]:
        """The d (m) where ``F(d, 0)`` or its slope jumps (a contact's offset): the derived stored energy
        integrates piece by piece between them.  None for a smooth law (the default)."""
        return ()

    def dissipated_energy(self, quadrature: Quadrature, d_nodes, rate_nodes, times_nodes, stored):
        """Cumulative dissipated energy (J) at the output samples: ``(F(d, d') - F(d, 0)) d'`` integrated.

        ``d_nodes``, ``rate_nodes`` and ``times_nodes`` are values at each output interval's quadrature
        nodes (shape (nodes, intervals)); ``stored`` is :meth:`stored_energy` at the output samples.
        """
        power = (self.force(d_nodes, rate_nodes, times_nodes)
                 - self.force(d_nodes, np.zeros_like(rate_nodes), times_nodes)) * rate_nodes
        return quadrature(power)

    # ------------------------------------------------------------------ stiffness
    @property
    def quadratic_stiffness(self) -> float:
        """k (N/m) of a quadratic potential ``U = k d^2 / 2`` (:attr:`quadratic_potential`); 0 otherwise."""
        return 0.0

    def tangent_stiffness(self, d: float) -> float:
        """``dF(d, 0)/dd`` in N/m: :meth:`derived_tangent_stiffness` unless closed form."""
        return self.derived_tangent_stiffness(d)

    def derived_tangent_stiffness(self, d: float) -> float:
        """``(F(d + h, 0) - F(d - h, 0)) / (2 h)`` (N/m), ``h = 6e-6 max(|d|, 1 mm)`` (about the cube root of
        the double precision: truncation and round-off errors balance)."""
        h = 6e-6 * max(abs(d), 1e-3)
        return (self.python_force(d + h, 0.0) - self.python_force(d - h, 0.0)) / (2.0 * h)

    @property
    def linear_damping(self) -> float:
        """Damping (N s/m) of the linearised connector (stability checks): ``dF/dd'`` at rest, by a central
        difference of step 1 mm/s."""
        h = 1e-3
        slope = (self.python_force(0.0, h) - self.python_force(0.0, -h)) / (2.0 * h)
        return slope if math.isfinite(slope) and slope > 0.0 else 0.0

    @property
    def linear_stiffness(self) -> float:
        """Stiffness (N/m) of the linearised connector (stability checks, time scales): the tangent stiffness
        at d = 0 (0 where it is not finite and positive).  It is *not* the energy bounds' quadratic form
        (:attr:`quadratic_stiffness`)."""
        k = self.tangent_stiffness(0.0)
        return k if math.isfinite(k) and k > 0.0 else 0.0

    def always_acting_fields(self) -> tuple[str | None, str | None]:
        """The fields of the connector's scene table that set :attr:`linear_stiffness` and :attr:`linear_damping`
        where the connector acts with them in every state (a linear spring, a linear damper), None where not.

        The up-front time-scale check (:mod:`mbs_models.engine.time_scales`) counts and names them.  A law of
        its own (a contact, whose linearisation holds in some states only) none unless it says so."""
        return None, None

    @property
    def first_step_limit(self) -> float:
        """Largest first step (s) an adaptive solve may take for this connector (default: inf, no limit).

        Exudyn's adaptive solvers start with their maximum step; a law whose force can grow faster than
        linearly within that step (a quadratic damper far stiffer than the step) sends the trial step's
        error beyond what its step-size control can reject.  Such a connector names the time scale of
        its fastest motion here; the engine starts the solve with the smallest of these limits."""
        return math.inf

    # ------------------------------------------------------------------ bounds
    def force_bound(self, d_bound: float, rate_bound: float, energy: float) -> float:
        """Bound (N) on ``|F|`` when ``|d| <= d_bound`` (m) and ``|d'| <= rate_bound`` (m/s) and the
        mechanical energy is ``energy`` (J) at most: :meth:`derived_force_bound` unless closed form."""
        return self.derived_force_bound(d_bound, rate_bound)

    #: Samples per axis of the box in :meth:`derived_force_bound` for a law not declared :attr:`monotone`.
    BOUND_SAMPLES = 33

    def derived_force_bound(self, d_bound: float, rate_bound: float) -> float:
        """Bound (N) on ``|F(d, d')|`` over the box ``|d| <= D``, ``|d'| <= V``, from the law alone; inf where the box
        leaves :attr:`coordinate_range` or the law is not finite on it.

        * :attr:`monotone` law: ``max(|F(D, V)|, |F(-D, -V)|)``, exact (F is largest at one corner and smallest
          at the opposite one).
        * otherwise: the largest ``|F|`` on a grid of :attr:`BOUND_SAMPLES` squared points (the corners and edges
          included) plus the largest change of F between neighbouring grid points: a true bound for a law
          monotone on each grid cell (piecewise monotone with its kinks on the grid), an estimate with a
          one-cell Lipschitz margin otherwise.
        """
        D, V = abs(float(d_bound)), abs(float(rate_bound))
        if not (math.isfinite(D) and math.isfinite(V)):
            return math.inf
        low, high = self.coordinate_range
        if not (low < -D and D < high):
            return math.inf
        if self.monotone:
            values = (self.python_force(D, V), self.python_force(-D, -V))
            bound = max(abs(v) for v in values)
            return bound if math.isfinite(bound) else math.inf
        n = self.BOUND_SAMPLES
        d = np.linspace(-D, D, n)
        rate = np.linspace(-V, V, n)
        dd, rr = np.meshgrid(d, rate, indexing="ij")
        with np.errstate(all="ignore"):
            F = np.asarray(self.force(dd, rr), dtype=float) * np.ones_like(dd)
        if not np.all(np.isfinite(F)):
            return math.inf
        margin = max(float(np.max(np.abs(np.diff(F, axis=0)), initial=0.0)),
                     float(np.max(np.abs(np.diff(F, axis=1)), initial=0.0)))
        return float(np.max(np.abs(F))) + margin


def add_connector_item(mbs, marker_a, marker_b, stiffness: float = 0.0, damping: float = 0.0):
    """Add Exudyn's ``ObjectConnectorCoordinateSpringDamper`` between two coordinate markers, with its built-in
    linear law ``F = stiffness d + damping d'`` (N/m, N s/m; a user function recorded on it replaces the law);
    return its ObjectIndex."""
    from exudyn.itemInterface import ObjectConnectorCoordinateSpringDamper

    return mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
        markerNumbers=[marker_a, marker_b], stiffness=stiffness, damping=damping,
        visualization={"show": False, "drawSize": -1.0, "color": [-1.0, -1.0, -1.0, -1.0]}))


def record_spring_force_law(mbs, index, law: Callable, user_functions: str, *, with_offset: bool = False):
    """Record ``law(d, rate) -> F`` (N, over the backend's ops) as the spring-force user function of the connector
    item ``index`` (``user_functions``: ``"symbolic"`` or ``"python"``); return what Exudyn holds, which must be kept
    alive as long as the system.  ``with_offset``: ``law(d, rate, offset)``, the offset (m) the item holds, as
    Exudyn passes it (:attr:`Connector.offset_in_item`)."""

    if with_offset:
        def user_function(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
            return law(displacement, velocity, offset)
    else:
        def user_function(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
            return law(displacement, velocity)

    recorded = make_user_function(mbs, user_function, user_functions, index)
    mbs.SetObjectParameter(index, "springForceUserFunction", recorded)
    return recorded


class LinearSpringDamper(Connector):
    """Exudyn's built-in linear spring-damper ``F = stiffness d + damping d'`` (either may be 0): no user function.

    Closed forms (checked against the derived ones by the conformance suite): ``U = stiffness d^2 / 2`` (a
    quadratic potential), ``k_t = stiffness``, ``|F| <= stiffness D + damping V``.

    Attributes: stiffness in N/m, damping in N s/m (both >= 0).
    """

    needs_user_function = False
    quadratic_potential = True
    monotone = True

    def __init__(self, name: str, element: str, a: str, b: str, *, stiffness: float = 0.0, damping: float = 0.0):
        super().__init__(name, element, a, b)
        self.stiffness, self.damping = float(stiffness), float(damping)

    def law(self, d, rate, ops: Ops):
        return self.stiffness * d + self.damping * rate

    def builtin_coefficients(self) -> tuple[float, float]:
        return self.stiffness, self.damping

    @property
    def stores_energy(self) -> bool:
        """True if the connector has a spring."""
        return self.stiffness > 0

    @property
    def dissipates(self) -> bool:
        """True if the connector has a damper."""
        return self.damping > 0

    def stored_energy(self, d):
        """Stored (potential) energy in J at ``d`` (m): ``stiffness d^2 / 2``."""
        return 0.5 * self.stiffness * np.asarray(d, dtype=float) ** 2

    def python_stored_energy(self, d: float) -> float:
        """:meth:`stored_energy` at one ``d`` (m), a plain float (J)."""
        return float(self.stored_energy(d))

    def dissipated_energy(self, quadrature: Quadrature, d_nodes, rate_nodes, times_nodes, stored):
        """``damping d'^2`` integrated (J)."""
        return quadrature(self.damping * rate_nodes ** 2)

    @property
    def quadratic_stiffness(self) -> float:
        return self.stiffness

    def tangent_stiffness(self, d: float) -> float:
        return self.stiffness

    @property
    def linear_damping(self) -> float:
        return self.damping

    @property
    def linear_stiffness(self) -> float:
        return self.stiffness

    def always_acting_fields(self) -> tuple[str | None, str | None]:
        """``stiffness`` and ``damping`` (those it has): the linear law acts with them in every state."""
        return ("stiffness" if self.stiffness else None), ("damping" if self.damping else None)

    def force_bound(self, d_bound: float, rate_bound: float, energy: float) -> float:
        """``stiffness D + damping V`` (N)."""
        bound = 0.0
        if self.stiffness > 0:
            bound += self.stiffness * d_bound
        if self.damping > 0:
            bound += self.damping * rate_bound
        return bound if math.isfinite(bound) else math.inf


class Load:
    """An external force on one body, a function of time only: ``F(t)`` in N, positive in the recoil direction.

    Gravity along an inclined cradle (a constant), the breech force of a shot (a pulse).  A load acts on
    ``body`` alone: it is not transmitted to the mount (no support force).  Its work
    ``W(t) = integral_0^t F v_body dt`` (J) enters the energy balance::

        kinetic + stored + dissipated - work = initial energy

    The base class is a constant load ``constant`` (N): Exudyn's ``LoadCoordinate`` with a fixed value, no
    user function, and exact work ``F (x(t) - x(0))``.  Subclasses with a time law set
    :attr:`needs_user_function`, implement :meth:`law` over the backend ops, and list their
    :attr:`breakpoints` (times where F jumps or its slope changes: the solve is split there, so that the
    solver integrates a smooth F in every segment) and :attr:`windows` (intervals where F varies: the
    solve's step is limited there) and :attr:`last_input_time` (F is 0 afterwards).

    Attributes
    ----------
    name: unique id in the scene: the key of its work (``"gravity"``, ``"breech_force"``).
    element: the scene element it belongs to.
    body: the body it acts on.
    constant: the force of a constant load (N).
    """

    needs_user_function = False

    def __init__(self, name: str, element: str, body: str, *, constant: float = 0.0):
        self.name, self.element, self.body = name, element, body
        self.constant = float(constant)

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r} on {self.body})"

    # ------------------------------------------------------------------ the law
    def law(self, t, ops: Ops):
        """The force in N at time ``t`` (s), over ``ops``."""
        return self.constant

    def force(self, t):
        """The force (N) at times ``t`` (s): numpy backend."""
        t = np.asarray(t, dtype=float)
        return np.full_like(t, self.constant) if not self.needs_user_function else self.law(t, NUMPY_OPS)

    def user_function_law(self, ops: Ops) -> Callable:
        """``t -> F`` (N) over ``ops``, as the solver evaluates it: :meth:`law`.  A load whose law has pieces may
        fix the piece per segment of the run instead (:meth:`start_segment`)."""
        return lambda t: self.law(t, ops)

    def start_segment(self, t: float) -> None:
        """The solver is about to integrate a segment of the run from ``t`` (s) (:attr:`breakpoints` split it).
        Nothing for a load without pieces."""

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times (s) where F jumps or its slope changes (the solve is split there).  A constant load has none."""
        return ()

    @property
    def windows(self) -> tuple[tuple[float, float], ...]:
        """``(start, end)`` intervals (s) where F varies in time (the step is limited there).  None for a constant."""
        return ()

    @property
    def last_input_time(self) -> float:
        """Time (s) after which the load does no more work (0 for none; inf for a constant non-zero load)."""
        return math.inf if self.constant != 0.0 else 0.0

    # ------------------------------------------------------------------ Exudyn
    def add_items(self, mbs, marker, user_functions: str = "symbolic"):
        """Add the load to an Exudyn system on a coordinate marker; return its LoadIndex.

        A ``LoadCoordinate``: the constant, or :meth:`law` as its load user function (``"symbolic"``,
        recorded once and evaluated in C++, or ``"python"``).
        """
        from exudyn.itemInterface import LoadCoordinate

        index = mbs.AddLoad(LoadCoordinate(markerNumber=marker, load=self.constant,
                                           visualization={"show": False}))
        self._set_user_function(mbs, index, user_functions)
        self.index = index
        return index

    def update_items(self, mbs, index, user_functions: str = "symbolic") -> None:
        """Write this load's numbers into ``index``, the item :meth:`add_items` made for a load of the same
        class and body (an earlier point of a sweep): the constant and, if any, the user function recorded anew."""
        mbs.SetLoadParameter(index, "load", self.constant)
        self._set_user_function(mbs, index, user_functions)
        self.index = index

    def _set_user_function(self, mbs, index, user_functions: str) -> None:
        """Record :meth:`user_function_law` as the item's load user function (if the load needs one)."""
        if not self.needs_user_function:
            return
        law = self.user_function_law(ops_for(user_functions))

        def user_function(mbs, t, load):
            return law(t)

        if user_functions == "python":
            self._user_function = user_function
        else:
            from exudyn.advancedUtilities import CreateSymbolicUserFunction
            self._user_function = CreateSymbolicUserFunction(mbs, user_function, "loadUserFunction", index)
        mbs.SetLoadParameter(index, "loadUserFunction", self._user_function)

    # ------------------------------------------------------------------ energy
    def work(self, quadrature: Quadrature, position, velocity_nodes, times_nodes):
        """Cumulative work (J) at the output samples: ``F (x - x(0))`` for a constant load (exact), else
        ``F(t) v`` integrated; ``position`` (m) of the body at the samples, ``velocity_nodes`` (m/s) and
        ``times_nodes`` (s) at each interval's quadrature nodes."""
        if not self.needs_user_function:
            position = np.asarray(position, dtype=float)
            return self.constant * (position - position[0])
        return quadrature(self.force(times_nodes) * velocity_nodes)
