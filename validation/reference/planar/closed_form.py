"""Closed forms of the planar model: the quasi-static front load (the oracle of the tests and the stability chart).

DESIGN.md, "Quasi-static check", derived here with absorbers.  The carriage at rest on rigid supports, the
spade at ``(0, 0)`` and one front support at ``(x_f, 0)``; the axis bodies (masses m_i, coordinates x_i, CGs
at ``t + (b - x_i) e``) accelerate along the axis.  The moment about the spade of every force on the whole gun,
with the axis bodies' inertial forces ``m_i x_i'' e`` (d'Alembert), is 0::

    x_f N_f - g sum_k m_k x_k + L h - h sum_i m_i x_i'' = 0

(``r x e = t x e = -h`` for a point r of the axis, ``h = y_t cos theta - x_t sin theta``; L the breech force along
``-e`` on the barrel, its arm h as well).  The axis bodies' own equations, summed, give
``sum_i m_i x_i'' = -R + g sin(theta) sum_i m_i + L``, where ``R`` is the force the recoil elements transmit
along the axis to the cradle (``support_force``: the sum of every ground-attached connector's share; the forces
between two bodies cancel).  So L cancels (the front load does not depend on the axis' accelerations)::

    N_f = [ g (m_tot d - cos(theta) sum_i m_i x_i) - (R - g sin(theta) sum_i m_i) h ] / x_f

with ``m_tot d = m_c x_c + sum_i m_i (x_t + b cos theta)``, the gun's weight moment about the spade in battery;
with the barrel alone (m_1 = M) it is DESIGN.md's ``[g (m_tot d - M x_M cos theta) - (R - M g sin theta) h] / x_f``.
"""

from __future__ import annotations

import math


def quasi_static_front_load(carriage_mass: float, carriage_x: float, trunnion, barrel_center_of_mass: float,
                            elevation: float, gravity: float, masses, positions, resistance: float,
                            front_x: float) -> float:
    """N_f (N) of the module docstring: carriage mass (kg) and CG x (m), trunnion ``(x_t, y_t)`` (m), b (m),
    theta (rad), g (m/s^2), the axis bodies' masses (kg) and coordinates (m), R (N) and x_f (m)."""
    xt, yt = trunnion
    c, s = math.cos(elevation), math.sin(elevation)
    axis_mass = sum(masses)
    moment = carriage_mass * carriage_x + axis_mass * (xt + barrel_center_of_mass * c)
    arm = yt * c - xt * s
    shift = sum(m * x for m, x in zip(masses, positions))
    return (gravity * (moment - c * shift) - (resistance - gravity * s * axis_mass) * arm) / front_x
