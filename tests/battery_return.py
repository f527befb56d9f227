"""The simplified model's return to battery in closed form (tests of ``time_to_battery``, engine and reference).

``M x'' + c(x') x' + k x = 0``, ``x(0) = 0``, ``x'(0) = v0``, with ``c = c_r`` while ``x' > 0`` and ``c = c_c`` while
``x' < 0`` (Eq. (1) of the paper, both underdamped for its numbers).  With ``w = sqrt(k / M)``,
``z = c / (2 sqrt(k M))`` and ``w_d = w sqrt(1 - z^2)``:

* recoil: ``x = (v0 / w_d1) exp(-z1 w t) sin(w_d1 t)``, at rest at ``t_max = atan2(w_d1, z1 w) / w_d1``;
* counter-recoil from rest at ``x_max`` (``s = t - t_max``):
  ``x = x_max exp(-z2 w s) (cos(w_d2 s) + (z2 w / w_d2) sin(w_d2 s))``, moving back until ``s = pi / w_d2``.

The barrel is back in battery (within ``tolerance`` of x = 0) at the root of ``x(s) = tolerance`` in that interval.
"""

from __future__ import annotations

import math

from scipy.optimize import brentq


def spring_damper_return(mass: float, stiffness: float, recoil_damping: float, counter_recoil_damping: float,
                         v0: float, tolerance: float = 1e-3) -> tuple[float, float, float]:
    """``(t_max, x_max, t_battery)`` in s, m, s of the closed form above."""
    w = math.sqrt(stiffness / mass)
    z1, z2 = (c / (2.0 * math.sqrt(stiffness * mass)) for c in (recoil_damping, counter_recoil_damping))
    wd1, wd2 = w * math.sqrt(1.0 - z1 ** 2), w * math.sqrt(1.0 - z2 ** 2)
    t_max = math.atan2(wd1, z1 * w) / wd1
    x_max = v0 / wd1 * math.exp(-z1 * w * t_max) * math.sin(wd1 * t_max)

    def back(s: float) -> float:
        return x_max * math.exp(-z2 * w * s) * (math.cos(wd2 * s) + z2 * w / wd2 * math.sin(wd2 * s)) - tolerance

    return t_max, x_max, t_max + brentq(back, 0.0, math.pi / wd2, xtol=1e-15, rtol=1e-15)


def simplified_return(scene, tolerance: float = 1e-3) -> tuple[float, float, float]:
    """:func:`spring_damper_return` with the numbers of a simplified-model scene."""
    return spring_damper_return(scene.barrel.mass, scene.recoil_spring.stiffness, scene.recoil_damper.recoil,
                                scene.recoil_damper.counter_recoil, scene.initial_velocity, tolerance)
