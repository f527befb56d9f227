"""
A version-2 scene: brake, recuperator, end stops and a burst
============================================================

The paper's mechanism is a linear spring and damper. A real recoil system throttles oil through an orifice
(a hydraulic brake, whose force grows with the square of the velocity), returns the barrel with a gas spring
(a recuperator, whose preload holds the barrel in battery), ends its stroke on stops, and is fired by a
breech-force pulse, often several times in a row. Scene format version 2 describes all of these as tables;
this example writes one such scene as a TOML file, loads it and fires a two-shot burst.
"""

# %%
# The scene file
# --------------
# ``version = 2`` opens every element table. The brake's orifice closes from 5 to 2 cm^2 over the first
# 0.2 m of the stroke (and throttles the return more strongly); the recuperator's 2 kN preload
# ``p0 A`` holds the barrel against the battery stop, so the barrel starts at rest in static equilibrium on
# that stop; a stiff recoil stop at 0.24 m ends the stroke a little before the brake would. The breech force is a pulse of 12 ms,
# scaled so that its impulse is the shot's momentum ``I = m_p v_p = 3869 N s``; the burst fires it twice,
# 2.5 s apart.
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from mbs_models import load_scene, simulate

SCENE = """
version = 2
name = "brake, recuperator, end stops and a two-shot burst"

[barrel]
mass = 5600.0                              # M, kg

[firing]
projectile_mass = 6.86                     # kg
muzzle_velocity = 564.0                    # m/s -> I = 3869 N s
[firing.pulse]
times  = [0.0, 0.002, 0.006, 0.012]        # s
forces = [0.0, 2.0e6, 6.0e5, 0.0]          # N, the shape; scaled to the impulse I
scale_to_momentum = true

[burst]
shots = 2
interval = 2.5                             # s

[recoil_brake]
piston_area = 0.012                        # A, m^2
orifice_area = [[0.0, 5.0e-4], [0.1, 3.5e-4], [0.2, 2.0e-4]]   # (stroke m, area m^2)
counter_recoil_orifice_area = [[0.0, 2.0e-4], [0.2, 4.0e-4]]    # throttles towards battery
discharge_coefficient = 0.7
fluid_density = 870.0                      # kg/m^3, hydraulic oil

[recuperator]
initial_pressure = 1.0e6                   # p0, Pa: preload p0 A = 2 kN
piston_area = 0.002                        # A, m^2
gas_volume = 0.002                         # V0, m^3
polytropic_exponent = 1.3

[recoil_stop]                              # end of the stroke: x_M > 0.24 m
position = 0.24
law = "hunt-crossley"
stiffness = 1.0e9
exponent = 1.5
damping_factor = 0.5

[battery_stop]                             # the counter-recoil buffer: x_M < 0
position = 0.0
law = "kelvin-voigt"
stiffness = 2.0e6
damping = 5.0e4
"""

with tempfile.TemporaryDirectory() as directory:
    path = Path(directory) / "burst.toml"
    path.write_text(SCENE)
    scene = load_scene(path)
print(scene.name)
print("tables:", ", ".join(name for name in ("firing", "burst", "recoil_brake", "recuperator", "recoil_stop",
                                             "battery_stop") if getattr(scene, name, None) is not None))

# %%
# Firing the burst
# ----------------
# The solve is split at every shot and at every point of the pulse's table, so that each segment integrates
# one linear piece of the force. ``result.shots`` reports, per shot, the maximum displacement, where the
# barrel is when the next shot fires and the time it takes to come back within 1 mm of battery.
result = simulate(scene, 5.0, "standard")
print(f"recoil {1e3 * result.max_barrel_displacement:.1f} mm, peak force on the mount "
      f"{1e-3 * result.peak_support_force:.2f} kN at {result.time_of_peak_support_force:.3f} s")
for shot in result.shots:
    back = "never back in battery" if shot["time_to_battery"] is None else \
        f"in battery {shot['time_to_battery']:.2f} s after it"
    print(f"shot {shot['shot']} at {shot['time']:.1f} s: max {1e3 * shot['max_barrel_displacement']:.1f} mm, {back}")
    if shot["position_at_next_shot"] is not None:
        print(f"    at the next shot: x = {1e3 * shot['position_at_next_shot']:.2f} mm, "
              f"v = {shot['velocity_at_next_shot']:+.4f} m/s")
for stop in result.stops():
    print(f"{stop['name']}: peak contact force {1e-3 * stop['peak_contact_force']:.1f} kN, "
          f"{len(stop['impacts'])} impacts")

# %%
# The first stroke runs into the recoil stop: the last millimetres of the stroke are stopped by the stiff
# stop instead of the brake, and the force on the mount jumps to several times the brake's force (the peak
# printed above). This is why a designer sizes the brake so that the stroke ends short of the stop. The
# second shot finds the barrel not quite at rest: it is still moving towards battery after bouncing on the
# buffer (the negative velocity printed), so the return's momentum cancels part of the shot's and the second
# stroke is shorter. A burst's rate of fire is limited by exactly this: the time to battery.
#
# Where the energy goes
# ---------------------
# Every element reports its kinetic, stored and dissipated energy; with the work of the breech force they
# balance. The brake dissipates the recoil's energy, the recuperator stores some of it and gives it back
# on the return, and the buffer takes what is left of the return.
for element, terms in result.energy().items():
    print(f"{element:<14}" + "  ".join(f"{name} {value:9.1f} J" for name, value in terms.items()))

dense = result.densified()  # the histories at most 1 ms apart (the solver's steps reach 20 ms), same metrics
fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True, layout="constrained")
axes[0].plot(dense.time, 1e3 * dense.barrel_position)
axes[0].axhline(240.0, color="grey", lw=0.8, ls="--", label="recoil stop")
axes[0].set_ylabel("barrel displacement [mm]")
axes[0].legend()
axes[1].plot(dense.time, dense.barrel_velocity)
axes[1].set_ylabel("barrel velocity [m/s]")
axes[2].plot(dense.time, 1e-3 * dense.support_force)
axes[2].set_ylabel("force on the mount [kN]")
axes[2].set_xlabel("time [s]")
for ax in axes:
    ax.grid(alpha=0.35)
plt.show()
