"""Magnitudes implausible for a recoil mechanism: unit slips that no range check can refuse.

A barrel mass typed in tonnes (``mass = 5.6`` for 5600 kg) or a breech-force pulse in ms and kN is a valid
number: the scene loads, and the run then diverges, or the barrel never moves.  :func:`implausible_magnitudes`
finds such values from the scene alone, each with the key to fix.  They are warnings
(:class:`~mbs_models.errors.UnitWarning`, given by :func:`mbs_models.engine.unit_slips.warn_unit_slips`),
never errors: nothing is clamped or refused.  A gap or stop position beyond the barrel's travel (a length in
mm) is found by :mod:`mbs_models.engine.reach`, which needs the assembled mechanism.

The checks (DESIGN.md "Unit slips" gives each threshold's reason from real guns):

* **free-recoil velocity** ``v = I / M`` (``I`` the firing momentum, or a pulse's impulse when the scene
  gives no projectile; ``M`` the barrel mass; ``v0`` as the conventions read it for an impulse shot), or
  ``barrel.initial_velocity`` as given, above :data:`MAX_RECOIL_VELOCITY`: key ``barrel.mass`` (a mass in tonnes) or
  ``barrel.initial_velocity`` (a velocity in mm/s);
* **pulse duration** (last minus first time of ``[firing.pulse]``) above :data:`MAX_PULSE_DURATION`: key
  ``firing.pulse.times`` (or ``.file``; times in ms);
* **pulse impulse** ``integral F dt`` of a pulse not scaled to the momentum, against the firing momentum
  when the scene gives it: a ratio outside ``[1 / IMPULSE_RATIO, IMPULSE_RATIO]``, key
  ``firing.pulse.forces`` (or ``.file``; forces in kN, kgf or lbf; times in ms);
* **peak pulse force** (as applied, after any scaling) below :data:`MIN_PEAK_FORCE_PER_WEIGHT` times the
  barrel's weight ``M g0``: key ``firing.pulse.forces`` (or ``.file``; forces in kN);
* **a carriage**: its mass outside :data:`CARRIAGE_MASS_RATIO` recoiling masses (``carriage.mass``, in tonnes), its
  points spanning outside :data:`CARRIAGE_SPAN` (``carriage.support``, positions in mm), a support sinking outside
  :data:`SUPPORT_PENETRATION` under the whole gun's weight (``carriage.support.N.stiffness``, in N/mm or kN/m).
"""

from __future__ import annotations

from dataclasses import dataclass

from .container import Scene

#: m/s: the largest plausible free-recoil velocity of a barrel, ``I / M``.
MAX_RECOIL_VELOCITY = 30.0
#: s: the longest plausible breech-force pulse (in-bore time plus the gas after-effect).
MAX_PULSE_DURATION = 0.1
#: A pulse's impulse within a factor of this of the firing momentum (either way) is plausible.
IMPULSE_RATIO = 3.0
#: The smallest plausible peak breech force, in barrel weights ``M g0``.
MIN_PEAK_FORCE_PER_WEIGHT = 1.0
#: m/s^2: standard gravity g0 (the weight scale of the barrel).
STANDARD_GRAVITY = 9.80665


@dataclass(frozen=True)
class Implausible:
    """A magnitude of the scene that is implausible for a recoil mechanism: ``key`` (the scene key to fix)
    and ``text`` (one line: the key, its value, the plausible range and the likely slip)."""

    key: str
    text: str

    def message(self) -> str:
        """The one line naming the key."""
        return self.text


def _recoil_velocity(scene: Scene) -> list[Implausible]:
    barrel, firing = scene.barrel, scene.firing
    limit = f"(plausible: up to {MAX_RECOIL_VELOCITY:g} m/s)"
    if firing is None:
        v0 = float(barrel.initial_velocity)
        if abs(v0) <= MAX_RECOIL_VELOCITY:
            return []
        return [Implausible("barrel.initial_velocity", f"barrel.initial_velocity = {v0:g} m/s is faster than any "
                                                       f"gun's recoil {limit}; a velocity in mm/s?")]
    # an impulse shot: v0 as the scene reads it (its conventions); a pulse: the firing momentum over M (the
    # pulse's impulse when the scene gives no projectile; a pulse at odds with the momentum is _pulse's)
    velocity = scene.initial_velocity if firing.pulse is None else firing.momentum / barrel.mass
    if velocity <= MAX_RECOIL_VELOCITY:
        return []
    return [Implausible("barrel.mass", f"barrel.mass = {barrel.mass:g} kg gives a recoil velocity of {velocity:.4g} "
                                       f"m/s for the shot's momentum of {firing.momentum:.4g} kg m/s {limit}; "
                                       f"a mass in tonnes?")]


