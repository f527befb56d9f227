"""The carriage's panels of ``recoil run --plot``: the ground reactions with the pitch, and a sketch of the gun.

Only a carriage scene gets them (:func:`mbs_models.results.plotting.plot_result` asks :func:`carriage_rows`).
"""

from __future__ import annotations

import math

import numpy as np

from .result import Result

#: Colours of the supports, in order.
SUPPORT_COLOURS = ("#1b6ca8", "#c0392b", "#27ae60", "#8e44ad", "#d35400")


def carriage_rows(result: Result) -> int:
    """Rows the carriage adds to the figure: 2 (reactions and pitch; the sketch), 0 without a carriage."""
    return 0 if result.carriage is None else 2


def plot_ground_reactions(ax, result: Result) -> None:
    """Each support's normal force (solid) and tangential force (dashed), kN, and the pitch change (mrad, grey,
    right axis); the lift-off time marked."""
    carriage = result.carriage
    for i, (name, support) in enumerate(carriage.supports.items()):
        colour = SUPPORT_COLOURS[i % len(SUPPORT_COLOURS)]
        ax.plot(result.time, support.normal_force / 1e3, color=colour, lw=1.0,
                label=f"{name} N (static {support.static_normal_force / 1e3:.1f}, min "
                      f"{support.min_normal_force / 1e3:.1f} kN)")
        if np.any(support.tangential_force):
            ax.plot(result.time, support.tangential_force / 1e3, color=colour, lw=0.8, ls="--", label=f"{name} T")
    if carriage.lift_off_time is not None:
        ax.axvline(carriage.lift_off_time, color="k", lw=0.6, ls=":")
    ax.axhline(0.0, color="#999999", lw=0.6)
    ax.set_ylabel("ground reactions [kN]")
    ax.legend(fontsize=7, loc="upper right")
    twin = ax.twinx()
    twin.plot(result.time, (carriage.pitch - carriage.static_pitch) * 1e3, color="#777777", lw=0.8)
    twin.set_ylabel("pitch change [mrad]", color="#777777")
    twin.tick_params(axis="y", colors="#777777")


def sketch_gun(ax, result: Result) -> None:
    """The gun in its static equilibrium, to scale (carriage frame, m): the ground, the supports (triangles with
    their static and smallest loads), the carriage (the polygon through its supports, CG and trunnion), the recoil
    axis at the elevation with the barrel at battery, and the verdict (stays down / lifts off at t)."""
    scene, carriage = result.scene, result.carriage
    table = scene.carriage
    theta = math.radians(scene.cradle.elevation) if scene.cradle is not None else 0.0
    e = np.array([math.cos(theta), math.sin(theta)])
    points = np.array([s.position for s in table.supports])
    trunnion = np.array(table.trunnion)
    outline = np.vstack([points[np.argsort(points[:, 0])], trunnion])
    ax.fill(outline[:, 0], outline[:, 1], color="#dddddd", ec="#777777", lw=1.0, zorder=1)
    xs = np.concatenate([points[:, 0], [trunnion[0]]])
    span = max(float(np.ptp(xs)), 1.0)
    ground = (xs.min() - 0.15 * span, xs.max() + 0.35 * span)
    ax.plot(ground, (0.0, 0.0), color="#6b4f2a", lw=2.0, zorder=0)
    barrel_cg = trunnion + table.barrel_center_of_mass * e
    length = 0.45 * span
    muzzle, breech = barrel_cg + length * e, barrel_cg - 0.35 * length * e
    ax.plot([breech[0], muzzle[0]], [breech[1], muzzle[1]], color="#333333", lw=4.0, solid_capstyle="round", zorder=3)
    ax.plot(*trunnion, "o", color="k", ms=5, zorder=4)
    ax.annotate("trunnion", trunnion, textcoords="offset points", xytext=(6, 6), fontsize=7)
    ax.plot(*table.center_of_mass, "+", color="k", ms=9, mew=1.5, zorder=4)
    ax.annotate("carriage CG", table.center_of_mass, textcoords="offset points", xytext=(-8, -12), ha="right",
                fontsize=7)
    for i, support in enumerate(table.supports):
        colour = SUPPORT_COLOURS[i % len(SUPPORT_COLOURS)]
        output = carriage.supports[support.name]
        ax.plot(*support.position, "^", color=colour, ms=9, zorder=5)
        ax.annotate(f"{support.name}\n{output.static_normal_force / 1e3:.1f} kN static\n"
                    f"{output.min_normal_force / 1e3:.1f} kN min", support.position, textcoords="offset points",
                    xytext=(0, -8), ha="center", va="top", fontsize=7, color=colour)
    verdict = ("stays down: every support keeps "
               f"{carriage.stability_margin:.0%} of its static load" if carriage.lift_off_time is None else
               f"a support leaves the ground at t = {carriage.lift_off_time:.4g} s "
               f"(lift {carriage.max_lift * 1e3:.2f} mm)")
    ax.set_title(f"elevation {math.degrees(theta):g} deg: {verdict}", fontsize=9)
    top = max(float(muzzle[1]), float(trunnion[1])) + 0.1 * span
    ax.plot([ground[0], ground[1]], [-0.3 * span, top], alpha=0.0)  # the extent to show (equal scales)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m] (forward)")
    ax.set_ylabel("y [m]")
