"""When is a metric final?  Energy bounds on everything a dissipative scene can still do.

The sweeps and studies need peak metrics (Table 2's maximum barrel displacement, the peak contact
force, the maximum absorber velocity), which occur in the first second of a 10 s run.  This module
proves, from the state at one instant, that no later instant can beat the maxima seen so far; the
engine (:func:`mbs_models.simulate` with ``stop_when_final``) then stops the solve there.

Energy
------
The mechanical energy (J) of a scene is ::

    E = 1/2 M v_M^2 + 1/2 m v_m^2 + 1/2 k x_M^2 + 1/2 k_r s^2 + k_c max(p, 0)^(n+1) / (n+1)

with ``s = x_M - x_m`` (absorber on the barrel, model (i)) or ``s = x_m`` (on the ground, model
(ii)) and ``p`` the contact penetration (m).  Its rate is minus the dissipated power:
``c(v_M) v_M^2`` (recoil damper, c >= 0), ``c_r s'^2`` (absorber damper) and, for the contact,
``F p' - k_c p^n p'``.  With the Hunt-Crossley force ``F = max(k_c p^n (1 + lambda p'), 0)`` the
contact term is ``lambda k_c p^n p'^2 >= 0`` where the force is not clipped and ``-k_c p^n p' > 0``
where it is (clipping needs ``1 + lambda p' < 0``, i.e. ``p' < 0``); with ``compression_only`` the
force is that or 0 (then ``-k_c p^n p'`` with ``p' <= 0``): every term is >= 0, so **E never
increases**.  ``literal_gap_sign`` moves the surface, ``v0_includes_absorber`` and
``rounded_initial_velocity`` change the start only: still dissipative.  ``literal_lambda_sign``
makes the contact term ``-lambda k_c p^n p'^2`` during compression -- energy is injected -- so no
bound holds and :func:`dissipative` is False: such scenes always run to their end time.

Bounds (every term of E is >= 0, so each is <= E(t) at every later time)
-----------------------------------------------------------------------
* barrel position ``x_M <= sqrt(2 E / k)`` (m); none if k = 0;
* absorber velocity ``v_m <= sqrt(2 E / m)`` (m/s); with the absorber on the ground and no contact
  reachable any more, the absorber is a free damped oscillator whose own energy
  ``E_a = 1/2 m v_m^2 + 1/2 k_r x_m^2`` never increases: ``v_m <= sqrt(2 E_a / m)``;
* relative displacement ``x_M - x_m``: on the barrel ``|x_M - x_m| <= sqrt(2 E / k_r)``; on the
  ground ``x_M - x_m <= |x_M| + |x_m| <= sqrt(2 E (1/k + 1/k_r))`` (Cauchy-Schwarz on
  ``1/2 k x_M^2 + 1/2 k_r x_m^2 <= E``); none if a stiffness is 0;
* penetration ``p = (x_M - x_m) - gap`` (``+ gap`` with ``literal_gap_sign``): no contact is
  reachable once the relative-displacement bound is <= the gap offset; otherwise
  ``p <= min(((n+1) E / k_c)^(1/(n+1)), relative bound - gap offset)``;
* penetration rate ``|p'| <= |v_M| + |v_m| <= sqrt(2 E (1/M + 1/m))`` (Cauchy-Schwarz on the kinetic
  energy);
* contact force ``F <= k_c p_max^n (1 + lambda |p'|_max)``, 0 if no contact is reachable.

Finality (what :class:`FinalityTracker` decides from the states it is shown)
---------------------------------------------------------------------------
* ``max_barrel_displacement`` (and its time): final once the x_M bound <= the largest x_M seen;
* ``max_absorber_velocity`` (signed maximum, and its time): once the v_m bound <= the largest v_m seen;
* ``peak_contact_force``: once no contact is reachable, or the force bound <= the largest force seen;
* ``impacts`` (episodes whose peak exceeds the impact threshold): once the force bound is <= the
  threshold and no contact is going on (the last episode has ended; later ones cannot count).

Ties keep the earliest time, as the peak refinement does.  The observed values are samples of the
solution, hence lower bounds of its refined maxima: a metric proven final from samples is final.

Numerical slack: a numerical solution dissipates energy only up to its integration error, so the
bounds use ``E (1 + ENERGY_SLACK)``.  :func:`mbs_models.simulate` trusts an early stop only if the
solution's energy rose by no more than that fraction anywhere in the simulated window
(:func:`largest_energy_rise`), and otherwise re-solves to the end time.
"""

