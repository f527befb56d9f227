"""Closed-form oracles (no ODE solver): the simplified model's maximum and Hunt-Crossley restitution.

Both are derived below and used by the tests to check :func:`validation.solve_reference`.
"""

from __future__ import annotations

import math

from scipy.optimize import brentq


def simplified_max_displacement(mass: float, stiffness: float, recoil_damping: float,
                                v0: float) -> tuple[float, float]:
    """Maximum barrel displacement x_max (m) and its time t_max (s) of the simplified model, Eq. (1).

    ``M x'' + c x' + k x = 0``, ``x(0) = 0``, ``x'(0) = v0 > 0``.  While ``x' > 0`` only the recoil
    coefficient ``c`` of Eq. (2) acts, so up to the first zero of the velocity the motion is that of a
    linear oscillator.  With ``w = sqrt(k/M)`` (rad/s) and ``sigma = c/(2M)`` (1/s):

    * underdamped (``sigma < w``), ``wd = sqrt(w^2 - sigma^2)``:
      ``x = v0 e^(-sigma t) sin(wd t) / wd``,
      ``x' = v0 e^(-sigma t) (wd cos(wd t) - sigma sin(wd t)) / wd = 0``
      at ``t_max = atan2(wd, sigma) / wd``; since ``sin(wd t_max) = wd / w`` this gives
      ``x_max = (v0 / w) exp(-sigma t_max)``;
    * critically damped (``sigma = w``): ``x = v0 t e^(-w t)``, ``t_max = 1/w``, ``x_max = v0 / (e w)``;
    * overdamped (``sigma > w``), ``g = sqrt(sigma^2 - w^2)``: ``x = v0 e^(-sigma t) sinh(g t) / g``,
      ``x' = 0`` where ``tanh(g t) = g / sigma``, i.e. ``t_max = atanh(g / sigma) / g``;
    * ``k = 0``: ``x`` creeps to ``M v0 / c`` as ``t -> inf`` (``t_max = inf``).

    The first maximum is the global one: the mechanical energy ``M x'^2/2 + k x^2/2`` never grows
    (both damper branches dissipate), so any later turning point has ``k x^2/2`` below ``k x_max^2/2``.
    For ``v0 <= 0`` the largest displacement is the start, ``(0, 0)``.
    """
    for name, value in (("mass", mass), ("stiffness", stiffness), ("recoil_damping", recoil_damping)):
        if not (math.isfinite(value) and value >= 0):
            raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    if mass <= 0:
        raise ValueError(f"mass must be > 0 kg, got {mass!r}")
    if v0 <= 0:
        return 0.0, 0.0
    if stiffness == 0:
        return (math.inf, math.inf) if recoil_damping == 0 else (mass * v0 / recoil_damping, math.inf)
    w = math.sqrt(stiffness / mass)
    sigma = recoil_damping / (2.0 * mass)
    if sigma < w:
        wd = math.sqrt((w - sigma) * (w + sigma))
        t_max = math.atan2(wd, sigma) / wd
        return v0 / w * math.exp(-sigma * t_max), t_max
    if sigma == w:
        return v0 / (math.e * w), 1.0 / w
    g = math.sqrt((sigma - w) * (sigma + w))
    t_max = math.atanh(g / sigma) / g
    return v0 * math.exp(-sigma * t_max) * math.sinh(g * t_max) / g, t_max


def _g(z: float) -> float:
    """``z - ln(1 + z)`` for ``z > -1`` (series for small ``|z|`` to avoid cancellation)."""
    if abs(z) < 1e-3:
        return sum((-1.0) ** k * z ** k / k for k in range(2, 14))
    return z - math.log1p(z)


def hunt_crossley_restitution(impact_velocity: float, damping_factor: float, exponent: float = 1.3) -> float:
    """Coefficient of restitution ``e = v_out / v_in`` of one free two-body Hunt-Crossley impact, Eq. (6).

    Two bodies, no springs or other forces, force ``F = k_c p^n (1 + lambda p')`` for ``p > 0``, never
    pulling.  With the reduced mass ``m`` and ``v = p'``: ``m v dv/dp = -k_c p^n (1 + lambda v)``, so

        ``v / (1 + lambda v) dv = -(k_c / m) p^n dp``  ->  ``G(v) - G(v_in) = -(k_c / m) p^(n+1) / (n+1)``

    with ``G(v) = integral_0^v w/(1 + lambda w) dw = v/lambda - ln(1 + lambda v)/lambda^2``.  The impact
    ends when ``p`` returns to 0, hence ``G(-v_out) = G(v_in)``.  Multiplying by ``lambda^2`` and writing
    ``u = lambda v_in``, ``z = -lambda v_out = -e u``: ``g(z) = g(u)`` with ``g(z) = z - ln(1 + z)``.
    So ``e`` depends on ``lambda v_in`` only -- not on ``k_c``, ``n`` (``exponent`` is accepted and checked
    but does not enter) or the masses.  ``g`` falls on ``(-1, 0)``, rises on ``(0, inf)``, ``g(0) = 0``:
    the root on the other side of 0 from ``u`` is unique.  ``lambda = 0`` gives ``e = 1``.

    Clipping: for ``lambda > 0`` the factor ``1 + lambda v`` is > 1 during compression; in restitution
    ``g(z) -> inf`` as ``z -> -1``, so ``p`` returns to 0 with ``lambda v_out < 1`` before the force could
    reach zero -- a free impact never clips (``e < min(1, 1/u)``).  Negative ``damping_factor`` models the
    literal sign reading ``(1 - lambda p')`` (energy injected, ``e > 1``); it needs ``1 + lambda v_in > 0``,
    otherwise the force is zero from the start (no impact) and ``ValueError`` is raised.

    Parameters
    ----------
    impact_velocity: approach velocity v_in (m/s, > 0).
    damping_factor: lambda (s/m).
    exponent: n (> 0); irrelevant to the result.
    """
    if not (math.isfinite(impact_velocity) and impact_velocity > 0):
        raise ValueError(f"impact_velocity must be > 0 m/s, got {impact_velocity!r}")
    if not (math.isfinite(exponent) and exponent > 0):
        raise ValueError(f"exponent must be > 0, got {exponent!r}")
    if not math.isfinite(damping_factor):
        raise ValueError(f"damping_factor must be finite, got {damping_factor!r}")
    u = damping_factor * impact_velocity
    if u == 0:
        return 1.0
    if u <= -1:
        raise ValueError(f"1 + lambda v_in = {1 + u:g} <= 0: the force is zero from the start, no impact")
    target = _g(u)
    if 0 < u < 1:   # z = -e u in (-u, 0): g(-u) > g(u) for 0 < u < 1
        z = brentq(lambda z: _g(z) - target, -u, 0.0, xtol=1e-300, rtol=8.9e-16, maxiter=500)
    elif u >= 1:    # z = -1 + exp(L) close to -1: solve for L = ln(1 + z) < 0, e^L - 1 - L = g(u)
        lo = -(target + 2.0)
        L = brentq(lambda L: math.expm1(L) - L - target, lo, 0.0, xtol=1e-300, rtol=8.9e-16, maxiter=500)
        z = math.expm1(L)
    else:           # literal sign, -1 < u < 0: z in (0, inf), g rising there
        hi = -u
        while _g(hi) < target:
            hi *= 2.0
        z = brentq(lambda z: _g(z) - target, 0.0, hi, xtol=1e-300, rtol=8.9e-16, maxiter=500)
    return -z / u
