"""
A measured spring characteristic
================================

Springs and dampers reach the designer as measured tables, not as a stiffness. ``[[tabulated_spring]]`` takes
a force-displacement table ``F(x)`` and ``[[tabulated_damper]]`` a force-velocity table ``F(v)``, inline or from
a CSV file beside the scene, and interpolates them piecewise linearly. This example writes a progressive
recoil spring's measurements to a CSV file, uses it in place of the paper's linear spring, and compares the
two recoils.
"""

# %%
# The measured table and the scene
# --------------------------------
# A progressive spring: softer than the paper's 27.5 kN/m near battery, stiffer beyond 0.25 m. The table
# must list the rest point (0, 0) and its force must never decrease with the displacement; beyond its ends
# it is extended linearly, and a run that leaves the table says so with a ``TableRangeWarning``.
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from mbs_models import load_scene, simplified_model, simulate

MEASURED = [(-0.1, -2600.0), (0.0, 0.0), (0.05, 1400.0), (0.1, 2900.0), (0.15, 4600.0), (0.2, 6500.0),
            (0.25, 8700.0), (0.3, 11600.0), (0.4, 17400.0)]   # (displacement m, force N)

SCENE = """
version = 2
name = "simplified model with a measured progressive spring"

[barrel]
mass = 5600.0
[firing]
projectile_mass = 6.86
muzzle_velocity = 564.0
[recoil_damper]
recoil = 6239.0
counter_recoil = 14050.0

[[tabulated_spring]]
name = "measured_spring"
file = "spring.csv"           # displacement,force (m, N) after one header line, beside this file
"""

with tempfile.TemporaryDirectory() as directory:
    folder = Path(directory)
    (folder / "spring.csv").write_text("displacement,force\n" + "".join(f"{x},{f}\n" for x, f in MEASURED))
    (folder / "measured.toml").write_text(SCENE)
    measured = load_scene(folder / "measured.toml")   # the table is read now: the files may go

paper = simplified_model()

# %%
# Two recoils
# -----------
# The same shot, the same damper; only the spring differs. The stiffening table stops the barrel sooner:
# the recoil is shorter and the force on the mount higher. The spring's stored energy is the integral of its
# own characteristic, ``U = int_0^x F``; at the end of the recoil it is checked here against the trapezoidal
# integral of the table (exact for a piecewise linear force).
runs = {"paper's linear spring": simulate(paper, 3.0), "measured progressive spring": simulate(measured, 3.0)}
for label, result in runs.items():
    print(f"{label:<28} recoil {1e3 * result.max_barrel_displacement:6.1f} mm at "
          f"{result.time_of_max_barrel_displacement:.3f} s, peak force on the mount "
          f"{1e-3 * result.peak_support_force:5.2f} kN")
result = runs["measured progressive spring"]
at_max = np.argmax(result.barrel_position)
x_max = result.barrel_position[at_max]
table_x = np.array([p for p, _ in MEASURED] + [x_max])
table_f = np.interp(table_x, [p for p, _ in MEASURED], [f for _, f in MEASURED])
inside = (table_x >= 0.0) & (table_x <= x_max)
order = np.argsort(table_x[inside])
xs, fs = table_x[inside][order], table_f[inside][order]
by_hand = float(np.sum(0.5 * (fs[1:] + fs[:-1]) * np.diff(xs)))
print(f"stored in the measured spring at x = {1e3 * x_max:.1f} mm: "
      f"{result.stored_energy_histories['measured_spring'][at_max]:.1f} J (table integrated by hand: {by_hand:.1f} J)")

fig, (ax_c, ax_x) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
x = np.linspace(-0.1, 0.4, 101)
ax_c.plot(1e3 * x, 1e-3 * 27500.0 * x, label="paper: k = 27.5 kN/m")
ax_c.plot([1e3 * p for p, _ in MEASURED], [1e-3 * f for _, f in MEASURED], "o-", label="measured table")
ax_c.set_xlabel("displacement [mm]")
ax_c.set_ylabel("spring force [kN]")
for label, result in runs.items():
    dense = result.densified()  # the histories at most 1 ms apart (the solver's steps reach 20 ms)
    ax_x.plot(dense.time, 1e3 * dense.barrel_position, label=label)
ax_x.set_xlabel("time [s]")
ax_x.set_ylabel("barrel displacement [mm]")
for ax in (ax_c, ax_x):
    ax.grid(alpha=0.35)
    ax.legend()
plt.show()
