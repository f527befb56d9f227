"""
Seven contact laws on one impact
================================

An impact between two bodies is over in milliseconds, and a contact law says how its force builds up and how
much of the energy it returns. The engine offers seven laws for every contact (an absorber against wall A,
an end stop against the barrel). This example puts each of the shipped ``contact_<law>`` scenes' contacts
on one free impact -- the 5600 kg barrel at the paper's 0.6909 m/s against the 1000 kg absorber at rest,
with every spring and damper removed -- and compares the force histories, the force-penetration loops and
the restitution each law achieves.
"""

# %%
# The laws and their parameters
# -----------------------------
# With the penetration ``p`` (m), its rate ``p'`` and ``v-`` the rate at the onset of the impact:
#
# * ``hunt-crossley``: ``k p^n (1 + lambda p')``, the paper's law (its restitution depends on ``lambda v-``);
# * ``lankarani-nikravesh``, ``flores``, ``gonthier``: ``k p^n (1 + chi(e) p'/v-)`` with each author's
#   approximation ``chi(e)`` of the damping that gives a requested restitution e;
# * ``exact-restitution``: the same form with the ``chi`` that gives exactly e;
# * ``hertz``: ``k p^n``, elastic (e = 1);
# * ``kelvin-voigt``: ``k p + c p'``, a linear spring and damper (its restitution depends on k, c and the
#   masses, and its force jumps at the onset).
#
# Every force is clipped to ``F >= 0``: a contact never pulls.
import matplotlib.pyplot as plt

from mbs_models import apply_overrides, load_scene, simulate
from mbs_models.scenes import scene_path

LAWS = ("hunt-crossley", "lankarani-nikravesh", "flores", "gonthier", "exact-restitution", "hertz", "kelvin-voigt")
FREE = {"recoil_spring.stiffness": 0.0, "recoil_damper.recoil": 0.0, "recoil_damper.counter_recoil": 0.0,
        "absorber.stiffness": 0.0, "absorber.damping": 0.0}

runs = {}
for law in LAWS:
    shipped = load_scene(scene_path("contact_" + law.replace("-", "_")))
    scene = apply_overrides(shipped, FREE)          # the same contact, nothing else acting
    runs[law] = simulate(scene, 0.05, "standard")

# %%
# What each law achieves
# ----------------------
# After the impact the two bodies fly apart freely; the restitution is their separation speed over the
# approach speed, ``e = (v_m - v_M) / v0``. The restitution laws are asked for e = 0.5: only
# ``exact-restitution`` gives it exactly; Lankarani-Nikravesh's approximation, derived for nearly elastic
# impacts, returns far more.
v0 = runs["hertz"].barrel_velocity[0]
print(f"impact speed v0 = {v0:.4f} m/s\n")
print(f"{'law':<20} {'asked e':>7} {'achieved e':>10} {'peak force [kN]':>15} {'duration [ms]':>13} {'dissipated [J]':>14}")
for law, result in runs.items():
    contact = result.scene.absorbers[0].contact
    asked = getattr(contact, "restitution", None)
    achieved = (result.absorber_velocity[-1] - result.barrel_velocity[-1]) / v0
    impact = result.impacts[0]
    print(f"{law:<20} {'-' if asked is None else f'{asked:.2f}':>7} {achieved:10.4f} "
          f"{1e-3 * impact.peak_force:15.1f} {1e3 * impact.duration:13.2f} "
          f"{result.dissipated_energy.get('contact', 0.0):14.1f}")

# %%
# Force histories and loops
# -------------------------
# The area inside a force-penetration loop is the energy the contact dissipates. Hertz has no loop
# (elastic); Kelvin-Voigt's force starts at ``c v0`` the moment the bodies touch and ends negative before
# the clipping, which is why it separates early.
fig, (ax_t, ax_p) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
for law, result in runs.items():
    result = result.densified()  # the histories at most 1 ms apart (the solver's steps reach 20 ms), same metrics
    force = result.contact_force
    gap = result.scene.absorbers[0].contact.gap
    penetration = result.barrel_position - result.absorber_position - gap
    touching = force > 0.0
    ax_t.plot(1e3 * result.time, 1e-3 * force, label=law)
    ax_p.plot(1e3 * penetration[touching], 1e-3 * force[touching], label=law)
ax_t.set_xlim(0.0, 25.0)
ax_t.set_xlabel("time [ms]")
ax_t.set_ylabel("contact force [kN]")
ax_p.set_xlabel("penetration [mm]")
ax_p.set_ylabel("contact force [kN]")
for ax in (ax_t, ax_p):
    ax.grid(alpha=0.35)
ax_p.legend(fontsize=8)
plt.show()
