"""The paper's equations of motion, Eqs. (1)-(8), as small vectorised numpy functions.

Written from the paper and DESIGN.md (Physics), independently of the Exudyn engine.

State vector ``y`` (leading axis of length 7; trailing axes allowed, so every function works on a
single state ``(7,)`` and on a batch ``(7, N)``)::

    y = [x_M, v_M, x_m, v_m, E_recoil_damper, E_absorber_damper, E_contact]
         m    m/s  m    m/s  J                J                  J

Positions are positive in the recoil direction; the last three entries are dissipated energies.

Forces (N)
----------
* recoil spring and damper on the barrel, Eqs. (1)-(3): ``-k x_M - c v_M`` with ``c = c_recoil`` while
  the barrel recoils (``v_M > 0``) and ``c_counter`` otherwise (the force is 0 at ``v_M = 0`` either way);
* absorber actuator ``(k_r, c_r)``: mount ``"barrel"`` (model (i), Eqs. 4-5) puts
  ``f_r = k_r (x_M - x_m) + c_r (v_M - v_m)`` on the absorber and ``-f_r`` on the barrel; mount
  ``"ground"`` (model (ii), Eqs. 7-8) puts ``-k_r x_m - c_r v_m`` on the absorber only;
* Hunt-Crossley contact, Eq. (6) with DESIGN's signs: penetration ``p = (x_M - x_m) - gap``, rate
  ``p' = v_M - v_m``, ``F = k_c p^n (1 + lambda p')`` while in contact, never negative; ``+F`` on the
  absorber, ``-F`` on the barrel.

Contact modes
-------------
The integrator (:mod:`validation.reference`) keeps the right-hand side smooth inside a segment by fixing a
:class:`Mode`: ``OFF`` (no force), ``ON`` (the Hunt-Crossley expression, evaluated without clipping so the
event functions see a smooth extension) or ``STICK``. ``STICK`` exists only with the
``compression_only`` convention: the force jumps from ``k_c p^n`` to 0 when ``p'`` reaches 0, and if the
other forces then push the bodies back together a Filippov sliding mode follows, ``p' = 0`` with the
contact force ``F = m_red (f_M/M - f_m/m)`` (``m_red = M m/(M + m)``) that keeps the penetration
constant, as long as ``0 < F < k_c p^n``.
"""

from __future__ import annotations

from dataclasses import dataclass

import math

import numpy as np

from mbs_models.scene import Scene

#: Contact modes.
OFF, ON, STICK = "off", "on", "stick"


@dataclass(frozen=True)
class Parameters:
    """Numbers of one scene in SI units, with the conventions folded in.

    ``lam`` is the signed damping factor (``-lambda`` with ``literal_lambda_sign``); ``gap_offset`` is the
    gap subtracted from ``x_M - x_m`` (``-gap`` with ``literal_gap_sign``).
    """

    M: float
    k: float
    c_recoil: float
    c_counter: float
    v0: float
    has_absorber: bool = False
    m: float = 1.0
    on_barrel: bool = False
    kr: float = 0.0
    cr: float = 0.0
    kc: float = 0.0
    n: float = 1.0
    lam: float = 0.0
    gap_offset: float = 0.0
    compression_only: bool = False

    @classmethod
    def from_scene(cls, scene: Scene) -> "Parameters":
        """Extract the parameters of ``scene`` (v0 from ``scene.initial_velocity``)."""
        base = dict(M=scene.barrel.mass, k=scene.recoil_spring.stiffness,
                    c_recoil=scene.recoil_damper.recoil, c_counter=scene.recoil_damper.counter_recoil,
                    v0=float(scene.initial_velocity))
        a, c, conv = scene.absorber, scene.contact, scene.conventions
        if a is None:
            return cls(**base)
        return cls(**base, has_absorber=True, m=a.mass, on_barrel=(a.mount == "barrel"), kr=a.stiffness,
                   cr=a.damping, kc=c.stiffness, n=c.exponent,
                   lam=-c.damping_factor if conv.literal_lambda_sign else c.damping_factor,
                   gap_offset=-c.gap if conv.literal_gap_sign else c.gap,
                   compression_only=conv.compression_only)

    @property
    def m_red(self) -> float:
        """Reduced mass M m / (M + m) in kg."""
        return self.M * self.m / (self.M + self.m)

    @property
    def symmetric_damper(self) -> bool:
        """True when the recoil damper has one coefficient (no switch at v_M = 0)."""
        return self.c_recoil == self.c_counter