from __future__ import annotations

import math
from typing import Iterable

from .errors import SceneError
from .forces import hunt_crossley_force
from .scene import Scene

#: Metrics that can be proven final before the end time (names of :class:`~mbs_models.result.Result` fields).
FINAL_METRICS = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "impacts")
#: Relative margin on the energy in every bound: covers the integration error of the solution's
#: energy (a relative rise of ~1e-9 per step at the presets' tolerances; see largest_energy_rise).
ENERGY_SLACK = 1e-4
#: Why a run ended (``Result.stop_reason``).
STOP_END_TIME = "end_time"                  # reached the requested end time (no early stop asked, or not proven)
STOP_METRICS_FINAL = "metrics_final"        # every metric named in stop_when_final was proven final
STOP_NO_BOUND = "end_time_no_energy_bound"  # early stop asked, but the scene injects energy (literal_lambda_sign)
STOP_ENERGY_CHECK = "end_time_energy_check"  # stopped early, but the energy error exceeded the slack: re-solved


def check_metric_names(names, key: str = "stop_when_final") -> tuple[str, ...]:
    """Validate a collection of metric names; return them as a tuple in :data:`FINAL_METRICS` order.

    Raises SceneError naming ``key`` and the allowed values for a string (not a sequence of names),
    an unknown name or a non-string item.
    """
    if isinstance(names, str):
        raise SceneError(key, f"must be a sequence of metric names (e.g. ({names!r},)), not a string; "
                              f"allowed: {', '.join(FINAL_METRICS)}")
    try:
        items = list(names)
    except TypeError:
        raise SceneError(key, f"must be a sequence of metric names; allowed: {', '.join(FINAL_METRICS)}") from None
    for name in items:
        if not isinstance(name, str) or name not in FINAL_METRICS:
            raise SceneError(key, f"unknown metric {name!r}; allowed: {', '.join(FINAL_METRICS)}")
    return tuple(name for name in FINAL_METRICS if name in items)


def dissipative(scene: Scene) -> bool:
    """True when the scene's mechanical energy never increases (every convention but literal_lambda_sign)."""
    return not scene.conventions.literal_lambda_sign


