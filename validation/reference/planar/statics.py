"""The initial state: the static equilibrium of the whole gun on its supports, the axis bodies held.

DESIGN.md, "Initial state": the axis bodies sit where the 1-D model starts them (x_i0: 0, or the preload's
hold on the battery stop), at rest; the carriage at rest, ``X = 0`` (the frames coincide but for the sinking into
the ground and the pitch), in the equilibrium of its vertical force and its moment (generalised forces
``Q_Y``, ``Q_phi`` of :mod:`.kinematics`) under gravity on every body and the supports' forces at rest::

    sum_s N_s - m g = 0
    sum_s (R S r_s) . (0, N_s) - g (R S s)_y = 0,          N_s = k_s max(-y_s, 0)^n_s

(at rest the friction and a spade anchored at its own static x give no tangential force, so ``Q_X = 0``
holds for any X; the holding forces on the axis coordinates are internal).  Solved for ``(Y, phi)`` with
``scipy.optimize.root`` (Powell's hybrid method) from the rigid-support guess, the residual scaled by the
weight; a solution with the residual below 1e-10 of the weight is required.  A support may carry nothing at rest
(a skid placed at the ground, or above it, in the equilibrium of the others): it touches only when the gun moves.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import root

from ..model import ReferenceModelError


def static_equilibrium(geometry, supports, xs) -> dict:
    """``{"Y": m, "phi": rad, "normal": [N_s (N)], "x": [x_s (m)]}`` of the carriage at rest on ``supports``
    (:class:`.supports.Support`) with the axis bodies at ``xs`` (m); ReferenceModelError if none is found."""
    weight = geometry.total_mass * geometry.gravity
    xs = [np.array([float(x)]) for x in xs]

    def forces(v):
        Y, phi = float(v[0]), float(v[1])
        out = []
        for s in supports:
            _, y_s = geometry.place(0.0, Y, phi, s.point)
            out.append(s.static_force(-float(y_s)))
        return out

    def residual(v):
        Y, phi = float(v[0]), float(v[1])
        Q = geometry.gravity_forces(np.array([phi]), xs)[:, 0]
        normals = forces(v)
        vertical = Q[1] + sum(normals)
        moment = Q[2] + sum(float(geometry.point_force(phi, s.point, 0.0, N)) for s, N in zip(supports, normals))
        return [vertical / weight, moment / weight]

    # rigid guess: the two extreme supports share the weight by the lever rule about the CG's x
    sx, _ = geometry.first_moment(xs)
    cg = float(sx[0]) / geometry.total_mass
    ordered = sorted(supports, key=lambda s: s.point[0])
    rear, front = ordered[0], ordered[-1]
    share_front = min(max((cg - rear.point[0]) / (front.point[0] - rear.point[0]), 0.05), 0.95)
    sink = [(load / s.law.stiffness) ** (1.0 / s.law.exponent)
            for s, load in ((rear, (1.0 - share_front) * weight), (front, share_front * weight))]
    pitch = (sink[0] - sink[1]) / (front.point[0] - rear.point[0])
    guess = [-0.5 * (sink[0] + sink[1]) - 0.5 * (rear.point[1] + front.point[1]), pitch]
    solution = root(residual, guess, method="hybr", options={"xtol": 1e-14})
    value = residual(solution.x)
    if not (solution.success or max(abs(r) for r in value) < 1e-12) or max(abs(r) for r in value) > 1e-10:
        raise ReferenceModelError(f"carriage: no static equilibrium on the supports found ({solution.message}; "
                                  f"residual {value})")
    Y, phi = float(solution.x[0]), float(solution.x[1])
    normals = forces(solution.x)
    x_points = [float(geometry.place(0.0, Y, phi, s.point)[0]) for s in supports]
    if not all(math.isfinite(v) for v in [Y, phi] + normals):
        raise ReferenceModelError("carriage: the static equilibrium is not finite")
    return {"Y": Y, "phi": phi, "normal": normals, "x": x_points}