@dataclass(frozen=True)
class Mode:
    """Smooth regime of one integration segment: contact mode and damper branch."""

    contact: str = OFF
    recoil: bool = True  # True: c = c_recoil (v_M > 0); False: c = c_counter
    penetrated: bool = False  # p > 0 (always so for ON and STICK; OFF with p > 0 = clipped force)

    def damping(self, P: Parameters) -> float:
        """Recoil damper coefficient c (N s/m) of this branch, Eqs. (2)-(3)."""
        return P.c_recoil if self.recoil else P.c_counter


def signed_power(p, n):
    """``sign(p) |p|^n``: ``p^n`` for ``p >= 0``, a smooth odd extension for tiny negative ``p``."""
    return np.copysign(np.abs(p) ** n, p)


def penetration(P: Parameters, y):
    """Contact penetration p (m), > 0 in contact."""
    return y[0] - y[2] - P.gap_offset


def penetration_rate(P: Parameters, y):
    """Penetration rate p' = v_M - v_m (m/s)."""
    return y[1] - y[3]


def damping_term(P: Parameters, y):
    """Hunt-Crossley factor ``s = 1 + lambda p'`` (``1 - lambda p'`` with the literal sign)."""
    return 1.0 + P.lam * (y[1] - y[3])


def absorber_relative(P: Parameters, y):
    """Actuator elongation and rate: (x_M - x_m, v_M - v_m) on the barrel, (x_m, v_m) on the ground."""
    if P.on_barrel:
        return y[0] - y[2], y[1] - y[3]
    return y[2], y[3]


def other_forces(P: Parameters, y, mode: Mode):
    """Non-contact forces (N) on barrel and absorber: (f_M, f_m), Eqs. (1), (4)-(5), (7)-(8)."""
    f_M = -P.k * y[0] - mode.damping(P) * y[1]
    if not P.has_absorber:
        return f_M, 0.0 * y[2]
    if P.on_barrel:
        f_r = P.kr * (y[0] - y[2]) + P.cr * (y[1] - y[3])
        return f_M - f_r, f_r
    return f_M, -P.kr * y[2] - P.cr * y[3]


def sticking_force(P: Parameters, f_M, f_m):
    """Contact force (N) that keeps p' = 0 in the STICK mode: m_red (f_M/M - f_m/m)."""
    return P.m_red * (f_M / P.M - f_m / P.m)


def raw_contact_force(P: Parameters, y, mode: Mode, f_M=None, f_m=None):
    """Contact force (N) of ``mode`` without clipping (smooth inside a segment)."""
    if not P.has_absorber or mode.contact == OFF:
        return 0.0 * y[0]
    if mode.contact == ON:
        return P.kc * signed_power(penetration(P, y), P.n) * damping_term(P, y)
    if f_M is None:
        f_M, f_m = other_forces(P, y, mode)
    return sticking_force(P, f_M, f_m)


def contact_force(P: Parameters, y, mode: Mode):
    """Contact force (N) for reporting: the raw force clipped to >= 0."""
    return np.maximum(raw_contact_force(P, y, mode), 0.0)


def accelerations(P: Parameters, y, mode: Mode):
    """(a_M, a_m) in m/s^2 from Eqs. (1), (4)-(5) or (7)-(8) with the contact force of ``mode``."""
    f_M, f_m = other_forces(P, y, mode)
    F = raw_contact_force(P, y, mode, f_M, f_m)
    a_M = (f_M - F) / P.M
    a_m = (f_m + F) / P.m if P.has_absorber else 0.0 * y[2]
    return a_M, a_m


