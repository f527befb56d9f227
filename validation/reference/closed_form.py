"""Closed-form oracles (no ODE solver): the simplified model's maximum and the restitution of a free impact.

* :func:`simplified_max_displacement` -- the simplified model's first maximum;
* :func:`hunt_crossley_restitution` -- a free Hunt-Crossley impact (depends on ``lambda v_in`` only);
* :func:`restitution_factor`, :func:`exact_restitution_factor` -- ``chi`` of the restitution laws;
* :func:`achieved_restitution` -- what a free two-body impact really rebounds with, for every law;
* :func:`kelvin_voigt_restitution` -- the same for Kelvin-Voigt, clipped (the law) or not (the classic
  linear oscillator).

All are derived in their docstrings and used by the tests to check :func:`validation.solve_reference`.
"""

from __future__ import annotations

import math
import sys

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
    return _free_restitution(damping_factor * impact_velocity)


def _free_restitution(u: float) -> float:
    """e of a free Hunt-Crossley impact with ``u = lambda v_in`` (see :func:`hunt_crossley_restitution`)."""
    if not math.isfinite(u):
        raise ValueError(f"lambda v_in must be finite, got {u!r}")
    if u == 0:
        return 1.0
    if u <= -1:
        raise ValueError(f"1 + lambda v_in = {1 + u:g} <= 0: the force is zero from the start, no impact")
    target = _g(u)
    if 0 < u < 1:   # z = -e u in (-u, 0): g(-u) > g(u) for 0 < u < 1
        z = brentq(lambda z: _g(z) - target, -u, 0.0, xtol=1e-300, rtol=8.9e-16, maxiter=500)
    elif u >= 1:    # z = -1 + exp(L) close to -1: solve for L = ln(1 + z) < 0, e^L - 1 - L = g(u)
        def f(L: float) -> float:
            return math.expm1(L) - L - target

        lo = -(target + 2.0)
        if not f(lo) > 0.0:  # g(u) >= 2^53: the 2 is lost to round-off; the root is near -(g(u) + 1)
            lo = max(-2.0 * (target + 1.0), -sys.float_info.max)
        L = brentq(f, lo, 0.0, xtol=1e-300, rtol=8.9e-16, maxiter=500)
        z = math.expm1(L)
    else:           # literal sign, -1 < u < 0: z in (0, inf), g rising there
        hi = -u
        while _g(hi) < target:
            hi *= 2.0
        z = brentq(lambda z: _g(z) - target, 0.0, hi, xtol=1e-300, rtol=8.9e-16, maxiter=500)
    return -z / u


# ================================================================================== restitution laws
#: The laws of the form ``k p^n (1 + chi p'/v-)`` (DESIGN.md, "Contact laws").
RESTITUTION_LAWS = ("lankarani-nikravesh", "flores", "gonthier", "exact-restitution")


def _check_restitution(restitution: float) -> float:
    e = float(restitution)
    if not (math.isfinite(e) and 0.0 < e <= 1.0):
        raise ValueError(f"restitution must be in (0, 1], got {restitution!r}")
    return e


def exact_restitution_factor(restitution: float) -> float:
    """``chi`` of the ``exact-restitution`` law: a free two-body impact then rebounds with exactly ``e``.

    A restitution law ``F = k p^n (1 + chi p'/v-)`` is, during one free impact, Hunt-Crossley with
    ``lambda = chi / v-`` (v- is the impact's own approach rate), so ``lambda v_in = chi`` and the rebound
    is ``e(chi)`` of :func:`hunt_crossley_restitution`: ``g(-e chi) = g(chi)``, ``g(z) = z - ln(1 + z)``, i.e.
    ``chi - ln(1 + chi) = -chi e - ln(1 - chi e)``.  ``e(u)`` falls from 1 (u = 0) towards 0 (u -> inf) and
    ``e(u) < 1/u``, so for ``0 < e < 1`` the root lies in ``(0, 1/e)``, where ``e(u) - e`` changes sign
    once: it is found by bracketing (``brentq``) on ``e(chi) - e`` itself, not on the logarithmic relation
    (whose ``1 - chi e`` cancels for small e).  ``e = 1`` gives 0.
    """
    e = _check_restitution(restitution)
    if e == 1.0:
        return 0.0
    high = 1.0 / e
    if not _free_restitution(high) < e:  # e(1/e) < e holds exactly, not always after round-off (e ~ 1e-305)
        high = min(2.0 / e, sys.float_info.max)
    return brentq(lambda chi: _free_restitution(chi) - e, 1e-300, high, xtol=1e-300, rtol=8.9e-16, maxiter=500)


def restitution_factor(law: str, restitution: float) -> float:
    """``chi`` (dimensionless) of a restitution law for the restitution ``e`` it is given (DESIGN.md)::

        lankarani-nikravesh   chi = 3 (1 - e^2) / 4
        flores                chi = 8 (1 - e) / (5 e)
        gonthier              chi = (1 - e^2) / e
        exact-restitution     chi = exact_restitution_factor(e)
    """
    e = _check_restitution(restitution)
    if law == "lankarani-nikravesh":
        return 3.0 * (1.0 - e * e) / 4.0
    if law == "flores":
        return 8.0 * (1.0 - e) / (5.0 * e)
    if law == "gonthier":
        return (1.0 - e * e) / e
    if law == "exact-restitution":
        return exact_restitution_factor(e)
    raise ValueError(f"{law!r} is not a restitution law ({', '.join(RESTITUTION_LAWS)})")


