"""The stability chart: the resistance a carriage allows at each elevation, the shortest stable recoil, and the
scene simulated there (``recoil stability SCENE --elevations 0:70:15``).

The closed form (DESIGN.md "The recoil axis on a carriage", quasi-static front load; references/recoil-data.md
2.2).  The rearmost support is the pivot (the spade, at ``P``), the front-most support unloads first.  With the
gun's weight moment about the pivot in battery ``g m_tot d`` (every mass times its CG's x - x_P), the recoiling
mass ``m_r`` (every body on the axis) and the axis' arm ``h(theta) = (y_t - y_P) cos theta - (x_t - x_P) sin
theta``, the front carries load while the resistance to recoil ``R`` (the force the elements transmit along the
axis) stays below

    R*_in(theta)     = m_r g sin theta + g m_tot d / h                      in battery
    R*_out(theta, L) = m_r g sin theta + g (m_tot d - m_r L cos theta) / h  at the end of a recoil L

(for ``h > 0``; for ``h <= 0`` the pull presses the front down: no limit from it).  A brake of constant
resistance over a recoil ``L`` absorbs the free-recoil energy ``E = M v0^2 / 2`` and the weight's work along the
axis: ``R = E / L + m_r g sin theta``, so ``R <= margin R*_out`` holds for

    margin g m_r cos theta L^2 - margin g m_tot d L + E h <= 0,

and the **shortest stable recoil** is its smaller root (none if the discriminant is negative: no recoil length
keeps the gun down).  The free-recoil energy's convention: the shot's momentum as the scene's firing gives it
(with the gas after-effect of ``charge_mass * gas_velocity`` where the scene has one), ``E = I^2 / (2 M)`` with the
barrel's mass ``M``; the recuperator and the friction are not in it (they are in the simulation).

At each elevation the scene itself (its own brake) is simulated with ``cradle.elevation`` set: its peak
resistance, stability margin, lift-off, pitch and recoil length are set beside the closed form.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, Callable, Sequence

from ..elements.barrel import free_recoil_speed
from ..elements.carriage import axis_point
from ..errors import SceneError
from ..scene import Scene
from ..scene.overrides import apply_overrides

#: The default fraction of the limit the resistance may reach (``--margin``).
DEFAULT_MARGIN = 0.8


@dataclass(frozen=True)
class ElevationPoint:
    """One elevation (degrees): the closed form's limits (N), the shortest stable recoil (m; None: no recoil keeps
    the gun down; inf: the pull never lifts the front), its resistance (N), and the simulation of the scene there
    (recoil m, peak resistance N, stability margin, lift-off s or None, max pitch rad; None if it failed, with
    ``error``).  ``recoil_margin``: the front support's least load over its static one during the recoil stroke
    (up to the max displacement), simulated; ``recoil_margin_closed_form``: the same from the closed form's front
    load with the simulated resistance and positions (:func:`front_load`); they agree while the carriage rests.
    ``lifts_on_counter_recoil``: a support left the ground after the recoil stroke (the return into battery)."""

    elevation: float
    arm: float
    limit_in_battery: float
    shortest_stable_recoil: float | None
    resistance_at_shortest: float | None
    limit_at_scene_recoil: float | None
    recoil: float | None = None
    peak_resistance: float | None = None
    stability_margin: float | None = None
    lift_off_time: float | None = None
    max_carriage_pitch: float | None = None
    recoil_margin: float | None = None
    recoil_margin_closed_form: float | None = None
    lifts_on_counter_recoil: bool | None = None
    error: str | None = None

    def to_dict(self) -> dict:
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in asdict(self).items()}


@dataclass(frozen=True)
class Geometry:
    """What the closed form needs of a scene: masses (kg), the carriage's weight moment ``m_c (x_c - x_P)`` (kg m)
    about the pivot, the pivot and trunnion (m), gravity (m/s^2) and the free-recoil energy (J)."""

    total_mass: float
    recoiling_mass: float
    carriage_moment: float
    pivot: tuple[float, float]
    trunnion: tuple[float, float]
    gravity: float
    energy: float

    @classmethod
    def of(cls, scene: Scene) -> "Geometry":
        carriage = scene.carriage
        if carriage is None:
            raise SceneError("carriage", "the stability chart needs a scene with a [carriage] table")
        pivot = min(carriage.supports, key=lambda s: s.position[0]).position
        bodies = [scene.barrel.mass] + [a.mass for a in scene.absorbers]
        recoiling = sum(bodies)
        total = carriage.mass + recoiling
        gravity = scene.cradle.gravity if scene.cradle is not None else 9.81
        speed = free_recoil_speed(scene) / (scene.burst.shots if getattr(scene, "burst", None) else 1)
        energy = 0.5 * scene.barrel.mass * speed ** 2
        moment = carriage.mass * (carriage.center_of_mass[0] - pivot[0])
        return cls(total, recoiling, moment, tuple(pivot), tuple(carriage.trunnion), gravity, energy)

    def weight_moment(self, scene: Scene, theta: float) -> float:
        """``m_tot d`` (kg m) in battery at ``theta`` (rad): the carriage's and the recoiling parts' (their CG at
        ``trunnion + b e``)."""
        x, _ = axis_point(scene.carriage, theta, 0.0)
        return self.carriage_moment + self.recoiling_mass * (x - self.pivot[0])

    def arm(self, theta: float) -> float:
        """h(theta) (m): the axis' arm about the pivot (module docstring)."""
        return ((self.trunnion[1] - self.pivot[1]) * math.cos(theta)
                - (self.trunnion[0] - self.pivot[0]) * math.sin(theta))


