"""
Your own element: a progressive recoil spring
=============================================

An element is a scene table and the connectors it adds; a connector is its force law ``F(d, d')`` -- the one
part you must write. The stored energy ``U = int_0^d F(s, 0) ds``, the dissipated power, the tangent stiffness
and the force bound of the early stop are derived from the law. ``examples/progressive_spring.py`` is a
complete user module, outside the package: a progressive recoil spring ``F = k1 x + k3 x^3`` with its table
``[progressive_spring]``, its outputs (the spring's force history and peak), and its term of the independent
reference. This example imports it and uses the new table everywhere a shipped one works.
"""

# %%
# Importing the element
# ---------------------
# Importing the module registers the table (``mbs_models.register_element``) and the reference's term
# (``validation.reference.terms.register_term``). On the command line the same is ``recoil --plugin
# examples/progressive_spring.py run examples/progressive_spring.toml``.
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

try:  # examples/, where the user's module lives
    EXAMPLES = Path(__file__).resolve().parents[2]
except NameError:  # sphinx-gallery runs the script without __file__, in the script's own folder
    EXAMPLES = Path.cwd().resolve().parents[1]
sys.path.insert(0, str(EXAMPLES))
import progressive_spring  # noqa: E402  (registers [progressive_spring])

from mbs_models import load_scene, run_sweep, simplified_model, simulate  # noqa: E402
from mbs_models.cli import main  # noqa: E402

scene = load_scene(EXAMPLES / "progressive_spring.toml")
spring = scene.progressive_spring
print(f"{scene.name}: k1 = {spring.linear_stiffness:g} N/m, k3 = {spring.cubic_stiffness:g} N/m^3")

# %%
# Simulating it
# -------------
# The element declares a metric ``peak_force`` and a history ``force``; they appear in
# ``result.element_metrics`` and ``result.element_histories``, in ``recoil run --json`` and as sweep columns.
# Against the paper's linear spring (27.5 kN/m) this spring is softer near battery, up to
# ``x = sqrt((27500 - k1) / k3)`` = 61 mm, and far stiffer beyond: with the same damper the recoil is much
# shorter, and the force on the mount -- mostly the spring's, at the end of the stroke -- much larger. The
# spring's peak force is its law at the recoil length (it grows with x), a check by hand.
result = simulate(scene, 3.0)
paper = simulate(simplified_model(), 3.0)
print(f"progressive spring: recoil {1e3 * result.max_barrel_displacement:.1f} mm, peak spring force "
      f"{1e-3 * result.element_metrics['progressive_spring']['peak_force']:.2f} kN, peak force on the mount "
      f"{1e-3 * result.peak_support_force:.2f} kN")
print(f"paper's spring:     recoil {1e3 * paper.max_barrel_displacement:.1f} mm, peak force on the mount "
      f"{1e-3 * paper.peak_support_force:.2f} kN")
x = result.max_barrel_displacement
by_hand = spring.linear_stiffness * x + spring.cubic_stiffness * x**3
print(f"peak spring force by hand at the recoil length, k1 x + k3 x^3 = {1e-3 * by_hand:.2f} kN")

# %%
# The early stop works for it too: its force bound is derived from the law, so a run asked only for the
# recoil length stops once that is proven final, with the same value as the full run.
early = simulate(scene, 10.0, stop_when_final=["max_barrel_displacement"])
print(f"early stop at {early.end_time:.2f} s of 10 s ({early.stop_reason}): recoil "
      f"{early.max_barrel_displacement:.9f} m, full run {simulate(scene, 10.0).max_barrel_displacement:.9f} m")

# %%
# Against the independent reference
# ---------------------------------
# ``recoil validate`` runs the engine and the reference's own implementation of the element (written from
# the law, in the module's second half) and compares every metric within the guarantee's tolerances.
main(["validate", str(EXAMPLES / "progressive_spring.toml"), "--end-time", "3"])

# %%
# In a sweep
# ----------
# Its fields are dotted keys like any shipped table's: here the cubic stiffness from 0 (a linear 20 kN/m
# spring) to 4e6 N/m^3.
table = run_sweep(scene, {"progressive_spring.cubic_stiffness": "0:4e6:5"}, end_time=3.0, workers=1, progress=False)
print(table[["progressive_spring.cubic_stiffness", "max_barrel_displacement", "progressive_spring.peak_force",
             "peak_support_force"]].to_string(index=False))

fig, (ax_f, ax_x) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
d = np.linspace(0.0, 0.25, 101)
ax_f.plot(1e3 * d, 1e-3 * 27500.0 * d, label="paper: 27.5 kN/m")
ax_f.plot(1e3 * d, 1e-3 * (spring.linear_stiffness * d + spring.cubic_stiffness * d**3), label="k1 x + k3 x^3")
ax_f.set_xlabel("barrel displacement [mm]")
ax_f.set_ylabel("spring force [kN]")
for label, run in (("progressive spring", result), ("paper's spring", paper)):
    dense = run.densified()  # the histories at most 1 ms apart (the solver's steps reach 20 ms)
    ax_x.plot(dense.time, 1e3 * dense.barrel_position, label=label)
ax_x.set_xlabel("time [s]")
ax_x.set_ylabel("barrel displacement [mm]")
for ax in (ax_f, ax_x):
    ax.grid(alpha=0.35)
    ax.legend()
plt.show()
