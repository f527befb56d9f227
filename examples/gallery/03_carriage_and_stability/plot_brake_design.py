"""
Designing the brake: constant resistance, and stable at every elevation
=======================================================================

The classical design rule: for a given recoil length L, the force on the mount is smallest when the total
resistance to the recoil stays constant over the stroke, ``R = M v0^2 / (2 L)``. ``recoil design-brake``
computes the orifice table of a hydraulic brake that makes the brake, the spring or recuperator, friction and
gravity add up to that constant, and iterates the design length on the simulation until the simulated recoil
is L. With ``--stable`` it designs, for a gun on its carriage, a variable-recoil brake (orifice bands that
switch with the elevation, as real throttling rods do) that keeps every support on the ground.
"""

# %%
# A constant-resistance brake for the paper's model
# -------------------------------------------------
# ``mbs_models.cli.main`` runs the command exactly as the shell would (``recoil design-brake simplified
# --recoil-length 0.2215 --out DIR``). It writes the designed scene (``designed.toml``), a figure and the
# numbers (``design_brake.json``) into a temporary directory, and compares the brake with the paper's linear
# damper scaled to the same recoil length.
import json
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from mbs_models import load_scene, simplified_model, simulate
from mbs_models.cli import main
from mbs_models.scenes import scene_path

outputs = tempfile.TemporaryDirectory(prefix="recoil-gallery-")   # removed at the end
work = Path(outputs.name)
main(["design-brake", "simplified", "--recoil-length", "0.2215", "--out", str(work / "brake")])
# the command wrote its own figure to design_brake.png; we draw ours below
numbers = json.loads((work / "brake" / "design_brake.json").read_text())
designed = load_scene(work / "brake" / "designed.toml")
print(f"\nconstant resistance R = {numbers['constant_resistance'] / 1e3:.3f} kN; the designed orifice: "
      f"{len(designed.recoil_brake.orifice_area)} points from {designed.recoil_brake.orifice_area[0][1]:.3e} to "
      f"{designed.recoil_brake.orifice_area[-1][1]:.3e} m^2")

# %%
# The resistance over the stroke
# ------------------------------
# The force on the mount against the barrel's displacement during the recoil: the designed brake holds it
# flat. With the linear damper it starts at the damper's ``c v0`` and grows as the spring's ``k x`` adds up
# faster than the damper's share falls, peaking late in the stroke. The area under each curve is the same
# recoil energy, so at the same recoil length the flat curve has the smaller peak.
runs = {"designed brake": simulate(designed, 3.0), "paper's linear damper": simulate(simplified_model(), 3.0)}
fig, ax = plt.subplots(figsize=(7, 3.5), layout="constrained")
for label, result in runs.items():
    dense = result.densified()  # the histories at most 1 ms apart (the solver's steps reach 20 ms), same metrics
    stroke = dense.time <= result.time_of_max_barrel_displacement
    ax.plot(1e3 * dense.barrel_position[stroke], 1e-3 * dense.support_force[stroke], label=label)
    print(f"{label:<22} recoil {1e3 * result.max_barrel_displacement:.1f} mm, peak force on the mount "
          f"{1e-3 * result.peak_support_force:.2f} kN")
ax.set_xlabel("barrel displacement [mm]")
ax.set_ylabel("force on the mount [kN]")
ax.grid(alpha=0.35)
ax.legend()

# %%
# A brake that keeps the howitzer down
# ------------------------------------
# The shipped howitzer's spade lifts on counter-recoil at low elevations (see the stability chart).
# ``--stable`` designs, per band of elevations, the constant-resistance orifice for the band's shortest
# stable recoil, and narrows the counter-recoil orifice until the return keeps ``1 - margin`` of every
# support's static load. Here two bands, up to 20 degrees and above, at ``draft`` accuracy. Above 20 degrees
# the recoil presses the front down and any length is stable: that band recoils as long as it may
# (``--max-recoil``, 1 m by default, which the scene's other elements cut short: the note it prints).
main(["design-brake", "towed_howitzer", "--stable", "--elevations", "0,10,40", "--bands", "20",
      "--accuracy", "draft", "--out", str(work / "stable")])
plt.close("all")
stable = load_scene(work / "stable" / "designed.toml")
for band in stable.recoil_brake.band:
    counter = band.counter_recoil_orifice_area
    print(f"band up to {band.up_to:g} deg: recoil orifice {band.orifice_area[0][1]:.3e} m^2 at battery, counter-recoil "
          f"orifice {'that of the brake' if counter is None else f'{counter:.3e} m^2'}")

# %%
# The shipped and the designed brake, level
# -----------------------------------------
# Level, the designed brake keeps the spade loaded through the return into battery, with its narrower
# counter-recoil orifice. Stability has a price: the band's short recoil (the closed form's shortest
# stable one, with margin) means a hard one, and the peak force on the mount rises. A designer trades these
# two against each other, and the carriage's geometry (a longer trail) against both.
shipped = load_scene(scene_path("towed_howitzer"))
fig, ax = plt.subplots(figsize=(7, 3.5), layout="constrained")
for label, scene in (("shipped brake", shipped), ("designed for stability", stable)):
    result = simulate(scene, 3.0, "draft")
    dense = result.densified()
    ax.plot(dense.time, 1e-3 * dense.carriage.supports["spade"].normal_force, label=label)
    print(f"{label:<23} recoil {1e3 * result.max_barrel_displacement:5.1f} mm, stability margin "
          f"{result.stability_margin:.3f}, peak force on the mount {1e-3 * result.peak_support_force:.1f} kN")
ax.set_xlabel("time [s]")
ax.set_ylabel("spade load at 0 deg [kN]")
ax.grid(alpha=0.35)
ax.legend()
plt.show()
outputs.cleanup()
