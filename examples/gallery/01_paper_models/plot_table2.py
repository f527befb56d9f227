"""
The paper's three models and its Table 2
========================================

The replicated paper studies a gun barrel of mass M = 5600 kg that recoils against a spring (k = 27.5 kN/m)
and an asymmetric damper (c = 6239 N s/m while it recoils, 14050 N s/m while it returns), and asks what an
impact absorber -- a mass m on its own spring and damper, hit by the barrel's wall A through a
Hunt-Crossley contact -- does to the recoil. Model (i) mounts the absorber on the barrel, model (ii) on the
ground. Its Table 2 gives the maximum barrel displacement (the recoil length) at gap 0 for m = 100, 500 and
1000 kg. This example recomputes the table, sets it beside the paper's numbers, and shows the histories
behind it.
"""

# %%
# The three models
# ----------------
# :func:`~mbs_models.simplified_model`, :func:`~mbs_models.model_i` and :func:`~mbs_models.model_ii` build the
# paper's scenes with its Table 1 parameters. The shot gives the barrel the velocity of the momentum balance,
# v0 = m_p v_p / M = 6.86 x 564 / 5600 = 0.6909 m/s (the paper prints it rounded to 0.7 m/s).
import time

import matplotlib.pyplot as plt
import numpy as np

from mbs_models import model_i, model_ii, simplified_model, simulate
from validation.studies.paper import table2

scene = model_ii(absorber_mass=1000.0, gap=0.0)
print(scene.model_label, "| barrel", scene.barrel.mass, "kg | absorber", scene.absorbers[0].mass, "kg,",
      scene.absorbers[0].mount, "mount | contact law", scene.absorbers[0].contact.law)

# %%
# Table 2, recomputed
# -------------------
# Table 2 needs only the recoil length, so each run stops as soon as the energy bounds prove that the
# maximum barrel displacement can no longer grow (``stop_when_final``): the value is that of the full
# 10-s run, at a fraction of its cost. ``standard`` accuracy keeps the displacement within 1e-7 relative of
# the independent reference.
paper = table2()
rows = []
start = time.perf_counter()
for label, make in (("simplified", lambda m: simplified_model()), ("model (i)", lambda m: model_i(m, 0.0)),
                    ("model (ii)", lambda m: model_ii(m, 0.0))):
    for mass in (100.0, 500.0, 1000.0):
        if label == "simplified" and mass != 100.0:
            continue  # no absorber: one value for every column
        result = simulate(make(mass), 10.0, "standard", stop_when_final=["max_barrel_displacement"])
        rows.append((label, mass, result.max_barrel_displacement, paper[(label, mass)].value, result.end_time))
print(f"{len(rows)} runs in {time.perf_counter() - start:.2f} s\n")
print(f"{'model':<11} {'m [kg]':>6} {'ours [m]':>9} {'paper [m]':>9} {'ours - paper [mm]':>18} {'stopped at [s]':>15}")
for label, mass, ours, published, stopped in rows:
    shown = "any" if label == "simplified" else f"{mass:.0f}"
    print(f"{label:<11} {shown:>6} {ours:9.6f} {published:9.4f} {1e3 * (ours - published):+18.2f} {stopped:15.2f}")

# %%
# The simplified model, model (i) at 500 and 1000 kg and model (ii) at 1000 kg agree with the paper within
# 0.6 mm. Model (i) at 100 kg and model (ii) at 100 and 500 kg do not: the paper says model (ii) at 100 kg is
# "absolutely the same" as the simplified model, which the printed equations cannot give at gap 0 (the
# absorber is hit at once). Nothing is tuned to match; the validation report studies which reading of the
# paper could explain each cell.
#
# The simplified model has a closed form, an independent check: during the recoil it is a damped
# oscillator, ``x(t) = v0 / w_d exp(-zeta w_n t) sin(w_d t)``, whose maximum is where ``tan(w_d t) = w_d /
# (zeta w_n)``.
M, k, c = 5600.0, 27500.0, 6239.0
v0 = 6.86 * 564.0 / M
w_n = np.sqrt(k / M)
zeta = c / (2.0 * np.sqrt(k * M))
w_d = w_n * np.sqrt(1.0 - zeta**2)
t_max = np.arctan(w_d / (zeta * w_n)) / w_d
x_max = v0 / w_d * np.exp(-zeta * w_n * t_max) * np.sin(w_d * t_max)
print(f"simplified model, closed form: {x_max:.6f} m at {t_max:.4f} s; simulated {rows[0][2]:.6f} m "
      f"(difference {abs(rows[0][2] - x_max):.1e} m)")

# %%
# The histories behind the table
# ------------------------------
# At m = 1000 kg, gap 0, over the first 3 s: the barrel's displacement, the contact force on the absorber and
# the force on the mount -- what the mechanism transmits to the ground, the quantity a recoil mechanism exists
# to moderate (the paper does not report it). Model (ii) shortens the recoil most, but its ground-mounted
# absorber passes its load straight to the mount.
runs = {"simplified": simulate(simplified_model(), 3.0), "model (i)": simulate(model_i(1000.0, 0.0), 3.0),
        "model (ii)": simulate(model_ii(1000.0, 0.0), 3.0)}
fig, axes = plt.subplots(3, 1, figsize=(7, 7.5), sharex=True, layout="constrained")
for label, result in runs.items():
    dense = result.densified()  # the histories at most 1 ms apart (the solver's steps reach 20 ms), same metrics
    axes[0].plot(dense.time, 1e3 * dense.barrel_position, label=label)
    if dense.contact_force is not None:
        axes[1].plot(dense.time, 1e-3 * dense.contact_force, label=label)
    axes[2].plot(dense.time, 1e-3 * dense.support_force, label=label)
    print(f"{label:<11} recoil {1e3 * result.max_barrel_displacement:6.1f} mm, peak force on the mount "
          f"{1e-3 * result.peak_support_force:5.2f} kN"
          + ("" if result.peak_contact_force is None else
             f", peak contact force {1e-3 * result.peak_contact_force:6.1f} kN, {len(result.impacts)} impacts"))
axes[0].set_ylabel("barrel displacement [mm]")
axes[1].set_ylabel("contact force [kN]")
axes[2].set_ylabel("force on the mount [kN]")
axes[2].set_xlabel("time [s]")
for ax in axes:
    ax.grid(alpha=0.35)
axes[0].legend()
fig.suptitle("m = 1000 kg, gap 0")

# %%
# The first impact lasts about 15 ms, far shorter than the recoil (about 0.7 s): a zoom shows the contact
# force of the Hunt-Crossley law, ``F = k_c p^1.3 (1 + lambda dp/dt)``, rising and falling within it.
fig, ax = plt.subplots(figsize=(7, 3), layout="constrained")
for label in ("model (i)", "model (ii)"):
    result = runs[label]
    first = result.impacts[0]
    window = (result.time >= first.start - 0.002) & (result.time <= first.end + 0.002)
    ax.plot(1e3 * result.time[window], 1e-3 * result.contact_force[window], ".-", ms=3, label=label)
    print(f"{label}: first impact {1e3 * first.start:.2f}-{1e3 * first.end:.2f} ms, peak "
          f"{1e-3 * first.peak_force:.1f} kN at {1e3 * first.time_of_peak_force:.2f} ms")
ax.set_xlabel("time [ms]")
ax.set_ylabel("contact force [kN]")
ax.grid(alpha=0.35)
ax.legend()
plt.show()