def closed_form(scene: Scene, elevation: float, margin: float = DEFAULT_MARGIN,
                scene_recoil: float | None = None) -> ElevationPoint:
    """The closed form's numbers at ``elevation`` (degrees) for ``margin`` (module docstring)."""
    geometry = Geometry.of(scene)
    theta = math.radians(elevation)
    h = geometry.arm(theta)
    g, m_r = geometry.gravity, geometry.recoiling_mass
    moment = geometry.weight_moment(scene, theta)
    weight_along = m_r * g * math.sin(theta)
    if h <= 0.0:  # the pull presses the front down: no limit from the front's lift-off
        return ElevationPoint(elevation, h, math.inf, math.inf, None, math.inf)
    limit_in = weight_along + g * moment / h
    a, b, c = margin * g * m_r * math.cos(theta), -margin * g * moment, geometry.energy * h
    disc = b * b - 4.0 * a * c
    shortest = resistance = None
    if disc >= 0.0:
        shortest = (-b - math.sqrt(disc)) / (2.0 * a) if a > 0.0 else -c / b
        resistance = geometry.energy / shortest + weight_along
    limit_out = None
    if scene_recoil is not None:
        limit_out = weight_along + g * (moment - m_r * scene_recoil * math.cos(theta)) / h
    return ElevationPoint(elevation, h, limit_in, shortest, resistance, limit_out)


def stability_chart(scene: Scene, elevations: Sequence[float], margin: float = DEFAULT_MARGIN, *,
                    end_time: float = 3.0, accuracy: str = "standard",
                    progress: Callable[[str], None] = lambda message: None) -> list[ElevationPoint]:
    """The chart (module docstring) at every elevation (degrees); a failed simulation is recorded, not raised."""
    from ..engine.simulation import simulate
    from ..errors import RecoilError

    if not 0.0 < margin <= 1.0:
        raise SceneError("--margin", f"must be in (0, 1], got {margin:g}")
    if scene.carriage is None:
        raise SceneError("carriage", "the stability chart needs a scene with a [carriage] table")
    points = []
    for k, elevation in enumerate(elevations):
        if not -90.0 <= elevation <= 90.0:
            raise SceneError("--elevations", f"every elevation must be in [-90, 90] degrees, got {elevation:g}")
        progress(f"elevation {elevation:g} deg ({k + 1}/{len(elevations)})")
        changes: dict[str, Any] = {}
        try:
            at = apply_overrides(scene, {"cradle.elevation": float(elevation)}) if scene.cradle is not None else \
                scene.with_changes(cradle=_cradle(elevation))
            result = simulate(at, end_time, accuracy)
            simulated, closed = recoil_margins(at, result)
            lift = result.lift_off_time
            changes = dict(recoil=result.max_barrel_displacement, peak_resistance=result.peak_support_force,
                           stability_margin=result.stability_margin, lift_off_time=lift,
                           max_carriage_pitch=result.max_carriage_pitch, recoil_margin=simulated,
                           recoil_margin_closed_form=closed,
                           lifts_on_counter_recoil=None if lift is None else lift > result.time_of_max_barrel_displacement)
        except RecoilError as exc:
            changes = {"error": f"{type(exc).__name__}: {' '.join(str(exc).split())[:300]}"}
        point = closed_form(scene, elevation, margin, changes.get("recoil"))
        points.append(ElevationPoint(**{**asdict(point), **changes}))
    return points


def front_load(scene: Scene, resistance, positions: dict) -> "np.ndarray":
    """The front-most support's load (N) by the closed form, from the resistance ``R`` (N, the force the elements
    transmit along the axis) and the axis bodies' positions (m) at the same times (DESIGN.md, with absorbers):

        N_f (x_f - x_P) = g (m_tot d - cos theta sum_j m_j x_j) - (R - g sin theta sum_j m_j) h(theta)."""
    import numpy as np

    geometry = Geometry.of(scene)
    theta = math.radians(scene.cradle.elevation if scene.cradle is not None else 0.0)
    masses = {"barrel": scene.barrel.mass, **{a.name: a.mass for a in scene.absorbers}}
    shift = sum(m * np.asarray(positions[name]) for name, m in masses.items() if name in positions)
    front = max(scene.carriage.supports, key=lambda s: s.position[0]).position
    g = geometry.gravity
    return (g * (geometry.weight_moment(scene, theta) - math.cos(theta) * shift)
            - (np.asarray(resistance) - g * math.sin(theta) * geometry.recoiling_mass) * geometry.arm(theta)) / (
        front[0] - geometry.pivot[0])