def kelvin_voigt_restitution(damping_ratio: float, clipped: bool = True) -> float:
    """Restitution of a free two-body Kelvin-Voigt impact, ``F = k p + c p'`` (never pulling if ``clipped``).

    With the reduced mass m, ``w = sqrt(k/m)``, the damping ratio ``zeta = c / (2 sqrt(k m))``, ``sigma =
    zeta w``, and ``p(0) = 0``, ``p'(0) = v-``, the impact is the linear oscillator ``m p'' = -k p - c p'``
    while the force acts.  Nothing depends on v- (the equation is linear) and k, c, m enter through
    zeta only.

    * **Unclipped** (the classic result): for ``zeta < 1``, ``wd = w sqrt(1 - zeta^2)``,
      ``p = (v-/wd) e^(-sigma t) sin(wd t)`` returns to 0 at ``wd t = pi`` with
      ``p' = -v- e^(-sigma pi / wd)``: ``e = exp(-zeta pi / sqrt(1 - zeta^2))``; for ``zeta >= 1`` p never
      returns to 0 (e = 0).  The force ``k p + c p'`` is then negative at the end: it pulls.
    * **Clipped** (the law here): the force is ``F = -m p''``, so it reaches 0 where ``p'' = 0``, i.e. at
      the extremum of p'.  For ``zeta < 1`` write ``p' = v- (w/wd) e^(-sigma t) cos(wd t + b)`` with
      ``sin b = zeta``; then ``p'' = -v- (w^2/wd) e^(-sigma t) sin(wd t + 2b)``, zero at ``wd t_c = pi - 2b
      = 2 arccos(zeta)``, where p > 0 still (``sin(pi - 2b) > 0``) and ``p'(t_c) = -v- e^(-sigma t_c)``
      (``w cos b / wd = 1``).  From then on no force acts (``k p + c p'`` only falls as p shrinks at
      constant ``p' < 0``): ``e = exp(-sigma t_c) = exp(-2 zeta arccos(zeta) / sqrt(1 - zeta^2))``.  For
      ``zeta > 1`` the same steps with ``zeta = cosh(a)``, ``g = w sqrt(zeta^2 - 1)``: ``g t_c = 2 a`` and
      ``e = exp(-2 zeta arccosh(zeta) / sqrt(zeta^2 - 1))``; both tend to ``e^(-2)`` at ``zeta = 1``.
      The clipped impact rebounds faster than the classic one (it loses the pull at the end).
    """
    zeta = float(damping_ratio)
    if not (math.isfinite(zeta) and zeta >= 0):
        raise ValueError(f"damping_ratio must be a finite number >= 0, got {damping_ratio!r}")
    if zeta == 0:
        return 1.0
    if not clipped:
        if zeta >= 1:
            return 0.0
        return math.exp(-zeta * math.pi / math.sqrt((1.0 - zeta) * (1.0 + zeta)))
    if zeta < 1:
        root = math.sqrt((1.0 - zeta) * (1.0 + zeta))   # sin of the angle arccos(zeta)
        ratio = math.atan2(root, zeta) / root           # arccos(zeta) / sqrt(1 - zeta^2), -> 1 at zeta = 1
    elif zeta == 1:
        ratio = 1.0
    else:
        root = math.sqrt((zeta - 1.0) * (zeta + 1.0))   # sinh of arccosh(zeta)
        ratio = math.log1p((zeta - 1.0) + root) / root  # arccosh(zeta) / sqrt(zeta^2 - 1)
    return math.exp(-2.0 * zeta * ratio)


def achieved_restitution(law: str, restitution: float | None = None, *, lambda_v: float | None = None,
                         damping_ratio: float | None = None) -> float:
    """Restitution ``e = -p'_out / v-`` that a free two-body impact really has under ``law``.

    Free impact: two bodies, no other force, contact from ``p = 0`` at ``v- > 0``.

    * restitution laws (``restitution`` = the e asked for): the law is Hunt-Crossley with
      ``lambda = chi / v-`` (``restitution_factor``), so ``e`` solves ``g(-e chi) = g(chi)`` -- whatever k, n,
      v- and the masses; it never clips (``e < 1/chi``).  Lankarani-Nikravesh, Flores and Gonthier give
      back only approximately what they are asked (0.5 -> about 0.73 for Lankarani-Nikravesh);
      exact-restitution gives it back exactly.
    * ``hunt-crossley``: give ``lambda_v`` = lambda v_in (dimensionless); e is that of
      :func:`hunt_crossley_restitution`.
    * ``hertz``: 1 (conservative).
    * ``kelvin-voigt``: give ``damping_ratio`` = ``c / (2 sqrt(k m_red))``; the law is clipped, so this is
      :func:`kelvin_voigt_restitution` with ``clipped=True`` (not the classic
      ``exp(-zeta pi / sqrt(1 - zeta^2))``).
    """
    if law in RESTITUTION_LAWS:
        if restitution is None:
            raise ValueError(f"law {law!r} needs the restitution it is asked for")
        return _free_restitution(restitution_factor(law, restitution))
    if law == "hunt-crossley":
        if lambda_v is None:
            raise ValueError("hunt-crossley's restitution depends on lambda v_in: give lambda_v")
        return _free_restitution(float(lambda_v))
    if law == "hertz":
        return 1.0
    if law == "kelvin-voigt":
        if damping_ratio is None:
            raise ValueError("kelvin-voigt's restitution depends on the damping ratio c / (2 sqrt(k m)): "
                             "give damping_ratio")
        return kelvin_voigt_restitution(damping_ratio, clipped=True)
    raise ValueError(f"unknown contact law {law!r}")