def contact_elastic_energy(P: Parameters, y):
    """Elastic contact energy k_c max(p, 0)^(n+1) / (n+1) in J."""
    if not P.has_absorber:
        return 0.0 * y[0]
    return P.kc * np.maximum(penetration(P, y), 0.0) ** (P.n + 1.0) / (P.n + 1.0)


def rhs(P: Parameters, mode: Mode, t, y):
    """Time derivative of the 7-state vector in ``mode`` (dissipated powers in W as the last three).

    Contact dissipation is the non-conservative power ``F p' - k_c p^n p'`` (force power minus the rate of
    elastic contact energy); with the clipped force (``F = 0`` while ``p > 0``) the stored elastic energy
    that vanishes counts as dissipated; with the literal lambda sign it is negative (energy injected).
    ``p^n`` is taken from ``mode`` (``mode.penetrated``), not from the sign of ``p``, so that the
    right-hand side stays smooth across the segment's end (solver stages may look past an event).

    The same equations as :func:`other_forces`, :func:`raw_contact_force` and :func:`accelerations`,
    written out on Python floats for one state (the integrator calls it ~10^4 times per run; numpy
    scalar arithmetic made it 5x slower).  ``tests/test_validation_reference.py`` checks the two
    forms against each other.
    """
    try:
        return _rhs(P, mode, *y[:4].tolist())
    except OverflowError:
        # a rejected trial step of an explicit method on a stiff contact: numpy gave inf here, and so
        # does this; the integrator rejects the step (its error estimate is inf)
        return np.full(7, np.inf)


def _rhs(P: Parameters, mode: Mode, x_M: float, v_M: float, x_m: float, v_m: float) -> np.ndarray:
    """:func:`rhs` on Python floats (raises OverflowError where numpy would give inf)."""
    c = P.c_recoil if mode.recoil else P.c_counter
    f_M = -P.k * x_M - c * v_M
    d_rec = c * v_M ** 2
    if not P.has_absorber:
        return np.array([v_M, f_M / P.M, v_m, 0.0, d_rec, 0.0, 0.0])
    rel_x, rel_v = x_M - x_m, v_M - v_m
    if P.on_barrel:
        f_r = P.kr * rel_x + P.cr * rel_v
        f_M, f_m = f_M - f_r, f_r
        d_abs = P.cr * rel_v ** 2
    else:
        f_m = -P.kr * x_m - P.cr * v_m
        d_abs = P.cr * v_m ** 2
    p = rel_x - P.gap_offset
    if mode.penetrated or mode.contact != OFF:
        elastic = P.kc * math.copysign(abs(p) ** P.n, p)
    else:
        elastic = 0.0
    if mode.contact == OFF:
        F = 0.0
    elif mode.contact == ON:
        F = elastic * (1.0 + P.lam * rel_v)
    else:
        F = P.M * P.m / (P.M + P.m) * (f_M / P.M - f_m / P.m)
    return np.array([v_M, (f_M - F) / P.M, v_m, (f_m + F) / P.m, d_rec, d_abs, (F - elastic) * rel_v])


def energy_components(P: Parameters, y) -> dict:
    """Energies in J: kinetic, recoil spring, absorber spring, contact elastic, and the dissipated ones."""
    rel_x, _ = absorber_relative(P, y) if P.has_absorber else (0.0 * y[0], None)
    return {
        "kinetic": 0.5 * P.M * y[1] ** 2 + (0.5 * P.m * y[3] ** 2 if P.has_absorber else 0.0 * y[0]),
        "recoil_spring": 0.5 * P.k * y[0] ** 2,
        "absorber_spring": 0.5 * P.kr * rel_x ** 2,
        "contact_elastic": contact_elastic_energy(P, y),
        "recoil_damper": y[4],
        "absorber_damper": y[5],
        "contact": y[6],
    }
