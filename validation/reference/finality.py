"""Energy bounds that tell the reference solver when a peak metric can no longer change.

Written from the equations of :mod:`validation.reference.equations`, independently of the engine's
``mbs_models.engine.final_metrics`` (the two implementations are compared by the tests).

For a dissipative scene the mechanical energy
``E = kinetic + recoil spring + absorber spring + contact elastic`` (J, see
:func:`validation.reference.equations.energy_components`) never increases: its rate is minus the dissipated
power of :func:`validation.reference.equations.rhs`, which is >= 0 for the recoil damper (``c v_M^2``), the
absorber damper (``c_r v_rel^2``) and the contact (``(F - k_c p^n) p'``: ``lambda k_c p^n p'^2``
unclipped, ``-k_c p^n p' > 0`` clipped at ``p' < -1/lambda``; with ``compression_only`` the force is
``k_c p^n s`` or 0 for ``p' <= 0``, and in the sliding mode ``p' = 0``).  Only ``literal_lambda_sign``
(``lambda < 0`` in :class:`~validation.reference.equations.Parameters`) injects energy: no bound then.

Each energy term is at most E, so at every later time (values in SI units):

* ``x_M <= sqrt(2 E / k)``;  ``|v_m| <= sqrt(2 E / m)``;
* ``x_M - x_m <= sqrt(2 E / k_r)`` (absorber on the barrel) or ``sqrt(2 E (1/k + 1/k_r))`` (on the
  ground: maximise ``a + b`` subject to ``k a^2 + k_r b^2 <= 2 E``);
* ``p = x_M - x_m - gap_offset``: none reachable when the bound above is <= ``gap_offset``, else
  ``p <= min(((n+1) E / k_c)^(1/(n+1)), bound - gap_offset)``;
* ``|p'| <= sqrt(2 E / m_red)``, ``m_red = M m / (M + m)`` (the kinetic energy is at least
  ``1/2 m_red p'^2``);
* ``F <= k_c p_max^n (1 + lambda |p'|_max)``;
* with the absorber on the ground and no contact reachable, the absorber alone keeps
  ``1/2 m v_m^2 + 1/2 k_r x_m^2`` from increasing.

The bounds are used with ``E (1 + ENERGY_SLACK)`` (integration error of the energy).
"""

from __future__ import annotations

import math

import numpy as np

from . import equations as eq
from .equations import Parameters

#: The metrics that can be proven final (names of :class:`~validation.reference.result.ReferenceResult` properties).
METRICS = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "impacts")
#: Relative margin on the energy in every bound.
ENERGY_SLACK = 1e-4
#: A bound counts as reached within this relative margin.  The terminal event's root is located to
#: ~1e-16 s, but the margin there is zero only to the event function's slope times that: measured
#: -1.005e-12 (model (ii), m = 500 kg, gap 120 mm, the force bound against the impact threshold),
#: which with a 1e-12 tolerance restarted the solve at the same instant for ever.  1e-9 is far below
#: the bounds' own ENERGY_SLACK (a 5e-5 relative margin on every square-root bound).
ROOT_TOLERANCE = 1e-9


def check_names(names) -> tuple[str, ...]:
    """The requested metric names as a tuple; ValueError naming ``stop_when_final`` and the allowed values."""
    if isinstance(names, str):
        raise ValueError(f"stop_when_final must be a sequence of metric names, not a string; allowed: "
                         f"{', '.join(METRICS)}")
    names = tuple(names)
    unknown = [n for n in names if n not in METRICS]
    if unknown:
        raise ValueError(f"stop_when_final: unknown metric {unknown[0]!r}; allowed: {', '.join(METRICS)}")
    return tuple(n for n in METRICS if n in names)


def mechanical_energy(P: Parameters, y):
    """E in J of a state ``y`` (7,) or batch (7, N): kinetic + springs + contact elastic energy."""
    parts = eq.energy_components(P, y)
    return parts["kinetic"] + parts["recoil_spring"] + parts["absorber_spring"] + parts["contact_elastic"]


def _sqrt_over(energy, stiffness_or_mass):
    return math.inf if stiffness_or_mass <= 0 else math.sqrt(2.0 * max(energy, 0.0) / stiffness_or_mass)


