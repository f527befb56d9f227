"""
Your own Exudyn script: a chain of buffers behind a hydraulic brake
===================================================================

The scene format covers the recoil mechanisms of the paper and their usual hardware, but not every
mechanism. The functions that add our items work on your own Exudyn system and markers: ``add_body`` (a 1-D
body), ``add_contact`` (a contact of any of the seven laws, with its force sensor), ``add_recoil_damper``,
``add_recoil_brake`` and ``add_recuperator``. This example first checks the building blocks on a hammer and an
anvil, then builds a mechanism no scene describes: a barrel on a hydraulic brake that strikes a chain of two
buffer masses, the last one sprung to the ground.
"""

# %%
# A hammer against an anvil
# -------------------------
# A 5 kg hammer at 2 m/s strikes a 20 kg anvil at rest 10 mm ahead through an ``exact-restitution`` contact
# with e = 0.6. After the impact the separation speed must be 0.6 times the approach speed, whatever the
# contact's stiffness, exponent and the masses: the law's damping is computed from the approach speed ``v-``,
# which a pre-step function captures at the onset (``add_contact`` installs it).
import exudyn
import matplotlib.pyplot as plt
import numpy as np
from exudyn.itemInterface import (MarkerNodeCoordinate, NodePointGround, ObjectConnectorCoordinateSpringDamper,
                                  SensorNode)

from mbs_models import Contact, RecoilBrake, add_body, add_contact, add_recoil_brake


def solve(mbs, end_time, steps):
    """DOPRI5 with the ``standard`` preset's tolerances; sensors stored in memory, no files."""
    settings = exudyn.SimulationSettings()
    settings.timeIntegration.endTime = end_time
    settings.timeIntegration.numberOfSteps = steps
    settings.timeIntegration.automaticStepSize = True
    settings.timeIntegration.relativeTolerance = 1e-9
    settings.timeIntegration.absoluteTolerance = 1e-11
    settings.timeIntegration.verboseMode = 0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = end_time / steps
    mbs.SolveDynamic(settings, solverType=exudyn.DynamicSolverType.DOPRI5)


system = exudyn.SystemContainer()
mbs = system.AddSystem()
ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
hammer, hammer_marker = add_body(mbs, mass=5.0, initial_velocity=2.0)       # kg, m/s
anvil, anvil_marker = add_body(mbs, mass=20.0)                               # at rest
contact = add_contact(mbs, anvil_marker, hammer_marker,                      # closes when x_hammer - x_anvil > gap
                      Contact(gap=0.01, stiffness=1e8, exponent=1.5, law="exact-restitution", restitution=0.6))
mbs.Assemble()
solve(mbs, 0.05, 50)
v_hammer, v_anvil = mbs.systemData.GetODE2Coordinates_t()
force = mbs.GetSensorStoredData(contact.sensor)
print(f"restitution {(v_anvil - v_hammer) / 2.0:.6f} (asked 0.6)")
print(f"momentum before {5.0 * 2.0:.6f}, after {5.0 * v_hammer + 20.0 * v_anvil:.6f} kg m/s")
print(f"peak contact force {force[:, 1].max():.0f} N")
system.Reset()

# %%
# A barrel, a brake and a chain of buffers
# ----------------------------------------
# The barrel (5600 kg at the paper's 0.6909 m/s) recoils on a hydraulic brake with a constant orifice. After
# 30 mm it strikes buffer 1 (200 kg), which after another 20 mm strikes buffer 2 (800 kg), held by a spring
# and damper to the ground. The first contact is Hunt-Crossley, the second exact-restitution; with more than
# one contact needing ``v-`` we install one pre-step function ourselves and call each contact's ``update``.
system = exudyn.SystemContainer()
mbs = system.AddSystem()
ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
barrel, barrel_marker = add_body(mbs, mass=5600.0, initial_velocity=6.86 * 564.0 / 5600.0)
buffer_1, buffer_1_marker = add_body(mbs, mass=200.0)
buffer_2, buffer_2_marker = add_body(mbs, mass=800.0)
brake = add_recoil_brake(mbs, ground, barrel_marker, RecoilBrake(piston_area=0.012, orifice_area=4e-4,
                                                                 discharge_coefficient=0.7, fluid_density=870.0))
first = add_contact(mbs, buffer_1_marker, barrel_marker,
                    Contact(gap=0.03, stiffness=2.1e8, exponent=1.3, damping_factor=0.6), name="barrel_buffer_1")
second = add_contact(mbs, buffer_2_marker, buffer_1_marker,
                     Contact(gap=0.02, stiffness=2.1e8, exponent=1.3, law="exact-restitution", restitution=0.3),
                     name="buffer_1_buffer_2", install_pre_step=False)
mbs.AddObject(ObjectConnectorCoordinateSpringDamper(markerNumbers=[ground, buffer_2_marker], stiffness=4.0e4,
                                                    damping=8.0e3))


def pre_step(mbs, t):
    for restitution_contact in (first, second):
        if restitution_contact.capture is not None:
            restitution_contact.update(mbs)
    return True


mbs.SetPreStepUserFunction(pre_step)
positions = {name: mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=exudyn.OutputVariableType.Coordinates,
                                            storeInternal=True))
             for name, node in (("barrel", barrel), ("buffer 1", buffer_1), ("buffer 2", buffer_2))}
mbs.Assemble()
solve(mbs, 1.0, 2000)

# %%
# What happened
# -------------
# The brake's quadratic force slows the barrel before the first impact; buffer 1 passes the blow on to
# buffer 2 within milliseconds, and buffer 2's spring returns the energy slowly. The contact forces come
# from the sensors ``add_contact`` made; the positions from our own node sensors.
fig, (ax_x, ax_f) = plt.subplots(2, 1, figsize=(7, 6), sharex=True, layout="constrained")
for name, sensor in positions.items():
    data = mbs.GetSensorStoredData(sensor)
    ax_x.plot(data[:, 0], 1e3 * data[:, 1], label=name)
    print(f"{name:<9} max position {1e3 * data[:, 1].max():7.2f} mm")
for contact in (first, second):
    data = mbs.GetSensorStoredData(contact.sensor)
    touching = np.flatnonzero(data[:, 1] > 0.0)
    print(f"{contact.name:<18} peak force {1e-3 * data[:, 1].max():7.1f} kN, first touch at "
          f"{data[touching[0], 0] * 1e3 if touching.size else float('nan'):.1f} ms")
    ax_f.plot(data[:, 0], 1e-3 * data[:, 1], label=contact.name)
ax_x.set_ylabel("position [mm]")
ax_f.set_ylabel("contact force [kN]")
ax_f.set_xlabel("time [s]")
for ax in (ax_x, ax_f):
    ax.grid(alpha=0.35)
    ax.legend()
system.Reset()
plt.show()
