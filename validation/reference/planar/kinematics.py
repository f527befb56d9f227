"""The planar mechanics of the gun on its carriage: mass matrix, velocity terms, gravity, points (by hand).

Written from DESIGN.md, "The recoil axis on a carriage: the planar model".  Generalised coordinates
``q = (X, Y, phi, x_1 .. x_n)``: the carriage frame is the ground frame moved by ``(X, Y)`` (m) and turned by
``phi`` (rad, counter-clockwise, nose up); ``x_i`` (m) is axis body i's coordinate, rearward from battery (the
barrel is body 0).  With ``R = R(phi)``, ``S = [[0, -1], [1, 0]]`` (a quarter turn, ``dR/dphi = R S``,
``S S = -1``) and ``e = (cos theta, sin theta)`` (theta: the elevation), a carriage-frame point ``r`` is at
``P = (X, Y) + R r``, and the bodies' centres of mass are at::

    carriage    r_c                                  (mass m_c, inertia I_c about its CG)
    axis body i a_i = t + (b - x_i) e                (mass m_i; the barrel also I_M about its CG)

(t: the trunnion, b: ``barrel_center_of_mass``).  Their velocities are ``V + phi' R S r_c`` and
``V + phi' R S a_i - x_i' R e`` (``V = (X', Y')``), so the kinetic energy
``T = 1/2 m_c |.|^2 + 1/2 (I_c + I_M) phi'^2 + sum_i 1/2 m_i |.|^2`` gives the mass matrix
(``T = 1/2 q'^T M q'``), with ``m = m_c + sum m_i``, the first moment ``s = m_c r_c + sum_i m_i a_i`` and
``h = t_y cos theta - t_x sin theta`` (the axis' arm about the frame's origin; ``a_i x e = t x e = -h``)::

    M_XX = M_YY = m,  M_XY = 0
    M_(XY),phi  = R S s                 M_(XY),x_i = -m_i R e
    M_phi,phi   = I_c + I_M + m_c |r_c|^2 + sum_i m_i |a_i|^2
    M_phi,x_i   = -m_i (a_i x e) = m_i h          M_x_i,x_j = m_i delta_ij

Lagrange's equations ``d/dt dT/dq' - dT/dq = Q`` read ``M q'' + c(q, q') = Q``.  The accelerations of the
centres of mass are ``J q'' + gamma``, ``gamma_c = -phi'^2 R r_c``, ``gamma_i = -phi'^2 R a_i - 2 phi' x_i' R S e``
(from ``a_i' = -x_i' e``), and ``c = sum_k m_k J_k^T gamma_k``::

    c_(XY) = -phi'^2 R s - 2 phi' R S e sum_i m_i x_i'
    c_phi  = -2 phi' sum_i m_i x_i' (a_i . e)
    c_x_i  = m_i phi'^2 (a_i . e)                       (the centrifugal pull along the axis)

Gravity g pulls every body down: potential ``V_g = g (m Y + (R s)_y)``, generalised force ``-dV_g/dq``::

    Q_X = 0,  Q_Y = -m g,  Q_phi = -g (R S s)_y,  Q_x_i = m_i g (R e)_y = m_i g sin(theta + phi)

A force ``F`` (N, ground frame) at a carriage point ``r`` adds ``J_r^T F``: ``Q_(XY) = F``,
``Q_phi = (R S r) . F``.  A force ``-L R e`` on the barrel's centre of mass (the breech force L, N, pushing it
rearward along the axis; its reaction is on the projectile, not on the gun) adds ``J_b^T (-L R e)``::

    Q_(XY) = -L R e,  Q_phi = -L (S a_b) . e = L h,  Q_x_b = L

which is ``L / m_b`` times column x_b of M: an impulse ``I`` of it is a jump of ``x_b'`` by ``I / m_b`` alone (the
carriage's velocity does not jump), DESIGN.md's shot.  Every 1-D element acts between the cradle and the axis
bodies along the axis: its virtual work is ``F delta d`` (d its relative coordinate), so it adds its 1-D force to
the axis coordinates only (the reaction goes into the carriage through M's coupling terms).

Every function takes ``phi`` and the axis coordinates as numpy arrays of N states (a batch) and returns arrays
with N last (``(n, n, N)`` for M); SI units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Default gravitational acceleration (m/s^2) of a carriage scene without a ``[cradle]`` table (DESIGN.md).
DEFAULT_GRAVITY = 9.81


@dataclass(frozen=True)
class Geometry:
    """The carriage and the axis bodies (SI): masses, inertias, carriage-frame points, elevation, gravity.

    ``masses``: the axis bodies' masses (kg), the barrel first (index 0), in the axis model's body order."""

    carriage_mass: float
    carriage_inertia: float
    center_of_mass: tuple
    trunnion: tuple
    barrel_offset: float
    barrel_inertia: float
    elevation: float
    gravity: float
    masses: tuple

    @classmethod
    def of(cls, scene, masses) -> "Geometry":
        """The geometry of ``scene.carriage`` (read as data), the ``[cradle]`` elevation (degrees; 0 without) and
        gravity (9.81 without), for the axis bodies of ``masses`` (kg, barrel first)."""
        carriage, cradle = scene.carriage, getattr(scene, "cradle", None)
        elevation = math.radians(float(cradle.elevation)) if cradle is not None else 0.0
        gravity = float(cradle.gravity) if cradle is not None else DEFAULT_GRAVITY
        return cls(float(carriage.mass), float(carriage.inertia),
                   tuple(float(v) for v in carriage.center_of_mass), tuple(float(v) for v in carriage.trunnion),
                   float(carriage.barrel_center_of_mass), float(carriage.barrel_inertia or 0.0), elevation, gravity,
                   tuple(float(m) for m in masses))

    # ------------------------------------------------------------------ constants
    @property
    def n_axis(self) -> int:
        return len(self.masses)

    @property
    def n(self) -> int:
        """Number of generalised coordinates (3 + axis bodies)."""
        return 3 + self.n_axis

    @property
    def total_mass(self) -> float:
        """m = m_c + sum m_i (kg)."""
        return self.carriage_mass + sum(self.masses)

    @property
    def axis(self) -> tuple[float, float]:
        """e = (cos theta, sin theta): the forward direction of the axis in the carriage frame."""
        return (math.cos(self.elevation), math.sin(self.elevation))

    @property
    def arm(self) -> float:
        """h = t_y cos theta - t_x sin theta (m): the axis' arm about the carriage frame's origin."""
        ex, ey = self.axis
        return self.trunnion[1] * ex - self.trunnion[0] * ey

    # ------------------------------------------------------------------ points
    def axis_point(self, x):
        """a_i = t + (b - x) e (m, carriage frame) of an axis body at ``x`` (m): (ax, ay)."""
        ex, ey = self.axis
        along = self.barrel_offset - x
        return self.trunnion[0] + along * ex, self.trunnion[1] + along * ey

    def first_moment(self, xs):
        """s = m_c r_c + sum_i m_i a_i (kg m, carriage frame): (sx, sy); ``xs`` the axis coordinates."""
        sx = self.carriage_mass * self.center_of_mass[0] + 0.0 * xs[0]
        sy = self.carriage_mass * self.center_of_mass[1] + 0.0 * xs[0]
        for m, x in zip(self.masses, xs):
            ax, ay = self.axis_point(x)
            sx, sy = sx + m * ax, sy + m * ay
        return sx, sy

    @staticmethod
    def place(X, Y, phi, point):
        """The ground-frame position ``(X, Y) + R(phi) r`` (m) of a carriage-frame point ``r = (rx, ry)``."""
        c, s = np.cos(phi), np.sin(phi)
        return X + c * point[0] - s * point[1], Y + s * point[0] + c * point[1]

    @staticmethod
    def point_velocity(phi, dX, dY, dphi, point, rate=(0.0, 0.0)):
        """Ground-frame velocity (m/s) of a point ``r`` of the carriage frame moving in it at ``r'`` (``rate``):
        ``V + phi' R S r + R r'``."""
        c, s = np.cos(phi), np.sin(phi)
        rx, ry = point
        wx, wy = -ry * dphi + rate[0], rx * dphi + rate[1]    # S r phi' + r'
        return dX + c * wx - s * wy, dY + s * wx + c * wy

    @staticmethod
    def point_force(phi, point, Fx, Fy):
        """``Q_phi = (R S r) . F`` (N m) of a ground-frame force F (N) at carriage point r (Q_X = Fx, Q_Y = Fy)."""
        c, s = np.cos(phi), np.sin(phi)
        rx, ry = point
        return Fx * (-c * ry - s * rx) + Fy * (-s * ry + c * rx)

    # ------------------------------------------------------------------ the equations
    def mass_matrix(self, phi, xs):
        """M(q) (module docstring), shape (n, n, N) for N states (``phi`` (N,), ``xs`` (n_axis, N))."""
        phi = np.asarray(phi, dtype=float)
        c, s = np.cos(phi), np.sin(phi)
        ex, ey = self.axis
        sx, sy = self.first_moment(xs)
        M = np.zeros((self.n, self.n) + phi.shape)
        M[0, 0] = M[1, 1] = self.total_mass
        M[0, 2] = M[2, 0] = -c * sy - s * sx                    # R S s, x
        M[1, 2] = M[2, 1] = -s * sy + c * sx                    #        y
        rcx, rcy = self.center_of_mass
        inertia = self.carriage_inertia + self.barrel_inertia + self.carriage_mass * (rcx * rcx + rcy * rcy)
        for i, (m, x) in enumerate(zip(self.masses, xs)):
            k = 3 + i
            ax, ay = self.axis_point(x)
            inertia = inertia + m * (ax * ax + ay * ay)
            M[0, k] = M[k, 0] = -m * (c * ex - s * ey)          # -m_i R e
            M[1, k] = M[k, 1] = -m * (s * ex + c * ey)
            M[2, k] = M[k, 2] = -m * (ax * ey - ay * ex)        # -m_i (a_i x e) = m_i h
            M[k, k] = m
        M[2, 2] = inertia
        return M

    def velocity_terms(self, phi, xs, dphi, dxs):
        """c(q, q') (module docstring), shape (n, N)."""
        phi = np.asarray(phi, dtype=float)
        c, s = np.cos(phi), np.sin(phi)
        ex, ey = self.axis
        sx, sy = self.first_moment(xs)
        Rs = (c * sx - s * sy, s * sx + c * sy)
        RSe = (-c * ey - s * ex, -s * ey + c * ex)
        momentum = 0.0 * phi
        out = np.zeros((self.n,) + phi.shape)
        cphi = 0.0 * phi
        for i, (m, x, dx) in enumerate(zip(self.masses, xs, dxs)):
            ax, ay = self.axis_point(x)
            along = ax * ex + ay * ey
            momentum = momentum + m * dx
            cphi = cphi - 2.0 * dphi * m * dx * along
            out[3 + i] = m * dphi * dphi * along
        out[0] = -dphi * dphi * Rs[0] - 2.0 * dphi * RSe[0] * momentum
        out[1] = -dphi * dphi * Rs[1] - 2.0 * dphi * RSe[1] * momentum
        out[2] = cphi
        return out

    def gravity_forces(self, phi, xs):
        """Q of gravity (module docstring), shape (n, N)."""
        phi = np.asarray(phi, dtype=float)
        c, s = np.cos(phi), np.sin(phi)
        ex, ey = self.axis
        sx, sy = self.first_moment(xs)
        g = self.gravity
        out = np.zeros((self.n,) + phi.shape)
        out[1] = -self.total_mass * g + 0.0 * phi
        out[2] = -g * (-s * sy + c * sx)                        # -g (R S s)_y
        for i, m in enumerate(self.masses):
            out[3 + i] = m * g * (s * ex + c * ey)              # m_i g (R e)_y
        return out

    def gravity_potential(self, Y, phi, xs):
        """``V_g = g sum_k m_k y_k = g (m Y + (R s)_y)`` (J): the bodies' weights at their CG heights above y = 0."""
        sx, sy = self.first_moment(xs)
        return self.gravity * (self.total_mass * Y + np.sin(phi) * sx + np.cos(phi) * sy)

    def axis_load(self, phi, xs, load, body: int = 0):
        """Q (shape (n, N)) of a force ``-L R e`` (L = ``load``, N, towards +x along the axis) on axis body
        ``body``'s CG: the breech force on the barrel (module docstring)."""
        phi = np.asarray(phi, dtype=float)
        c, s = np.cos(phi), np.sin(phi)
        ex, ey = self.axis
        ax, ay = self.axis_point(xs[body])
        out = np.zeros((self.n,) + phi.shape)
        out[0] = -load * (c * ex - s * ey)
        out[1] = -load * (s * ex + c * ey)
        out[2] = -load * (-ay * ex + ax * ey)                   # -L (S a_b) . e
        out[3 + body] = load + 0.0 * phi
        return out

    def kinetic_energies(self, phi, xs, dX, dY, dphi, dxs) -> dict[str, np.ndarray]:
        """``1/2 m |v_CG|^2 + 1/2 I phi'^2`` (J) of the carriage (key ``carriage``) and of every axis body (by index;
        the barrel with I_M)."""
        ex, ey = self.axis
        vx, vy = self.point_velocity(phi, dX, dY, dphi, self.center_of_mass)
        out = {"carriage": 0.5 * self.carriage_mass * (vx * vx + vy * vy) + 0.5 * self.carriage_inertia * dphi * dphi}
        for i, (m, x, dx) in enumerate(zip(self.masses, xs, dxs)):
            vx, vy = self.point_velocity(phi, dX, dY, dphi, self.axis_point(x), (-dx * ex, -dx * ey))
            out[i] = 0.5 * m * (vx * vx + vy * vy) + (0.5 * self.barrel_inertia * dphi * dphi if i == 0 else 0.0)
        return out
