"""The planar model: the axis model of the 1-D reference moved by the carriage, and the right-hand side.

The axis model (:func:`validation.reference.assembly.build_model`: the bodies on the recoil axis, the connectors
of every element with their modes and events, the loads and the velocity jumps) is reused unchanged; this
module adds the carriage (:mod:`.kinematics`) and the supports (:mod:`.supports`).  State vector::

    [ axis state (x_0, v_0, x_1, v_1, ..., D_j, W_k: exactly the 1-D layout),
      X, Y, phi, X', Y', phi'   (the carriage: m, m, rad, m/s, m/s, rad/s),
      D_s                       (the dissipated energy of every support, J) ]

so every switching function of the axis connectors (written on the 1-D state's indices) reads a planar state
as it stands.  Equations of motion (:mod:`.kinematics`)::

    M(q) q'' + c(q, q') = Q_gravity + Q_connectors + Q_loads + Q_supports + G F_constraint

* ``Q_connectors``: the axis connectors' 1-D forces on the axis coordinates (``f_i``, N; the compiled
  ``"axis"`` code of :mod:`validation.reference.codegen`), nothing on X, Y, phi;
* ``Q_loads``: every load ``L_k(t)`` (the breech force) is the force ``-L R e`` on its body's CG;
* ``Q_supports``: ``J_s^T (T_s, N_s)`` of every support;
* a connector whose mode is a constraint (exact Coulomb friction sticking, a sliding contact) holds its
  relative coordinate's acceleration at 0: ``d'' = -G^T q'' = 0`` with ``G = e_a - e_b`` (the axis
  coordinates of its ends; the ground has none), its force F the multiplier:
  ``F = -(G^T M^-1 G)^-1 G^T M^-1 Q`` (Q: every other generalised force minus c);
* a spade sliding on the ground (:mod:`.supports`: p = 0, N = 0) holds its point's ``p'' = 0`` with the share alpha
  of its force ``D`` (generalised): all multipliers together solve ``q'' = M^-1 (Q + D lam)``, ``R q'' = b`` (rows
  ``R = G^T``, ``b = 0`` for the connectors).

Dissipated powers: the axis connectors' as in 1-D (a constraint's ``(F - F_c(d)) d'``), the supports'
(:meth:`.supports.Support.dissipated_power`); the work rate of a load is ``Q_load . q'``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model import Evaluation, Mode, Model
from ..terms.contact_laws import OFF, STICK, ContactMode
from .kinematics import Geometry
from .supports import Support, SupportMode

#: Names of the carriage's states.
CARRIAGE_STATES = ("X", "Y", "phi", "dX", "dY", "dphi")


@dataclass(frozen=True)
class PlanarMode(Mode):
    """A :class:`~validation.reference.model.Mode` of the axis connectors plus every support's
    :class:`~.supports.SupportMode` (``supports``, in the carriage's order)."""

    supports: tuple = ()

    def axis_mode(self) -> Mode:
        return Mode(self.names, self.states, self.loads)

    def __repr__(self) -> str:
        inner = ", ".join(f"{s.contact.phase}{'/clipped' if s.contact.clipped else ''}"
                          f"{'/slip%+d' % s.slip if s.slip else ''}" for s in self.supports)
        return f"{Mode.__repr__(self)[:-1]}; supports {inner})"


@dataclass
class PlanarEvaluation(Evaluation):
    """:class:`~validation.reference.model.Evaluation` (forces, axis accelerations, support force S) plus the
    generalised accelerations ``qdd`` (n rows), each support's ``normal`` and ``tangential`` force (N) and
    dissipated power (W), the axis connectors' ``powers``, the loads' work rates (W) and the share alpha of every
    spade sliding on the ground (``shares``, by support index)."""

    qdd: object = None
    normal: list = field(default_factory=list)
    tangential: list = field(default_factory=list)
    support_powers: list = field(default_factory=list)
    powers: list = field(default_factory=list)
    work_rates: list = field(default_factory=list)
    shares: dict = field(default_factory=dict)


class PlanarModel:
    """The axis model (``axis``) on the carriage (``geometry``) with its ``supports`` (module docstring).

    Everything of the axis model that does not depend on the dynamics (bodies, connectors, roles, loads,
    impulses, shot times, stored and dissipated energies of the connectors, works) is read through it."""

    def __init__(self, axis: Model, geometry: Geometry, supports):
        self.axis = axis
        self.geometry = geometry
        self.supports = tuple(supports)
        self.n1 = axis.n_states
        self.carriage_slot = self.n1
        self.support_slot = self.n1 + 6
        self.n_states = self.n1 + 6 + len(self.supports)
        self._constraints: dict = {}
        self._load_code: dict = {}
        self._compiled: dict = {}
        self.static: dict = {}

    def __getattr__(self, name):
        if name.startswith("__") or name == "axis":
            raise AttributeError(name)
        return getattr(self.axis, name)

    # ------------------------------------------------------------------ state
    def carriage(self, y):
        """``(X, Y, phi, X', Y', phi')`` of a state or a batch."""
        k = self.carriage_slot
        return tuple(y[k + i] for i in range(6))

    def axis_coordinates(self, y):
        """(x_i, ...), (x_i', ...) of the axis bodies."""
        nb = self.axis.n_bodies
        return [y[2 * i] for i in range(nb)], [y[2 * i + 1] for i in range(nb)]

    def support_motion(self, support: Support):
        """``y -> (x_s, y_s, u_s, w_s)`` of ``support`` on a state or a batch."""
        geometry, carriage = self.geometry, self.carriage
        return lambda y: support.motion(geometry, carriage(y))

    # ------------------------------------------------------------------ pieces
    def constraints(self, mode: Mode) -> tuple[int, ...]:
        """Indices of the connectors whose state in ``mode`` is a constraint."""
        key = (mode.names, mode.states)
        found = self._constraints.get(key)
        if found is None:
            found = tuple(j for j, (c, state) in enumerate(zip(self.axis.connectors, mode.states))
                          if (eq := c.equations(state)) is not None and eq.constraint)
            self._constraints[key] = found
        return found

    def load_values(self, mode: Mode, t):
        """``L_k(t)`` (N) of every load: the smooth piece of ``mode`` (or the whole law without pieces)."""
        out = []
        for k, load in enumerate(self.axis.loads):
            if not mode.loads:
                out.append(load.force(t))
                continue
            key = (k, mode.loads[k])
            function = self._load_code.get(key)
            if function is None:
                code = load.equations(mode.loads[k])
                if code is None:
                    function = None
                else:
                    expression = code.format(L="L").strip().split("=", 1)[1]
                    function = eval(f"lambda t: {expression}", {})  # noqa: S307 - the load's own source
                self._load_code[key] = function
            out.append(0.0 * np.asarray(t, dtype=float) if function is None else function(t) + 0.0 * np.asarray(t))
        return out

    # ------------------------------------------------------------------ the dynamics
    def evaluate(self, mode: PlanarMode, y, omit: int | None = None, t=None, free_support: int | None = None,
                 free_share: float = 0.0) -> PlanarEvaluation:
        """Everything at a state ``y`` (n,) or a batch (n, N) in ``mode`` (module docstring): floats for a state,
        arrays for a batch.  ``omit``: leave out axis connector ``omit`` (its force, or its constraint);
        ``free_support``: leave out that support's forces (normal, and tangential: its friction or spade), but for the
        share ``free_share`` of a spade's force (1: all of it, with N = 0)."""
        y = np.asarray(y, dtype=float)
        batch = y.ndim == 2
        shape = y.shape[1:]                                       # () for a state, (N,) for a batch
        g = self.geometry
        nb = self.axis.n_bodies
        axis_mode = mode.axis_mode() if isinstance(mode, PlanarMode) else mode
        function = self.axis.compiled(axis_mode, "axis_array" if batch else "axis", omit)
        forces, f, fg, powers = function(y[:self.n1])
        if batch:
            forces = [np.broadcast_to(np.asarray(F, dtype=float), shape).copy() for F in forces]
            fg = np.broadcast_to(np.asarray(fg, dtype=float), shape).copy()
        X, Yc, phi, dX, dY, dphi = self.carriage(y)
        xs, vs = self.axis_coordinates(y)
        shares = {}
        Q = g.gravity_forces(phi, xs) - g.velocity_terms(phi, xs, dphi, vs)
        for i in range(nb):
            Q[3 + i] += f[i]
        work_rates = []
        if self.axis.loads:
            if t is None:
                raise ValueError("the model has loads: evaluate needs the time t")
            qd = np.stack([dX + 0.0 * phi, dY + 0.0 * phi, dphi + 0.0 * phi] + [v + 0.0 * phi for v in vs])
            tt = np.broadcast_to(np.asarray(t, dtype=float), shape) if batch else float(t)
            for load, L in zip(self.axis.loads, self.load_values(axis_mode, tt)):
                QL = g.axis_load(phi, xs, L, self.axis.body_index[load.body])
                Q += QL
                work_rates.append(np.sum(QL * qd, axis=0))
        normal, tangential, support_powers = [], [], []
        sliding = []   # the spades sliding on the ground: (support index, x_s, u_s)
        for k, s in enumerate(self.supports):
            smode = mode.supports[k]
            if k == free_support:
                smode = SupportMode(ContactMode(STICK if free_share else OFF), smode.slip, smode.anchor)
            x_s, y_s, u_s, w_s = s.motion(g, (X, Yc, phi, dX, dY, dphi))
            Nn = s.normal(smode, -y_s, -w_s)
            if smode.sliding and k != free_support:
                T = 0.0 * u_s  # its share of the spade's force is a multiplier, below
                sliding.append((k, smode, x_s, u_s))
            else:
                T = s.tangential(smode, Nn, x_s, u_s, share=free_share)
            Q[0] += T
            Q[1] += Nn
            Q[2] += g.point_force(phi, s.point, T, Nn)
            normal.append(Nn)
            tangential.append(T)
            support_powers.append((smode, -y_s, -w_s, Nn, u_s, x_s))
        M = g.mass_matrix(phi, xs)
        if batch:
            M, Q = np.moveaxis(M, -1, 0), np.moveaxis(Q, -1, 0)   # (N, n, n), (N, n)
        held = [j for j in self.constraints(axis_mode) if j != omit]
        if not held and not sliding:
            qdd = np.linalg.solve(M, Q[..., None])[..., 0]
        else:
            # multipliers lam: qdd = M^-1 (Q + D lam) with R qdd = b (the axis constraints: D = G, R = G^T, b = 0;
            # a sliding spade: D its force's generalised force, R qdd = b its point's p'' = 0)
            m = len(held) + len(sliding)
            D = np.zeros(M.shape[:-2] + (g.n, m))
            R = np.zeros(M.shape[:-2] + (m, g.n))
            b = np.zeros(M.shape[:-2] + (m,))
            for col, j in enumerate(held):
                c = self.axis.connectors[j]
                if c.body_a is not None:
                    D[..., 3 + c.body_a, col] += 1.0
                if c.body_b is not None:
                    D[..., 3 + c.body_b, col] -= 1.0
                R[..., col, :] = D[..., :, col]
            cphi, sphi = np.cos(phi), np.sin(phi)
            for col, (k, smode, x_s, u_s) in enumerate(sliding, start=len(held)):
                support = self.supports[k]
                rx, ry = support.point
                full = support.spade_force(smode.anchor, x_s, u_s)
                D[..., 0, col] = full
                D[..., 2, col] = g.point_force(phi, support.point, full, 0.0)
                # p'' = -(Y'' + phi'' (c rx - s ry)) + phi'^2 (s rx + c ry) = 0
                R[..., col, 1] = -1.0
                R[..., col, 2] = -(cphi * rx - sphi * ry)
                b[..., col] = -dphi * dphi * (sphi * rx + cphi * ry)
            MD = np.linalg.solve(M, D)                                          # (..., n, m)
            MQ = np.linalg.solve(M, Q[..., None])                               # (..., n, 1)
            lam = np.linalg.solve(R @ MD, b[..., None] - R @ MQ)                # (..., m, 1)
            qdd = (MQ + MD @ lam)[..., 0]
            for col, j in enumerate(held):
                c = self.axis.connectors[j]
                F = lam[..., col, 0] if batch else float(lam[col, 0])
                forces[j] = F
                fg = fg + c.support_sign * F
                d, rate = c.d_of(y), c.rate_of(y)
                static = (np.array([c.static_force(float(v)) for v in np.ravel(d)]).reshape(np.shape(d)) if batch
                          else c.static_force(float(d)))
                if c.dissipates:
                    powers[self.axis.dissipating.index(c)] = (F - static) * rate
            for col, (k, smode, x_s, u_s) in enumerate(sliding, start=len(held)):
                share = lam[..., col, 0] if batch else float(lam[col, 0])
                shares[k] = share
                tangential[k] = share * self.supports[k].spade_force(smode.anchor, x_s, u_s)
        support_powers = [s.dissipated_power(smode, p, rate, Nn, T, u_s, x_s)
                          for s, T, (smode, p, rate, Nn, u_s, x_s) in zip(self.supports, tangential, support_powers)]
        if batch:
            qdd = qdd.T
            powers = [np.broadcast_to(np.asarray(P, dtype=float), shape) for P in powers]
            normal, tangential, support_powers = ([np.broadcast_to(np.asarray(v, dtype=float), shape) for v in group]
                                                  for group in (normal, tangential, support_powers))
        else:
            fg = float(fg)
            normal, tangential, support_powers, powers, work_rates = (
                [float(v) for v in group] for group in (normal, tangential, support_powers, powers, work_rates))
        return PlanarEvaluation(forces, [qdd[3 + i] for i in range(nb)], fg, qdd=qdd, normal=normal,
                                tangential=tangential, support_powers=support_powers, powers=powers,
                                work_rates=work_rates, shares=shares)

    def rhs(self, mode: PlanarMode):
        """``f(t, y) -> dy/dt`` in ``mode`` (state layout: module docstring)."""
        function = self._compiled.get(mode)
        if function is not None:
            return function
        axis = self.axis
        nb, n1, slot = axis.n_bodies, self.n1, self.carriage_slot
        dissipation = [c.di for c in axis.dissipating]
        works = [axis.work_slot[load.name] for load in axis.loads]

        def function(t, y):
            try:
                ev = self.evaluate(mode, y, t=t)
            except OverflowError:  # a rejected trial state (as the 1-D right-hand side: inf, as numpy gives)
                return np.full(self.n_states, np.inf)
            out = np.zeros(self.n_states)
            for i in range(nb):
                out[2 * i] = y[2 * i + 1]
                out[2 * i + 1] = ev.qdd[3 + i]
            for index, power in zip(dissipation, ev.powers):
                out[index] = power
            for index, rate in zip(works, ev.work_rates):
                out[index] = rate
            out[slot:slot + 3] = y[slot + 3:slot + 6]
            out[slot + 3:slot + 6] = ev.qdd[:3]
            out[self.support_slot:] = ev.support_powers
            return out
        self._compiled[mode] = function
        return function

    def relative_acceleration(self, connector, evaluation):
        return self.axis.relative_acceleration(connector, evaluation)

    # ------------------------------------------------------------------ energy
    def kinetic_energies(self, y) -> dict[str, object]:
        """Kinetic energy (J) of the carriage (``carriage``) and of every axis body (by name)."""
        X, Yc, phi, dX, dY, dphi = self.carriage(y)
        xs, vs = self.axis_coordinates(y)
        parts = self.geometry.kinetic_energies(phi, xs, dX, dY, dphi, vs)
        return {"carriage": parts["carriage"], **{b.name: parts[i] for i, b in enumerate(self.axis.bodies)}}

    def gravity_potential(self, y):
        """``g sum m_k y_k`` (J) of every body."""
        X, Yc, phi, *_ = self.carriage(y)
        xs, _ = self.axis_coordinates(y)
        return self.geometry.gravity_potential(Yc, phi, xs)

    def support_energies(self, mode: PlanarMode | None, y) -> dict[str, object]:
        """Stored energy (J) of every support (``support.NAME``); ``mode`` None: without the spades' springs."""
        out = {}
        for k, s in enumerate(self.supports):
            x_s, y_s, _, _ = s.motion(self.geometry, self.carriage(y))
            out[f"support.{s.name}"] = s.stored_energy(None if mode is None else mode.supports[k], -y_s, x_s)
        return out

    def support_dissipation(self, y) -> dict[str, object]:
        """Dissipated energy (J) of every support (``support.NAME``)."""
        return {f"support.{s.name}": y[self.support_slot + k] for k, s in enumerate(self.supports)}

    def apply_impulses(self, t: float, y: np.ndarray) -> np.ndarray:
        """The state after the velocity jumps firing at ``t`` (s): ``x_b' += dv`` alone (DESIGN.md: the carriage's
        velocity does not jump), the work = the change of the kinetic energy."""
        y = np.array(y, dtype=float)
        for impulse in self.axis.impulses:
            if t in impulse.times:
                before = sum(self.kinetic_energies(y).values())
                y[2 * self.axis.body_index[impulse.body] + 1] += impulse.jump
                y[self.axis.work_slot[impulse.name]] += sum(self.kinetic_energies(y).values()) - before
        return y

    def mechanical_energy(self, mode, y):
        """Kinetic + stored (connectors and supports) + gravity potential (J)."""
        return (sum(self.kinetic_energies(y).values()) + sum(self.axis.stored_energies(y).values())
                + sum(self.support_energies(mode, y).values()) + self.gravity_potential(y))
