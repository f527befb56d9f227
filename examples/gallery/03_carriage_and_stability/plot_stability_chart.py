"""
The stability chart over elevation
==================================

How hard may the recoil pull on a carriage before its front lifts? Taking moments about the rearmost support
(the spade), the front support unloads when the resistance to recoil R -- the force the recoil elements
transmit along the axis -- exceeds

``R* = m_r g sin(theta) + g m_tot d / h(theta)``

with the recoiling mass ``m_r``, the gun's weight moment about the spade ``m_tot d`` and the recoil axis' arm
``h(theta)`` about it. A constant-resistance brake over a recoil L has ``R = E / L + m_r g sin(theta)`` (E the
free-recoil energy), so the limit gives a **shortest stable recoil** at every elevation. The study
``stability_chart`` (the CLI's ``recoil stability``) sets these closed forms beside the scene simulated at
each elevation.
"""

# %%
# The chart of the shipped gun
# ----------------------------
# ``margin = 0.8`` asks the resistance to stay within 80 % of the limit. Above 60 degrees the shipped
# recuperator's preload can no longer return the barrel against gravity (the scene is refused there), so the
# chart stops at 55 degrees. ``draft`` accuracy and a 3-s window per elevation keep it cheap.
import time

import matplotlib.pyplot as plt
import numpy as np

from mbs_models import load_scene
from mbs_models.scenes import scene_path
from mbs_models.studies.stability_chart import stability_chart, summary_lines

scene = load_scene(scene_path("towed_howitzer"))
start = time.perf_counter()
elevations = [0.0, 3.0, 6.0, 9.0, 12.0, 15.0, 17.0, 20.0, 30.0, 40.0, 50.0, 55.0]   # finer where the limit lives
points = stability_chart(scene, elevations, margin=0.8, end_time=3.0, accuracy="draft")
print("\n".join(summary_lines(points)))
print(f"({len(points)} elevations in {time.perf_counter() - start:.1f} s)")

# %%
# Reading the chart
# -----------------
# The closed form's limit rises steeply with the elevation: the recoil axis' arm ``h`` about the spade
# shrinks to zero where the axis points straight at the spade's tip, and beyond that elevation the pull
# presses the front down and any recoil is stable ("none" and "any" in the table). The simulated peak resistance stays
# far below the limit at every elevation: the shipped brake never tips the gun *during the recoil*. The
# simulated stability margin still reaches 0 at low elevations, on *counter-recoil*: the buffer that stops
# the returning barrel pushes the gun forward about its wheels. The columns ``recoil: sim/cf`` compare the
# front's least load during the stroke, simulated and by the closed form with the simulated resistance:
# from 20 degrees on they agree; level, the carriage pitches on its supports' compliance, a motion the
# quasi-static closed form leaves out, and the two separate.
def finite(values, scale=1.0):
    return np.array([np.nan if v is None or not np.isfinite(v) else v * scale for v in values])


elevation = np.array([p.elevation for p in points])
fig, axes = plt.subplots(3, 1, figsize=(7, 8), sharex=True, layout="constrained")
axes[0].plot(elevation, finite([p.limit_in_battery for p in points], 1e-3), "-", label="limit in battery (closed form)")
axes[0].plot(elevation, finite([p.limit_at_scene_recoil for p in points], 1e-3), "--",
             label="limit at the end of the scene's recoil")
axes[0].plot(elevation, finite([p.peak_resistance for p in points], 1e-3), "ko", label="simulated peak resistance")
axes[0].set_yscale("log")
axes[0].set_ylabel("resistance [kN]")
axes[1].plot(elevation, finite([p.shortest_stable_recoil for p in points], 1e3), "-",
             label="shortest stable recoil (closed form)")
axes[1].plot(elevation, finite([p.recoil for p in points], 1e3), "ko", label="simulated recoil")
axes[1].set_ylabel("recoil [mm]")
axes[2].plot(elevation, finite([p.stability_margin for p in points]), "ko-", label="whole run")
axes[2].plot(elevation, finite([p.recoil_margin for p in points]), "s--", mfc="none", label="during the recoil stroke")
axes[2].axhline(0.0, color="grey", lw=0.8)
axes[2].set_ylabel("stability margin")
axes[2].set_xlabel("elevation [deg]")
for ax in axes:
    ax.grid(alpha=0.35)
    ax.legend(fontsize=8)
plt.show()