class EnergyBounds:
    """The bounds of the module docstring for one scene, as functions of the energy ``E`` (J) now.

    Every method returns a bound on the quantity at *every later time* of a :func:`dissipative`
    scene (``math.inf`` where no bound exists, e.g. a zero stiffness).  The scene's numbers are
    folded into a few coefficients once, so that each call costs a microsecond.
    """

    def __init__(self, scene: Scene):
        self.scene = scene
        k = scene.recoil_spring.stiffness
        self._half_M, self._half_k = 0.5 * scene.barrel.mass, 0.5 * k
        self._x_coefficient = 2.0 / k if k > 0 else math.inf          # x_M^2 <= 2 E / k
        absorber, contact = scene.absorber, scene.contact
        self.has_absorber = absorber is not None
        if not self.has_absorber:
            return
        self.on_barrel = absorber.mount == "barrel"
        self._half_m, self._half_kr = 0.5 * absorber.mass, 0.5 * absorber.stiffness
        self._v_coefficient = 2.0 / absorber.mass                       # v_m^2 <= 2 E / m
        if absorber.stiffness <= 0 or (not self.on_barrel and k <= 0):
            self._rel_coefficient = math.inf
        else:                                                           # (x_M - x_m)^2 <= 2 E compliance
            self._rel_coefficient = 2.0 * (1.0 / absorber.stiffness if self.on_barrel
                                           else 1.0 / k + 1.0 / absorber.stiffness)
        self._rate_coefficient = 2.0 * (1.0 / scene.barrel.mass + 1.0 / absorber.mass)   # p'^2 <= 2 E / m_red
        self.gap_offset = -contact.gap if scene.conventions.literal_gap_sign else contact.gap
        self._k_c, self._n = contact.stiffness, contact.exponent
        self._elastic = (contact.exponent + 1.0) / contact.stiffness     # p^(n+1) <= (n+1) E / k_c
        self._lambda = contact.damping_factor

    # ---------------------------------------------------------------------------- the state
    def contact_force(self, relative_position: float, relative_velocity: float) -> float:
        """Hunt-Crossley force in N (>= 0) for ``x_M - x_m`` (m) and ``p' = v_M - v_m`` (m/s):
        :func:`mbs_models.forces.hunt_crossley_force` with the scene's conventions."""
        return hunt_crossley_force(relative_position, relative_velocity, self.scene.contact,
                                   self.scene.conventions)

    def energy(self, x_M: float, v_M: float, x_m: float = 0.0, v_m: float = 0.0) -> float:
        """E in J at the state (m, m/s): kinetic + springs + contact elastic energy."""
        energy = self._half_M * v_M * v_M + self._half_k * x_M * x_M
        if self.has_absorber:
            s = x_M - x_m if self.on_barrel else x_m
            energy += self._half_m * v_m * v_m + self._half_kr * s * s
            p = x_M - x_m - self.gap_offset
            if p > 0.0:
                energy += p ** (self._n + 1.0) / self._elastic
        return energy

    def absorber_energy(self, x_m: float, v_m: float) -> float:
        """The absorber's own energy 1/2 m v_m^2 + 1/2 k_r x_m^2 in J (model (ii): conserved but for c_r)."""
        return self._half_m * v_m * v_m + self._half_kr * x_m * x_m

    # ---------------------------------------------------------------------------- bounds
    def barrel_displacement(self, energy: float) -> float:
        """Bound (m) on x_M; inf if k = 0."""
        return math.sqrt(self._x_coefficient * max(energy, 0.0))

    def absorber_velocity(self, energy: float) -> float:
        """Bound (m/s) on |v_m|."""
        return math.sqrt(self._v_coefficient * max(energy, 0.0))

    def relative_displacement(self, energy: float) -> float:
        """Bound (m) on x_M - x_m; inf if a needed stiffness is 0."""
        return math.sqrt(self._rel_coefficient * max(energy, 0.0))

    def contact_reachable(self, energy: float) -> bool:
        """False when the energy cannot bring wall A to the absorber (p > 0) ever again."""
        return self.relative_displacement(energy) > self.gap_offset

    def penetration(self, energy: float) -> float:
        """Bound (m) on the penetration p (0 if no contact is reachable)."""
        relative = self.relative_displacement(energy)
        if not relative > self.gap_offset:
            return 0.0
        return min((self._elastic * max(energy, 0.0)) ** (1.0 / (self._n + 1.0)), relative - self.gap_offset)

    def penetration_rate(self, energy: float) -> float:
        """Bound (m/s) on |p'| = |v_M - v_m|."""
        return math.sqrt(self._rate_coefficient * max(energy, 0.0))

    def contact_force_bound(self, energy: float) -> float:
        """Bound (N) on the contact force (0 if no contact is reachable)."""
        p = self.penetration(energy)
        if p <= 0.0:
            return 0.0
        return self._k_c * p ** self._n * (1.0 + self._lambda * self.penetration_rate(energy))


def mechanical_energy(scene: Scene, x_M: float, v_M: float, x_m: float = 0.0, v_m: float = 0.0) -> float:
    """E in J at the state of ``scene`` (positions m, velocities m/s); see :class:`EnergyBounds`."""
    return EnergyBounds(scene).energy(x_M, v_M, x_m, v_m)


def largest_energy_rise(energy) -> float:
    """Largest relative rise ``max_{i <= j} (E_j - E_i) / E_i`` of a sampled energy history (J).

    0 for a non-increasing history; inf if the energy rises from exactly 0.  This is the assumption
    behind every bound, checked on the simulated window.
    """
    import numpy as np

    e = np.asarray(energy, dtype=float)
    if e.size < 2:
        return 0.0
    future_max = np.maximum.accumulate(e[::-1])[::-1]
    rise = future_max - e
    if np.any((rise > 0) & (e <= 0)):
        return math.inf
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = np.where(rise > 0, rise / np.where(e > 0, e, 1.0), 0.0)
    return float(np.max(relative))