def bounds(P: Parameters, energy: float) -> dict[str, float]:
    """Bounds valid at every later time for a dissipative scene with energy ``energy`` (J) now.

    Keys: ``x_M`` (m), and with an absorber ``v_m`` (m/s), ``relative`` (x_M - x_m, m), ``p`` (m),
    ``p_rate`` (m/s), ``force`` (N); ``reachable`` (1.0 / 0.0: can the contact close again).
    """
    out = {"x_M": _sqrt_over(energy, P.k)}
    if not P.has_absorber:
        return out
    out["v_m"] = _sqrt_over(energy, P.m)
    if P.kr <= 0 or (not P.on_barrel and P.k <= 0):
        relative = math.inf
    elif P.on_barrel:
        relative = _sqrt_over(energy, P.kr)
    else:
        relative = math.sqrt(2.0 * max(energy, 0.0) * (1.0 / P.k + 1.0 / P.kr))
    out["relative"] = relative
    reachable = relative > P.gap_offset
    out["reachable"] = 1.0 if reachable else 0.0
    p = 0.0
    if reachable:
        p = min(((P.n + 1.0) * max(energy, 0.0) / P.kc) ** (1.0 / (P.n + 1.0)), relative - P.gap_offset)
    out["p"] = p
    out["p_rate"] = _sqrt_over(energy, P.m_red)
    out["force"] = P.kc * p ** P.n * (1.0 + abs(P.lam) * out["p_rate"]) if p > 0 else 0.0
    return out


class Finality:
    """Running maxima of a reference solve and the finality decisions (see the module docstring).

    ``observed`` holds lower bounds of the maxima over the time integrated so far (values of the
    solution at grid points): x_M (m), v_m (m/s), F (N).  :meth:`gaps` gives, per metric not yet
    final, ``observed - bound`` at a state: final once >= 0.
    """

    def __init__(self, P: Parameters, requested, impact_threshold: float):
        self.P = P
        self.requested = check_names(requested)
        self.impact_threshold = float(impact_threshold)
        self.enabled = P.lam >= 0  # literal_lambda_sign injects energy
        self.observed = {"x_M": -math.inf, "v_m": -math.inf, "force": 0.0}
        self.final: set[str] = set() if P.has_absorber else {"peak_contact_force", "max_absorber_velocity", "impacts"}

    @property
    def done(self) -> bool:
        return self.enabled and bool(self.requested) and set(self.requested) <= self.final

    def observe_segment(self, mode, sol, t0: float, t1: float) -> None:
        """Fold the values of one finished segment (dense output ``sol`` on [t0, t1]) into the maxima."""
        ts = np.asarray(sol.ts, dtype=float)
        ts = np.unique(np.concatenate(([t0], ts[(ts > t0) & (ts < t1)], [t1])))
        y = sol(ts)
        self.observed["x_M"] = max(self.observed["x_M"], float(np.max(y[0])))
        if self.P.has_absorber:
            self.observed["v_m"] = max(self.observed["v_m"], float(np.max(y[3])))
            self.observed["force"] = max(self.observed["force"], float(np.max(eq.contact_force(self.P, y, mode))))

    def gaps(self, y, contact_off: bool, names=None, continuous: bool = False) -> dict[str, float]:
        """Relative margin ``(observed - bound) / |observed|`` per metric in ``names`` (default: the
        requested ones) not yet final; final once >= -:data:`ROOT_TOLERANCE`.  ``contact_off``: no
        contact force acts in the current segment (no impact episode is going on).  ``continuous``
        leaves out the free-absorber refinement, which jumps where the contact becomes unreachable
        (an event function must be continuous for its root to be a state where the margin is 0)."""
        names = self.requested if names is None else names
        P = self.P
        energy = float(mechanical_energy(P, y)) * (1.0 + ENERGY_SLACK)
        b = bounds(P, energy)
        out = {}
        for name in names:
            if name in self.final:
                continue
            if name == "max_barrel_displacement":
                observed, bound = self.observed["x_M"], b["x_M"]
            elif name == "peak_contact_force":  # the bound is 0 once no contact is reachable
                observed, bound = self.observed["force"], b["force"]
            elif name == "impacts":
                observed, bound = self.impact_threshold, (b["force"] if contact_off else math.inf)
            else:  # max_absorber_velocity
                observed, bound = self.observed["v_m"], b["v_m"]
                if not continuous and not b["reachable"] and not P.on_barrel:
                    own = (0.5 * P.m * y[3] ** 2 + 0.5 * P.kr * y[2] ** 2) * (1.0 + ENERGY_SLACK)
                    bound = min(bound, _sqrt_over(own, P.m))
            if not math.isfinite(bound) or not math.isfinite(observed):
                out[name] = -math.inf
            else:
                out[name] = (observed - bound) / (abs(observed) if observed != 0 else 1.0)
        return out

    def check(self, y, contact_off: bool, names=None) -> None:
        """Mark the metrics that the state ``y`` proves final."""
        if not self.enabled:
            return
        for name, gap in self.gaps(y, contact_off, names).items():
            if gap >= -ROOT_TOLERANCE:
                self.final.add(name)

    def stop_event(self, contact_off: bool):
        """Terminal solve_ivp event: crosses 0 upwards when every requested metric becomes final.

        Uses the maxima observed *before* the segment: a bound below them is below the maximum
        up to the event too.
        """
        def event(t, y):
            gaps = self.gaps(y, contact_off, continuous=True)
            return min(1.0, max(-1.0, min(gaps.values()))) if gaps else 1.0
        event.terminal = True
        event.direction = 1.0
        return event