def _pulse(scene: Scene) -> list[Implausible]:
    firing = scene.firing
    pulse = None if firing is None else firing.pulse
    if pulse is None:
        return []
    out = []
    if pulse.file is None:
        times_key, forces_key, times_name, forces_name = ("firing.pulse.times", "firing.pulse.forces",
                                                          "firing.pulse.times", "firing.pulse.forces")
    else:
        times_key = forces_key = "firing.pulse.file"
        times_name, forces_name = (f"firing.pulse.file = {pulse.file!r}: its {what}" for what in ("times", "forces"))
    if pulse.duration > MAX_PULSE_DURATION:
        out.append(Implausible(times_key, f"{times_name} span {pulse.duration:g} s, longer than any breech pressure "
                                          f"pulse (plausible: up to {MAX_PULSE_DURATION:g} s); times in ms?"))
    if not pulse.scale_to_momentum and firing.projectile_mass is not None:
        ratio = pulse.impulse / firing.momentum
        if not 1.0 / IMPULSE_RATIO <= ratio <= IMPULSE_RATIO:
            slip = "forces in kN, kgf or lbf?" if ratio < 1.0 else "times in ms?"
            out.append(Implausible(forces_key, f"{forces_name} give an impulse of {pulse.impulse:.4g} N s, {ratio:.3g} "
                                               f"times the shot's momentum of {firing.momentum:.4g} kg m/s (plausible: "
                                               f"1/{IMPULSE_RATIO:g} to {IMPULSE_RATIO:g} times); {slip}"))
    scale = firing.momentum / pulse.impulse if pulse.scale_to_momentum else 1.0
    peak = scale * max(pulse.table[1])
    weight = scene.barrel.mass * STANDARD_GRAVITY
    if peak < MIN_PEAK_FORCE_PER_WEIGHT * weight:
        out.append(Implausible(forces_key, f"{forces_name} peak at {peak:.5g} N, below the barrel's weight of "
                                           f"{weight:.5g} N (plausible: at least "
                                           f"{MIN_PEAK_FORCE_PER_WEIGHT:g} x the weight); forces in kN?"))
    return out


#: The plausible carriage mass, in recoiling masses (towed guns 0.3-3; a self-propelled hull up to ~10).
CARRIAGE_MASS_RATIO = (0.1, 30.0)
#: m: the plausible span of a carriage's points (supports, CG, trunnion): a gun is metres long.
CARRIAGE_SPAN = (0.2, 30.0)
#: m: the plausible static penetration of a support (a tyre's deflection at most; a spade's soil at least).
SUPPORT_PENETRATION = (1e-9, 0.3)


def _carriage(scene: Scene) -> list[Implausible]:
    """The carriage's mass against the recoiling parts', its points' span, each support's static penetration."""
    carriage = getattr(scene, "carriage", None)
    if carriage is None:
        return []
    out = []
    recoiling = scene.barrel.mass + sum(a.mass for a in scene.absorbers)
    ratio = carriage.mass / recoiling
    low, high = CARRIAGE_MASS_RATIO
    if not low <= ratio <= high:
        out.append(Implausible("carriage.mass", f"carriage.mass = {carriage.mass:g} kg is {ratio:.3g} times the "
                                                f"recoiling mass of {recoiling:g} kg (plausible: {low:g} to {high:g} "
                                                f"times); a mass in tonnes?"))
    points = [s.position for s in carriage.supports] + [carriage.center_of_mass, carriage.trunnion]
    span = max(max(abs(a[0] - b[0]), abs(a[1] - b[1])) for a in points for b in points)
    low, high = CARRIAGE_SPAN
    if not low <= span <= high:
        out.append(Implausible("carriage.support", f"the carriage's points (supports, center_of_mass, trunnion) span "
                                                   f"{span:g} m (plausible: {low:g} to {high:g} m); positions in mm?"))
    weight = STANDARD_GRAVITY * (carriage.mass + recoiling)
    low, high = SUPPORT_PENETRATION
    for i, support in enumerate(carriage.supports):
        sunk = support.static_penetration(weight)
        if not low <= sunk <= high:
            out.append(Implausible(f"carriage.support.{i}.stiffness",
                                   f"carriage.support.{i}.stiffness = {support.stiffness:g} sinks the support by "
                                   f"{sunk:.3g} m under the whole gun's weight (plausible: {low:g} to {high:g} m); "
                                   f"a stiffness in N/mm or kN/m?"))
    return out


def implausible_magnitudes(scene: Scene) -> list[Implausible]:
    """Every implausible magnitude of ``scene`` (module docstring), barrel first, then the pulse and the carriage;
    [] for a plausible scene."""
    return _recoil_velocity(scene) + _pulse(scene) + _carriage(scene) + _tables(scene)


def _tables(scene: Scene) -> list[Implausible]:
    """The findings an element's table gives itself: ``table.implausible(key) -> [(key, text), ...]`` (the tabulated
    characteristics: a table in mm or mm/s)."""
    return [Implausible(key, text) for table_key, table in scene.tables() if hasattr(table, "implausible")
            for key, text in table.implausible(table_key)]


__all__ = ["Implausible", "implausible_magnitudes", "MAX_RECOIL_VELOCITY", "MAX_PULSE_DURATION", "IMPULSE_RATIO",
           "MIN_PEAK_FORCE_PER_WEIGHT", "STANDARD_GRAVITY", "CARRIAGE_MASS_RATIO", "CARRIAGE_SPAN",
           "SUPPORT_PENETRATION"]
