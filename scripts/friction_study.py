#!/usr/bin/env python
"""Which friction law for the inclined cradle?  Exudyn's items and a smoothed law against exact Coulomb.

    python scripts/friction_study.py          # both cases, every law and solver (about 30 s)
    python scripts/friction_study.py --quick  # the laws on DOPRI5 only

Not a test: it measures what ``mbs_models/elements/cradle.py``'s docstring reports (the numbers there were
printed by this script on Exudyn 1.13.6; wall times depend on the machine, steps and errors do not).

The mechanism is one barrel (M = 5600 kg, v0 = 0.6909 m/s) on a cradle, written directly in Exudyn (no
engine code): a ``NodeGenericODE2`` + ``ObjectMass1D``, gravity ``M g sin(theta)`` as a ``LoadCoordinate``,
and optionally the paper's recoil spring k and a linear damper c in one ``ObjectConnectorCoordinateSpringDamper``.
The friction ``mu N`` (``N = M g cos(theta)``) is one of:

* ``exudyn-regularised``: ``ObjectConnectorCoordinateSpringDamperExt`` with ``frictionProportionalZone =
  v_reg``: ``F = mu N v / v_reg`` in ``|v| <= v_reg``, ``mu N sign(v)`` outside (C++, no state);
* ``tanh``: our own symbolic user function ``mu N tanh(v / v_reg)``;
* ``exudyn-bristle``: the same Exudyn item with ``frictionProportionalZone = 0`` and a ``NodeGenericData``
  (stick/slip state, last sticking position): a sticking spring ``k_stick`` with critical damping while
  stuck, switched after each step.

Exact Coulomb (:func:`exact_coulomb`) is integrated event by event with scipy (DOP853, rtol 1e-12): slip
modes ``F = +-mu N`` up to ``v = 0``, then stick while ``|F_ext - k x| <= mu N``.

Case (a): a block on a 10 deg incline with mu = 0.3 (sub-threshold: ``tan(theta) < mu``) slides down,
decelerates at ``g (mu cos - sin)``, stops and must stay: the creep is its displacement in the second
after the exact stop.  Case (b): free recoil of the simplified model (k = 27500 N/m, c = 6239 N s/m) with
friction for 10 s: level with mu = 0.05 (stops once, reverses, sticks), level with mu = 0.6 (the recoil
stops and sticks), 30 deg with mu = 0.05 (the shipped scene without the asymmetric damper).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.integrate import solve_ivp

import exudyn
from exudyn.itemInterface import (LoadCoordinate, MarkerNodeCoordinate, NodeGenericData, NodeGenericODE2,
                                  NodePointGround, ObjectConnectorCoordinateSpringDamper,
                                  ObjectConnectorCoordinateSpringDamperExt, ObjectMass1D, SensorNode)

MASS, G, V0 = 5600.0, 9.81, 0.6909
HIDDEN = {"show": False, "drawSize": -1.0, "color": [-1.0, -1.0, -1.0, -1.0]}


def exact_coulomb(k, c, force, friction, v0, end_time):
    """(t, x) of ``M x'' = force - k x - c v - friction sign(v)`` with exact sticking, dense enough to
    interpolate; and the list of (event, t, x)."""
    t, y = 0.0, np.array([0.0, v0])
    ts, xs, events = [0.0], [0.0], []
    mode = 1 if v0 > 0 else (-1 if v0 < 0 else 0)
    while t < end_time:
        if mode == 0:
            net = force - k * y[0]
            if abs(net) <= friction:  # nothing else changes: stuck for ever
                ts.append(end_time)
                xs.append(y[0])
                events.append(("stick", t, y[0]))
                break
            mode = 1 if net > 0 else -1

        def rhs(_, s, sign=mode):
            return [s[1], (force - k * s[0] - c * s[1] - sign * friction) / MASS]

        def stop(_, s):
            return s[1]
        stop.terminal, stop.direction = True, -mode
        sol = solve_ivp(rhs, (t, end_time), y, method="DOP853", rtol=1e-12, atol=1e-14, events=stop,
                        dense_output=True, max_step=1e-3)
        grid = np.linspace(t, sol.t[-1], 4000)
        ts += list(grid[1:])
        xs += list(sol.sol(grid)[0][1:])
        t, y = float(sol.t[-1]), sol.y[:, -1].copy()
        if sol.status == 1:
            y[1] = 0.0
            events.append(("v = 0", t, y[0]))
            net = force - k * y[0]
            mode = 0 if abs(net) <= friction else (1 if net > 0 else -1)
    return np.array(ts), np.array(xs), events


def build(law, friction, force, k=0.0, c=0.0, v_reg=1e-4, k_stick=1e9):
    """An Exudyn system of the barrel with ``law``; returns (SystemContainer, mbs, position sensor, keep-alive)."""
    system = exudyn.SystemContainer()
    mbs = system.AddSystem()
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0], initialCoordinates=[0.0],
                                       initialCoordinates_t=[V0], numberOfODE2Coordinates=1))
    mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=MASS))
    barrel = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
    if k or c:
        mbs.AddObject(ObjectConnectorCoordinateSpringDamper(markerNumbers=[ground, barrel], stiffness=k, damping=c,
                                                            visualization=HIDDEN))
    keep = None
    if law == "exudyn-regularised":
        mbs.AddObject(ObjectConnectorCoordinateSpringDamperExt(
            markerNumbers=[ground, barrel], dynamicFrictionForce=friction, frictionProportionalZone=v_reg,
            visualization=HIDDEN))
    elif law == "exudyn-bristle":
        data = mbs.AddNode(NodeGenericData(initialCoordinates=[friction, 0.0, 0.0], numberOfDataCoordinates=3))
        mbs.AddObject(ObjectConnectorCoordinateSpringDamperExt(
            markerNumbers=[ground, barrel], nodeNumber=data, dynamicFrictionForce=friction,
            frictionProportionalZone=0.0, stickingStiffness=k_stick,
            stickingDamping=2.0 * math.sqrt(k_stick * MASS), visualization=HIDDEN))
    elif law == "tanh":
        from exudyn.advancedUtilities import CreateSymbolicUserFunction
        esym = exudyn.symbolic
        index = mbs.AddObject(ObjectConnectorCoordinateSpringDamper(markerNumbers=[ground, barrel],
                                                                    visualization=HIDDEN))

        def user_function(mbs, t, item, d, v, stiffness, damping, offset):
            return friction * esym.tanh(v / v_reg)
        keep = CreateSymbolicUserFunction(mbs, user_function, "springForceUserFunction", index)
        mbs.SetObjectParameter(index, "springForceUserFunction", keep)
    else:
        raise ValueError(law)
    mbs.AddLoad(LoadCoordinate(markerNumber=barrel, load=force))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=exudyn.OutputVariableType.Coordinates,
                                      storeInternal=True))
    mbs.Assemble()
    return system, mbs, sensor, keep


def solve(mbs, solver, end_time, rtol=1e-9, atol=1e-11, max_step=5e-3, step=1e-4):
    """Run ``solver``; (steps, wall time s)."""
    settings = exudyn.SimulationSettings()
    ti = settings.timeIntegration
    ti.endTime, ti.verboseMode = end_time, 0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = 0.0
    if solver in ("DOPRI5", "ODE23"):
        ti.automaticStepSize = True
        ti.numberOfSteps = math.ceil(end_time / max_step)
        ti.relativeTolerance, ti.absoluteTolerance, ti.minimumStepSize = rtol, atol, 1e-12
    else:
        ti.automaticStepSize = False
        ti.numberOfSteps = math.ceil(end_time / step)
        ti.newton.relativeTolerance, ti.newton.absoluteTolerance = 1e-10, 1e-12
    exudyn.config.printToConsole = False
    start = time.perf_counter()
    mbs.SolveDynamic(settings, solverType=getattr(exudyn.DynamicSolverType, solver))
    return int(mbs.sys["dynamicSolver"].it.currentStepIndex), time.perf_counter() - start


LAWS = [("exudyn-regularised", dict(v_reg=1e-4)), ("exudyn-regularised", dict(v_reg=1e-5)), ("tanh", dict(v_reg=1e-4)),
        ("exudyn-bristle", dict(k_stick=1e9)), ("exudyn-bristle", dict(k_stick=1e7))]
SOLVERS = [("DOPRI5", {}), ("ODE23", {}), ("GeneralizedAlpha", dict(step=1e-4))]


def case_a(solvers):
    theta, mu = math.radians(10.0), 0.3
    friction, force = mu * MASS * G * math.cos(theta), MASS * G * math.sin(theta)
    deceleration = G * (mu * math.cos(theta) - math.sin(theta))
    t_stop, x_stop = V0 / deceleration, V0 ** 2 / (2 * deceleration)
    print(f"(a) block on a 10 deg incline, mu = 0.3: stops at t = {t_stop:.6f} s, x = {x_stop:.9f} m "
          f"(F_g / mu N = {force / friction:.3f}); creep = x(t_stop + 1 s) - x(t_stop)")
    for law, options in LAWS:
        for solver, settings in solvers:
            system, mbs, sensor, keep = build(law, friction, force, **options)
            steps, wall = solve(mbs, solver, t_stop + 1.0, **settings)
            x = mbs.GetSensorStoredData(sensor)
            at_stop = float(np.interp(t_stop, x[:, 0], x[:, 1]))
            print(f"  {law:19s} {str(options):20s} {solver:17s} steps {steps:7d}  {wall * 1e3:7.1f} ms  "
                  f"x(stop) error {at_stop - x_stop:+.1e} m  creep in 1 s {x[-1, 1] - at_stop:+.1e} m")
            system.Reset()


def case_b(solvers):
    k, c, end = 27500.0, 6239.0, 10.0
    for label, degrees, mu in (("level, mu = 0.05", 0.0, 0.05), ("level, mu = 0.6", 0.0, 0.6),
                               ("30 deg, mu = 0.05", 30.0, 0.05)):
        theta = math.radians(degrees)
        friction, force = mu * MASS * G * math.cos(theta), MASS * G * math.sin(theta)
        te, xe, events = exact_coulomb(k, c, force, friction, V0, end)
        print(f"(b) free recoil with friction, {label}: exact x_max = {xe.max():.9f} m, x(10 s) = {xe[-1]:.9f} m, "
              f"events {[(e[0], round(e[1], 4)) for e in events]}")
        for law, options in LAWS:
            for solver, settings in solvers:
                system, mbs, sensor, keep = build(law, friction, force, k, c, **options)
                steps, wall = solve(mbs, solver, end, **settings)
                x = mbs.GetSensorStoredData(sensor)
                worst = float(np.max(np.abs(np.interp(te, x[:, 0], x[:, 1]) - xe)))
                print(f"  {law:19s} {str(options):20s} {solver:17s} steps {steps:7d}  {wall * 1e3:7.1f} ms  "
                      f"x_max error {x[:, 1].max() - xe.max():+.1e} m  x(10 s) error {x[-1, 1] - xe[-1]:+.1e} m  "
                      f"largest |x error| {worst:.1e} m")
                system.Reset()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="DOPRI5 only")
    args = parser.parse_args()
    solvers = SOLVERS[:1] if args.quick else SOLVERS
    case_a(solvers)
    case_b(solvers)


if __name__ == "__main__":
    main()
