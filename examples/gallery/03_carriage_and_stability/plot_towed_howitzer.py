"""
The towed howitzer: does it stay on the ground?
===============================================

A gun's recoil mechanism does not push against a fixed ground: it pushes against its carriage, which rests on
wheels and a spade and may pitch, lift and slide. The ``[carriage]`` table puts the recoil axis on a planar
rigid carriage; every element keeps its law, and its reaction goes into the carriage. The shipped
``towed_howitzer`` scenes put realistic recoil hardware (a breech-force pulse, a brake designed for constant
resistance, a recuperator, a battery buffer) on a 4.4 t carriage with two wheels and a spade, at 0 and 45
degrees of elevation.
"""

# %%
# The gun
# -------
# The carriage frame has its origin at the spade's tip, x forward and y up. The recoil axis passes through
# the trunnion at the cradle's elevation; the barrel recoils rearward along it, towards the spade.
import math

import matplotlib.pyplot as plt

from mbs_models import load_scene, simulate
from mbs_models.scenes import scene_path

level = load_scene(scene_path("towed_howitzer"))
raised = load_scene(scene_path("towed_howitzer_45"))
carriage = level.carriage
print(f"carriage {carriage.mass:.0f} kg, barrel {level.barrel.mass:.0f} kg, trunnion at {carriage.trunnion} m")
for support in carriage.supports:
    print(f"  support {support.name:<7} at {support.position} m, {support.law}")

fig, ax = plt.subplots(figsize=(7, 3), layout="constrained")
for support in carriage.supports:
    ax.plot(*support.position, "^", ms=12, label=support.name)
ax.plot(*carriage.center_of_mass, "ks", label="carriage CG")
for scene, style in ((level, "-"), (raised, "--")):
    theta = math.radians(scene.cradle.elevation)
    tx, ty = scene.carriage.trunnion
    ax.plot([tx - 1.5 * math.cos(theta), tx + 3.0 * math.cos(theta)],      # breech side ... muzzle side
            [ty - 1.5 * math.sin(theta), ty + 3.0 * math.sin(theta)], "k" + style, lw=1,
            label=f"recoil axis at {scene.cradle.elevation:g} deg")
ax.plot(*carriage.trunnion, "ro", label="trunnion")
ax.axhline(0.0, color="saddlebrown", lw=2)
ax.set_aspect("equal")
ax.set_xlabel("x [m]")
ax.set_ylabel("y [m]")
ax.legend(fontsize=7, loc="upper left")

# %%
# Firing at 0 and 45 degrees
# --------------------------
# The result carries the carriage's metrics: the ``stability_margin`` (the least load of any support over its
# static load: 1 never unloads, 0 a support leaves the ground), the ``lift_off_time``, the largest pitch and
# lift, and per support its static, least and largest normal force. ``draft`` accuracy is enough to read a
# stability margin (its error against the reference is about 2e-3).
runs = {scene.cradle.elevation: simulate(scene, 2.0, "draft") for scene in (level, raised)}
for elevation, result in runs.items():
    lift = "never lifts" if result.lift_off_time is None else f"a support lifts at {result.lift_off_time:.3f} s"
    print(f"\n{elevation:g} deg: recoil {1e3 * result.max_barrel_displacement:.1f} mm, stability margin "
          f"{result.stability_margin:.3f}, {lift}, max pitch {1e3 * result.max_carriage_pitch:.2f} mrad, "
          f"max lift {1e3 * result.max_lift:.2f} mm")
    for support in result.supports:
        print(f"  {support['name']:<7} static {1e-3 * support['static_normal_force']:6.1f} kN, least "
              f"{1e-3 * support['min_normal_force']:6.1f} kN, largest {1e-3 * support['max_normal_force']:6.1f} kN")

# %%
# At 45 degrees the recoil pulls the trail into the ground and the spade keeps part of its static load. Level,
# the recoil is short, the barrel returns fast, and the battery buffer's forward push on the return tips
# the gun forward about its wheels: the spade leaves the ground on counter-recoil. What a designer would
# change is the counter-recoil, not the recoil (see the stability examples that follow).
fig, axes = plt.subplots(3, 1, figsize=(7, 7.5), sharex=True, layout="constrained")
for elevation, result in runs.items():
    result = result.densified()  # the histories at most 1 ms apart (the solver's steps reach 20 ms), same metrics
    for name, output in result.carriage.supports.items():
        ax = axes[0] if name == "spade" else axes[1]
        ax.plot(result.time, 1e-3 * output.normal_force, label=f"{elevation:g} deg")
    axes[2].plot(result.time, 1e3 * (result.carriage_pitch - result.carriage.static_pitch), label=f"{elevation:g} deg")
axes[0].set_ylabel("spade load [kN]")
axes[1].set_ylabel("wheel load [kN]")
axes[2].set_ylabel("pitch from static [mrad]")
axes[2].set_xlabel("time [s]")
for ax in axes:
    ax.grid(alpha=0.35)
    ax.legend()
plt.show()
