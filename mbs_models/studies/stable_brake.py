"""Designing a variable-recoil brake that keeps the gun down at every elevation (``recoil design-brake --stable``).

The elevations are split into bands at ``bands`` (``up_to`` degrees, as ``[[recoil_brake.band]]``; the last band
reaches the highest elevation asked).  In each band:

1. **Recoil length**: the longest of the band's shortest stable recoils (the closed form of
   :mod:`~mbs_models.studies.stability_chart` at every elevation of the band, with ``margin``): the band's lowest
   elevation asks most.  Where every length is stable (the pull presses the front down) the band recoils
   ``max_recoil`` (the least force on the mount the clearance allows).  A length beyond ``max_recoil`` cannot be
   met: the band is designed for ``max_recoil`` and says so.
2. **Orifice**: the constant-resistance table for that length (:func:`~mbs_models.studies.brake_length.hit_recoil_length`,
   iterated on the simulation), designed on the scene without its carriage (the 1-D rule of
   :mod:`~mbs_models.studies.brake_design`) at the band's lowest elevation.
3. **Counter-recoil**: the scene on its carriage is simulated at every elevation of the band; while a support's
   least load falls below ``1 - margin`` of its static one (the buffer's forward pull on the return into battery
   tips the gun about its wheels), the band's counter-recoil orifice is narrowed (bisection on its scale: the
   return slower), at most :data:`COUNTER_RECOIL_RUNS` times; where no scale reaches that, until no support lifts.

The designed scene holds the bands (:class:`~mbs_models.elements.recoil_brake.BrakeBand`); every elevation is
simulated with it, and the design says where a support still lifts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Callable, Sequence

from ..elements.recoil_brake import BrakeBand, area_points
from ..errors import SceneError
from ..scene import Scene
from ..scene.overrides import apply_overrides
from .stability_chart import DEFAULT_MARGIN, closed_form

#: Simulations of the counter-recoil bisection per band.
COUNTER_RECOIL_RUNS = 8


@dataclass
class BandDesign:
    """One band: up to ``up_to`` degrees, over ``elevations``; the stable length the closed form asks (m; inf: any,
    None: none), the length designed for and achieved (m), the orifice table, the counter-recoil area (m^2) and a
    note where a target could not be met."""

    up_to: float
    elevations: list[float]
    shortest_stable: float | None
    design_length: float
    achieved: float
    orifice_area: object
    counter_recoil_orifice_area: float | None
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"up_to": self.up_to, "elevations": self.elevations,
                "shortest_stable_recoil": None if self.shortest_stable is None or math.isinf(self.shortest_stable)
                else self.shortest_stable,
                "design_length": self.design_length, "recoil_length": self.achieved,
                "orifice_area": [list(p) for p in area_points(self.orifice_area)],
                "counter_recoil_orifice_area": self.counter_recoil_orifice_area, "notes": self.notes}


@dataclass
class ElevationCheck:
    """The designed scene simulated at one elevation: recoil (m), peak resistance (N), stability margin, lift-off
    (s or None) and whether it is on counter-recoil."""

    elevation: float
    recoil: float
    peak_resistance: float
    stability_margin: float
    lift_off_time: float | None
    on_counter_recoil: bool | None

    def to_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class StableDesign:
    """The designed scene (with its bands), the bands, the check at every elevation; ``stable``: no support lifts.
    ``refused``: elevations at which the scene itself is invalid (its recuperator cannot hold the barrel in battery
    there, ...), with the reason; they are left out of the design."""

    scene: Scene
    bands: list[BandDesign]
    checks: list[ElevationCheck]
    refused: dict = field(default_factory=dict)

    @property
    def stable(self) -> bool:
        return all(c.lift_off_time is None for c in self.checks)

    def to_dict(self) -> dict:
        return {"stable": self.stable, "bands": [b.to_dict() for b in self.bands],
                "checks": [c.to_dict() for c in self.checks], "refused": self.refused}


def _at(scene: Scene, elevation: float) -> Scene:
    return apply_overrides(scene, {"cradle.elevation": float(elevation)})


def _without_carriage(scene: Scene) -> Scene:
    return scene.with_changes(carriage=None)


def _check(scene: Scene, elevation: float, end_time: float, accuracy: str) -> ElevationCheck:
    from ..engine.simulation import simulate

    result = simulate(_at(scene, elevation), end_time, accuracy)
    lift = result.lift_off_time
    return ElevationCheck(elevation, result.max_barrel_displacement, result.peak_support_force,
                          result.stability_margin, lift,
                          None if lift is None else lift > result.time_of_max_barrel_displacement)


def design_stable_brake(scene: Scene, elevations: Sequence[float], bands: Sequence[float] = (), *,
                        margin: float = DEFAULT_MARGIN, max_recoil: float = 1.0, accuracy: str = "standard",
                        end_time: float = 3.0, progress: Callable[[str], None] = lambda message: None) -> StableDesign:
    """The variable-recoil brake of ``scene`` (module docstring) for ``elevations`` (degrees), split at ``bands``."""
    from .brake_length import hit_recoil_length

    if scene.carriage is None or scene.cradle is None:
        raise SceneError("scene", "designing for stability needs a scene with a [carriage] and a [cradle]")
    if scene.recoil_brake is None:
        raise SceneError("recoil_brake", "designing a variable-recoil brake needs the scene's [recoil_brake] (its "
                                         "piston area, Cd and oil)")
    if not 0.0 < margin <= 1.0:
        raise SceneError("--margin", f"must be in (0, 1], got {margin:g}")
    if not max_recoil > 0.0:
        raise SceneError("--max-recoil", f"must be a length > 0 m, got {max_recoil:g}")
    elevations = sorted(float(e) for e in elevations)
    if not elevations:
        raise SceneError("--elevations", "needs at least one elevation")
    if any(not -90.0 <= e <= 90.0 for e in [*elevations, *bands]):
        raise SceneError("--elevations", "every elevation and band edge must be in [-90, 90] degrees")
    refused = {}
    for elevation in elevations:  # the scene must hold at each elevation (a recuperator's preload, ...)
        try:
            _at(scene, elevation)
        except SceneError as exc:
            refused[elevation] = f"{exc.key}: {exc.message}"
    elevations = [e for e in elevations if e not in refused]
    if not elevations:
        raise SceneError("--elevations", f"the scene is invalid at every elevation asked: {next(iter(refused.values()))}")
    edges = sorted(float(b) for b in bands if float(b) < elevations[-1]) + [elevations[-1]]
    designed_bands: list[BandDesign] = []
    lower = -math.inf
    for up_to in edges:
        inside = [e for e in elevations if lower < e <= up_to]
        lower = up_to
        if not inside:
            continue
        needs = [closed_form(scene, e, margin).shortest_stable_recoil for e in inside]
        notes = []
        if any(n is None for n in needs):
            shortest, length = None, max_recoil
            notes.append(f"no recoil length keeps the gun down at {inside[needs.index(None)]:g} deg by the closed "
                         f"form: designed for the longest allowed, {max_recoil:g} m")
        else:  # the most demanding elevation of the band; inf (any length is stable) asks nothing
            finite = [n for n in needs if math.isfinite(n)]
            shortest = max(finite) if finite else math.inf
            length = max_recoil if math.isinf(shortest) else shortest
            if length > max_recoil:
                notes.append(f"the shortest stable recoil {shortest:.4g} m exceeds the maximum {max_recoil:g} m: "
                             "designed for the maximum")
                length = max_recoil
        progress(f"band up to {up_to:g} deg: a constant resistance over {length:.4g} m at {inside[0]:g} deg")
        twin = _at(_without_carriage(scene), inside[0])
        try:
            hit = hit_recoil_length(twin, length, accuracy=accuracy, end_time=end_time)
        except SceneError as exc:  # too long for a constant resistance: the other elements stop the barrel sooner
            if exc.key != "recoil_length":
                raise
            longest = _longest_recoil(twin, accuracy, end_time)
            notes.append(f"{length:.4g} m is longer than any constant-resistance recoil on this scene at "
                         f"{inside[0]:g} deg (the other elements stop the barrel within {longest:.4g} m): designed "
                         f"for {0.98 * longest:.4g} m")
            length = 0.98 * longest
            hit = hit_recoil_length(twin, length, accuracy=accuracy, end_time=end_time)
        brake = hit.design.scene.recoil_brake
        band = BandDesign(up_to, inside, shortest, length, hit.recoil_length, brake.orifice_area,
                          brake.counter_recoil_orifice_area, notes)
        designed_bands.append(band)
        _tune_counter_recoil(scene, designed_bands, band, end_time, accuracy, progress, 1.0 - margin)
    final = _with_bands(scene, designed_bands)
    checks = []
    for elevation in elevations:
        progress(f"check at {elevation:g} deg")
        checks.append(_check(final, elevation, end_time, accuracy))
    return StableDesign(final, designed_bands, checks, refused)


def _longest_recoil(scene: Scene, accuracy: str, end_time: float) -> float:
    """The simulated recoil (m) of the longest constant-resistance design the rule accepts on ``scene``."""
    from ..engine.simulation import simulate
    from .brake_design import design_brake, longest_design_length

    limit = longest_design_length(scene, 1e-3)
    return simulate(design_brake(scene, limit).scene, end_time, accuracy).max_barrel_displacement


def _with_bands(scene: Scene, bands: Sequence[BandDesign]) -> Scene:
    """``scene`` with its brake's bands replaced by ``bands`` (the brake's own areas above the last)."""
    tables = tuple(BrakeBand(up_to=b.up_to, orifice_area=b.orifice_area,
                             counter_recoil_orifice_area=b.counter_recoil_orifice_area) for b in bands)
    return scene.with_changes(recoil_brake=replace(scene.recoil_brake, band=tables))


def _tune_counter_recoil(scene: Scene, bands: list[BandDesign], band: BandDesign, end_time: float, accuracy: str,
                         progress, target: float) -> None:
    """Narrow ``band``'s counter-recoil orifice (bisection on its scale in (0, 1]) until the stability margin at
    every elevation of the band is at least ``target`` (module docstring, step 3); if no scale reaches it, until no
    support lifts; a note of what was done or could not be."""
    start = band.counter_recoil_orifice_area
    if start is None or not isinstance(start, float):
        return

    def worst(scale: float) -> float:
        band.counter_recoil_orifice_area = start * scale
        candidate = _with_bands(scene, bands)
        return min(_check(candidate, e, end_time, accuracy).stability_margin for e in band.elevations)

    if worst(1.0) >= target:
        band.counter_recoil_orifice_area = start
        return
    for goal, words in ((target, f"keeps {target:.0%} of every support's static load"),
                        (1e-9, "does not lift the gun")):
        low, high, good = 0.0, 1.0, None  # high misses the goal; the largest scale that meets it
        for _ in range(COUNTER_RECOIL_RUNS):
            middle = 0.5 * (low + high)
            progress(f"band up to {band.up_to:g} deg: counter-recoil orifice x{middle:.3g}")
            if worst(middle) >= goal:
                low, good = middle, middle
            else:
                high = middle
        if good is not None:
            band.counter_recoil_orifice_area = start * good
            band.notes.append(f"counter-recoil orifice narrowed from {start:.3g} to {start * good:.3g} m^2: the "
                              f"return into battery {words}")
            return
    band.counter_recoil_orifice_area = start
    band.notes.append(f"narrowing the counter-recoil orifice down to {start * high:.3g} m^2 did not keep the gun down")


__all__ = ["BandDesign", "ElevationCheck", "StableDesign", "design_stable_brake", "COUNTER_RECOIL_RUNS"]