def recoil_margins(scene: Scene, result) -> tuple[float, float]:
    """(simulated, closed form): the front support's least load over its load at t = 0 during the recoil stroke
    (t up to the max barrel displacement); the closed form's with the run's resistance and positions."""
    import numpy as np

    front = max(scene.carriage.supports, key=lambda s: s.position[0]).name
    stroke = result.time <= result.time_of_max_barrel_displacement
    simulated = result.carriage.supports[front].normal_force
    closed = front_load(scene, result.support_force, result.positions)
    theta = math.radians(scene.cradle.elevation if scene.cradle is not None else 0.0)
    geometry = Geometry.of(scene)
    holding = geometry.gravity * math.sin(theta) * geometry.recoiling_mass  # R at rest
    static = front_load(scene, np.array([holding]), {name: values[:1] for name, values in result.positions.items()})
    return (float(np.min(simulated[stroke]) / result.carriage.supports[front].static_normal_force),
            float(np.min(closed[stroke]) / static[0]))


def _cradle(elevation: float):
    from ..elements.cradle import Cradle

    return Cradle(elevation=float(elevation))


def chart_figure(points: Sequence[ElevationPoint], title: str, margin: float):
    """Resistance and its limits against elevation (the simulated peaks as dots); recoil length against elevation
    (the shortest stable one of the closed form, and the scene's simulated recoil); the simulated stability
    margin."""
    from ..results.plotting import new_figure

    fig, axes = new_figure(3, 1, width=8.0, row_height=2.6)
    e = [p.elevation for p in points]

    def finite(values):
        return [v if v is not None and math.isfinite(v) else float("nan") for v in values]

    ax = axes[0, 0]
    ax.plot(e, finite([p.limit_in_battery / 1e3 for p in points]), "-", label="limit in battery (closed form)")
    ax.plot(e, finite([None if p.limit_at_scene_recoil is None else p.limit_at_scene_recoil / 1e3 for p in points]),
            "--", label="limit at the scene's recoil (closed form)")
    ax.plot(e, finite([None if p.resistance_at_shortest is None else p.resistance_at_shortest / 1e3
                       for p in points]), ":", label=f"constant resistance, shortest stable recoil (margin {margin:g})")
    ax.plot(e, finite([None if p.peak_resistance is None else p.peak_resistance / 1e3 for p in points]), "ko",
            ms=4, label="simulated peak resistance")
    ax.set_ylabel("resistance [kN]")
    ax.legend(fontsize=7)
    ax = axes[1, 0]
    ax.plot(e, finite([None if p.shortest_stable_recoil is None else p.shortest_stable_recoil * 1e3
                       for p in points]), "-", label="shortest stable recoil (closed form)")
    ax.plot(e, finite([None if p.recoil is None else p.recoil * 1e3 for p in points]), "ko", ms=4,
            label="simulated recoil (the scene's brake)")
    ax.set_ylabel("recoil length [mm]")
    ax.legend(fontsize=7)
    ax = axes[2, 0]
    ax.plot(e, finite([p.stability_margin for p in points]), "ko-", ms=4, lw=0.8)
    ax.axhline(0.0, color="#999999", lw=0.6)
    ax.set_ylabel("stability margin")
    ax.set_xlabel("elevation [deg]")
    fig.suptitle(title, fontsize=10)
    return fig


def summary_lines(points: Sequence[ElevationPoint]) -> list[str]:
    """One line per elevation: limits, shortest stable recoil, and the simulation's verdict."""
    def kn(value):
        return "-" if value is None else ("none" if not math.isfinite(value) else f"{value / 1e3:.1f} kN")

    def mm(value):
        return "none" if value is None else ("any" if not math.isfinite(value) else f"{value * 1e3:.0f} mm")

    lines = [f"{'elev':>5} {'limit in battery':>17} {'shortest stable':>16} {'recoil':>8} {'peak R':>9} "
             f"{'margin':>7} {'recoil: sim/cf':>15}  verdict"]
    for p in points:
        if p.error:
            verdict = p.error
        elif p.lift_off_time is None:
            verdict = "stays down"
        else:
            verdict = (f"lifts at {p.lift_off_time:.3g} s "
                       + ("on counter-recoil" if p.lifts_on_counter_recoil else "during the recoil"))
        margin = "-" if p.stability_margin is None else f"{p.stability_margin:.3f}"
        recoil = "-" if p.recoil_margin is None else f"{p.recoil_margin:.3f} / {p.recoil_margin_closed_form:.3f}"
        lines.append(f"{p.elevation:5g} {kn(p.limit_in_battery):>17} {mm(p.shortest_stable_recoil):>16} "
                     f"{mm(p.recoil):>8} {kn(p.peak_resistance):>9} {margin:>7} {recoil:>15}  {verdict}")
    return lines


__all__ = ["DEFAULT_MARGIN", "ElevationPoint", "Geometry", "closed_form", "stability_chart", "chart_figure",
           "summary_lines", "front_load", "recoil_margins"]