class FinalityTracker:
    """Watches the states of one solve and says which metrics are final (see the module docstring).

    Show it the states in time order with :meth:`observe` (m, m/s); :attr:`final` holds the metrics
    proven final so far (once final, always final) and :attr:`final_at` the time (s) each was proven.
    ``requested`` are the metrics the caller wants; :attr:`done` is True once all of them are final
    (never for a non-dissipative scene).
    For a scene without absorber the contact metrics do not exist and count as final from the start.
    A scene that is not :func:`dissipative` never proves anything.
    """

    def __init__(self, scene: Scene, requested: Iterable[str], impact_threshold: float):
        self.scene = scene
        self.bounds = EnergyBounds(scene)
        self.requested = check_metric_names(requested)
        self.impact_threshold = float(impact_threshold)
        self.enabled = dissipative(scene)
        self.max_barrel_position = -math.inf
        self.max_absorber_velocity = -math.inf
        self.max_contact_force = 0.0
        self.final: set[str] = set()
        self.final_at: dict[str, float] = {}
        self.done = False
        if scene.absorber is None:
            self._mark(("peak_contact_force", "max_absorber_velocity", "impacts"), 0.0)

    def _mark(self, names: Iterable[str], t: float) -> None:
        for name in names:
            if name not in self.final:
                self.final.add(name)
                self.final_at[name] = float(t)
        self.done = self.enabled and bool(self.requested) and all(name in self.final for name in self.requested)

    def observe(self, t: float, x_M: float, v_M: float, x_m: float = 0.0, v_m: float = 0.0) -> bool:
        """Take the state at time ``t`` (s) into account; return :attr:`done`.

        The state updates the running maxima (samples of the solution: lower bounds of its maxima,
        so observing only some states is safe, it merely proves finality a little later), then the
        bounds of the requested metrics are evaluated at it.
        """
        if x_M > self.max_barrel_position:
            self.max_barrel_position = x_M
        force = 0.0
        bounds = self.bounds
        if bounds.has_absorber:
            if v_m > self.max_absorber_velocity:
                self.max_absorber_velocity = v_m
            force = bounds.contact_force(x_M - x_m, v_M - v_m)
            if force > self.max_contact_force:
                self.max_contact_force = force
        if self.enabled:
            self.check(t, x_M, v_M, x_m, v_m, force, self.requested)
        return self.done

    def check(self, t: float, x_M: float, v_M: float, x_m: float = 0.0, v_m: float = 0.0,
              force: float = 0.0, names: Iterable[str] = FINAL_METRICS) -> None:
        """Mark those of ``names`` that the energy at this state (contact force ``force`` N) proves final."""
        if not self.enabled:
            return
        todo = [name for name in names if name not in self.final]
        if not todo:
            return
        bounds = self.bounds
        energy = bounds.energy(x_M, v_M, x_m, v_m) * (1.0 + ENERGY_SLACK)
        newly = []
        if "max_barrel_displacement" in todo and bounds.barrel_displacement(energy) <= self.max_barrel_position:
            newly.append("max_barrel_displacement")
        if bounds.has_absorber and len(todo) > ("max_barrel_displacement" in todo):
            reachable = bounds.contact_reachable(energy)
            force_bound = bounds.contact_force_bound(energy)
            if not reachable or force_bound <= self.max_contact_force:
                newly.append("peak_contact_force")
            if force_bound <= self.impact_threshold and force == 0.0:
                newly.append("impacts")
            velocity_bound = bounds.absorber_velocity(energy)
            if not reachable and not bounds.on_barrel:  # model (ii): a free damped oscillator from now on
                own = bounds.absorber_energy(x_m, v_m) * (1.0 + ENERGY_SLACK)
                velocity_bound = min(velocity_bound, bounds.absorber_velocity(own))
            if velocity_bound <= self.max_absorber_velocity:
                newly.append("max_absorber_velocity")
        if newly:
            self._mark(newly, t)

    def observe_last(self, t: float, x_M: float, v_M: float, x_m: float = 0.0, v_m: float = 0.0) -> None:
        """Observe the final state of a solve and check *every* metric there (not only the requested ones)."""
        self.observe(t, x_M, v_M, x_m, v_m)
        force = self.bounds.contact_force(x_M - x_m, v_M - v_m) if self.bounds.has_absorber else 0.0
        self.check(t, x_M, v_M, x_m, v_m, force, FINAL_METRICS)
