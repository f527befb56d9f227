"""Measure the two Exudyn routes for the planar "gun on its carriage" model (issue #22).

Standalone (numpy, scipy, exudyn; no project imports).  One test problem, built twice:

* route A -- minimal coordinates: one ``ObjectKinematicTree`` on a ``NodeGenericODE2`` of 4 coordinates
  ``q = (x_c, y_c, phi, x_b)``: a floating planar base (prismatic x, prismatic y, both massless links,
  then revolute z at the carriage CG carrying the carriage) and one prismatic link for the barrel, its axis
  through the trunnion along ``-e``, ``e = (cos th, sin th)`` (``x_b`` positive rearward).  The recoil
  spring-damper is an ``ObjectConnectorCoordinateSpringDamper`` between a ground coordinate marker and a
  ``MarkerNodeCoordinate`` on the tree node; the supports are ``ObjectConnectorCartesianSpringDamper``
  between a ground marker and a ``MarkerKinematicTreeRigid`` on the carriage link; DOPRI5.
* route B -- redundant coordinates: two ``ObjectRigidBody2D`` (carriage, barrel), an
  ``ObjectJointPrismatic2D``, the recoil spring-damper an ``ObjectConnectorSpringDamper`` along the axis
  (between the barrel CG and a carriage point a fixed distance ahead on the axis, so the spring length is
  ``L + x_b``), the same supports; an implicit index-3 solver (GeneralizedAlpha, fixed step).

Test problem: carriage 2000 kg, 1500 kg m^2 about its CG (2.4, 0.8) m; trunnion (2.5, 1.0) m; barrel
1000 kg (and 200 kg m^2, an assumption: the brief gives none) with its CG at the trunnion in battery;
recoil spring 27500 N/m, damper 6239 N s/m, preloaded by the barrel's weight along the settled axis
(``F = k (x_b - x_0) + c x_b'``, ``x_0 = -m_b g sin(th + phi_0) / k``) so the whole gun is in equilibrium;
spade at (0, 0): Kelvin-Voigt normal ``max(0, k p + c p')`` while ``p = -y > 0`` (k 5e8 N/m, c 2e6 N s/m)
plus a horizontal spring 2e8 N/m and damper 1e6 N s/m anchored at x = 0 while in contact; wheels at
(2.8, 0): Hunt-Crossley ``k p^n (1 + lambda p')`` (k 2e7, n 1, lambda 0.5 s/m), clipped at 0, and Coulomb
friction mu 0.3 regularised linearly below 1e-4 m/s.  Start: the statics (scipy), the barrel at
x_b = 0 with x_b' = 10 m/s (an impulse shot); 1 s.

Prints: the API checks, the routes' agreement, a work-precision table against a tight solution, wall
time per simulated second (median of 3; the load from /proc/loadavg), the 1-D model's cost, and what limits
DOPRI5's step in route A (route A re-run with one support parameter changed).
Usage: ``python scripts/carriage_routes.py [--quick]``.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time

import numpy as np
import scipy.optimize
from scipy.interpolate import CubicHermiteSpline

import exudyn as exu
from exudyn.advancedUtilities import CreateSymbolicUserFunction
from exudyn.itemInterface import (LoadCoordinate, LoadMassProportional, MarkerBodyMass, MarkerBodyPosition,
                                  MarkerBodyRigid, MarkerKinematicTreeRigid, MarkerNodeCoordinate, NodeGenericODE2,
                                  NodePointGround, NodeRigidBody2D, ObjectConnectorCartesianSpringDamper,
                                  ObjectConnectorCoordinateSpringDamper, ObjectConnectorSpringDamper,
                                  ObjectGround, ObjectJointPrismatic2D, ObjectKinematicTree, ObjectMass1D,
                                  ObjectRigidBody2D, SensorKinematicTree, SensorMarker, SensorNode)

esym = exu.symbolic
OVT = exu.OutputVariableType

G = 9.81                      # m/s^2
M_C, I_C = 2000.0, 1500.0     # carriage kg, kg m^2 (about its CG)
CG_C = np.array([2.4, 0.8])   # m
TRUNNION = np.array([2.5, 1.0])
M_B, I_B = 1000.0, 200.0      # barrel kg, kg m^2 (I_B assumed)
K_REC, C_REC = 27500.0, 6239.0
SPADE = np.array([0.0, 0.0])
K_SPADE, C_SPADE, KX_SPADE, CX_SPADE = 5e8, 2e6, 2e8, 1e6
WHEEL = np.array([2.8, 0.0])
K_WHEEL, N_WHEEL, LAMBDA_WHEEL, MU_WHEEL, V_REG = 2e7, 1.0, 0.5, 0.3, 1e-4
V_SHOT = 10.0                 # m/s, barrel rearward at t = 0
END_TIME = 1.0
AXIS_LENGTH = 10.0            # m, route B: the recoil spring's carriage point lies this far ahead on the axis


def rot(phi):
    c, s = math.cos(phi), math.sin(phi)
    return np.array([[c, -s], [s, c]])


# ---------------------------------------------------------------------------------------------------------
# Support laws, written once over a small "ops" namespace (Python floats or exudyn.symbolic expressions).
# The Cartesian connector passes d = p(marker1) - p(marker0), v likewise, and applies -f on marker1 (the
# carriage point; measured in check_cartesian_sign): the laws return minus the force on the carriage.
# ---------------------------------------------------------------------------------------------------------
class PyOps:
    @staticmethod
    def select(cond, a, b):
        return a if cond else b

    max = staticmethod(max)
    min = staticmethod(min)
    pow = staticmethod(math.pow)


class SymOps:
    @staticmethod
    def select(cond, a, b):
        wrap = (lambda v: esym.Real(v) if isinstance(v, (int, float)) else v)
        return esym.IfThenElse(cond, wrap(a), wrap(b))

    max = staticmethod(esym.max)
    min = staticmethod(esym.min)
    pow = staticmethod(esym.pow)


def spade_law(ops, d, v):
    """Minus the force on the carriage at the spade: normal max(0, k p + c p'), p = -y, while p > 0; horizontal
    -(kx x + cx x') while p > 0 (anchored at x = 0, the spade's rest x)."""
    p, pd = -d[1], -v[1]
    fy = ops.select(p > 0, ops.max(0.0, K_SPADE * p + C_SPADE * pd), 0.0)
    fx = ops.select(p > 0, -(KX_SPADE * d[0] + CX_SPADE * v[0]), 0.0)
    return [-fx, -fy, 0.0]


def wheel_law(ops, d, v):
    """Minus the force on the carriage at the wheels: Hunt-Crossley normal k p^n (1 + lambda p') >= 0 while
    p = -y > 0; friction -mu N clip(v_x / v_reg, -1, 1)."""
    p, pd = -d[1], -v[1]
    pos = ops.max(p, 0.0)
    fn = ops.select(p > 0, ops.max(0.0, K_WHEEL * ops.pow(pos, N_WHEEL) * (1.0 + LAMBDA_WHEEL * pd)), 0.0)
    ft = -MU_WHEEL * fn * ops.max(-1.0, ops.min(1.0, v[0] / V_REG))
    return [-ft, -fn, 0.0]


def cartesian_user_function(law, backend, mbs, item):
    """springForceUserFunction for ObjectConnectorCartesianSpringDamper ``item``: Python or symbolic."""
    if backend == "python":
        def uf(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
            return law(PyOps, displacement, velocity)
        return uf, None

    def uf(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        return law(SymOps, displacement, velocity)
    sym = CreateSymbolicUserFunction(mbs, uf, "springForceUserFunction", item)
    return sym, sym


def recoil_user_function(backend, mbs, item):
    """springForceUserFunction of the coordinate recoil spring-damper: k (d - offset) + c d' (the built-in law)."""
    def uf(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        return stiffness * (displacement - offset) + damping * velocity
    if backend == "python":
        return uf, None
    sym = CreateSymbolicUserFunction(mbs, uf, "springForceUserFunction", item)
    return sym, sym


# ---------------------------------------------------------------------------------------------------------
# Statics (scipy)
# ---------------------------------------------------------------------------------------------------------
def support_forces_numpy(q, qd=(0.0, 0.0, 0.0)):
    """(Fx, Fy, moment about the CG) of the supports on the carriage at carriage coordinates q = (x, y, phi)."""
    x, y, phi = q
    total = np.zeros(3)
    R = rot(phi)
    for point, law in ((SPADE, spade_law), (WHEEL, wheel_law)):
        r = R @ (point - CG_C)
        world = CG_C + np.array([x, y]) + r
        omega = qd[2]
        vel = np.array([qd[0] - omega * r[1], qd[1] + omega * r[0]])
        minus_f = law(PyOps, [world[0] - point[0], world[1] - point[1], 0.0], [vel[0], vel[1], 0.0])
        f = -np.array(minus_f[:2])
        total += [f[0], f[1], r[0] * f[1] - r[1] * f[0]]
    return total


def statics(theta):
    """Carriage (x, y, phi) at which the supports carry the gun's weight (barrel in battery, preloaded spring)."""
    def residual(q):
        f = support_forces_numpy(q)
        r_b = rot(q[2]) @ (TRUNNION - CG_C)
        weight = np.array([0.0, -(M_C + M_B) * G, -M_B * G * r_b[0]])
        return (f + weight) / np.array([1e4, 1e4, 1e4])
    W = (M_C + M_B) * G
    guess = np.array([0.0, -W / (K_SPADE + K_WHEEL), 0.0])
    sol = scipy.optimize.fsolve(residual, guess, xtol=1e-14, full_output=True)
    q = sol[0]
    if np.max(np.abs(residual(q))) > 1e-8:
        raise RuntimeError(f"statics failed: residual {residual(q)}")
    return q


# ---------------------------------------------------------------------------------------------------------
# Route A: kinematic tree
# ---------------------------------------------------------------------------------------------------------
def rotz3(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def build_tree(theta, q0, backend="symbolic", base_mass=0.0, recoil="builtin", v_shot=V_SHOT):
    """Route A.  Returns (SC, mbs, info); info holds the sensors and the node."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    keep = []
    n_tree = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * 4, initialCoordinates=[q0[0], q0[1], q0[2], 0.0],
                                         initialCoordinates_t=[0.0, 0.0, 0.0, v_shot], numberOfODE2Coordinates=4))
    I3 = np.eye(3)
    small = np.diag([1.0, 1.0, 1.0]) * base_mass
    o_tree = mbs.AddObject(ObjectKinematicTree(
        nodeNumber=n_tree, gravity=[0.0, -G, 0.0], baseOffset=[CG_C[0], CG_C[1], 0.0],
        jointTypes=[exu.JointType.PrismaticX, exu.JointType.PrismaticY, exu.JointType.RevoluteZ,
                    exu.JointType.PrismaticX],
        linkParents=[-1, 0, 1, 2],
        jointTransformations=exu.Matrix3DList([I3, I3, I3, rotz3(theta + math.pi)]),
        jointOffsets=exu.Vector3DList([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                                       [TRUNNION[0] - CG_C[0], TRUNNION[1] - CG_C[1], 0.0]]),
        linkInertiasCOM=exu.Matrix3DList([small, small, np.diag([I_C, I_C, I_C]), np.diag([I_B, I_B, I_B])]),
        linkCOMs=exu.Vector3DList([[0.0, 0.0, 0.0]] * 4),
        linkMasses=[base_mass, base_mass, M_C, M_B]))
    n_ground = mbs.AddNode(NodePointGround())
    m_ground_coord = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n_ground, coordinate=0))
    m_barrel_coord = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n_tree, coordinate=3))
    x_preload = -M_B * G * math.sin(theta + q0[2]) / K_REC   # the weight along the settled axis
    o_rec = mbs.AddObject(ObjectConnectorCoordinateSpringDamper(markerNumbers=[m_ground_coord, m_barrel_coord],
                                                                stiffness=K_REC, damping=C_REC, offset=x_preload))
    if recoil != "builtin":
        uf, sym = recoil_user_function(recoil, mbs, o_rec)
        keep.append(sym)
        mbs.SetObjectParameter(o_rec, "springForceUserFunction", uf)
    o_ground = mbs.AddObject(ObjectGround())
    sensors = {}
    for name, point, law in (("spade", SPADE, spade_law), ("wheel", WHEEL, wheel_law)):
        m_g = mbs.AddMarker(MarkerBodyPosition(bodyNumber=o_ground, localPosition=[point[0], point[1], 0.0]))
        local = point - CG_C
        m_c = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=o_tree, linkNumber=2,
                                                     localPosition=[local[0], local[1], 0.0]))
        o = mbs.AddObject(ObjectConnectorCartesianSpringDamper(markerNumbers=[m_g, m_c]))
        uf, sym = cartesian_user_function(law, backend, mbs, o)
        keep.append(sym)
        mbs.SetObjectParameter(o, "springForceUserFunction", uf)
        sensors[name + "_force"] = mbs.AddSensor(SensorMarker(markerNumber=m_c, outputVariableType=OVT.Position,
                                                              storeInternal=True, writeToFile=False))
    sensors["q"] = mbs.AddSensor(SensorNode(nodeNumber=n_tree, outputVariableType=OVT.Coordinates,
                                            storeInternal=True, writeToFile=False))
    sensors["qd"] = mbs.AddSensor(SensorNode(nodeNumber=n_tree, outputVariableType=OVT.Coordinates_t,
                                             storeInternal=True, writeToFile=False))
    sensors["wheel_pos_kt"] = mbs.AddSensor(SensorKinematicTree(
        objectNumber=o_tree, linkNumber=2, localPosition=[WHEEL[0] - CG_C[0], WHEEL[1] - CG_C[1], 0.0],
        outputVariableType=OVT.Position, storeInternal=True, writeToFile=False))
    mbs.Assemble()
    return SC, mbs, {"keep": keep, "sensors": sensors, "node": n_tree, "tree": o_tree}


def tree_history(mbs, info):
    """t, q (n x 4: x_c, y_c, phi, x_b), qd (n x 4) of route A."""
    q = mbs.GetSensorStoredData(info["sensors"]["q"])
    qd = mbs.GetSensorStoredData(info["sensors"]["qd"])
    return q[:, 0], q[:, 1:5], qd[:, 1:5]


# ---------------------------------------------------------------------------------------------------------
# Route B: redundant rigid bodies + prismatic joint
# ---------------------------------------------------------------------------------------------------------
def build_redundant(theta, q0, backend="symbolic", v_shot=V_SHOT):
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    keep = []
    e = np.array([math.cos(theta), math.sin(theta)])
    R0 = rot(q0[2])
    trunnion0 = CG_C + q0[:2] + R0 @ (TRUNNION - CG_C)
    v_b = -(R0 @ e) * v_shot                                    # rearward
    n_c = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[CG_C[0], CG_C[1], 0.0],
                                      initialCoordinates=[q0[0], q0[1], q0[2]]))
    n_b = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[TRUNNION[0], TRUNNION[1], 0.0],
                                      initialCoordinates=[trunnion0[0] - TRUNNION[0], trunnion0[1] - TRUNNION[1],
                                                          q0[2]],
                                      initialVelocities=[v_b[0], v_b[1], 0.0]))
    o_c = mbs.AddObject(ObjectRigidBody2D(mass=M_C, inertia=I_C, nodeNumber=n_c))
    o_b = mbs.AddObject(ObjectRigidBody2D(mass=M_B, inertia=I_B, nodeNumber=n_b))
    for o, m in ((o_c, M_C), (o_b, M_B)):
        mm = mbs.AddMarker(MarkerBodyMass(bodyNumber=o))
        mbs.AddLoad(LoadMassProportional(markerNumber=mm, loadVector=[0.0, -G, 0.0]))
    t_local = TRUNNION - CG_C
    m_ct = mbs.AddMarker(MarkerBodyRigid(bodyNumber=o_c, localPosition=[t_local[0], t_local[1], 0.0]))
    m_b = mbs.AddMarker(MarkerBodyRigid(bodyNumber=o_b, localPosition=[0.0, 0.0, 0.0]))
    mbs.AddObject(ObjectJointPrismatic2D(markerNumbers=[m_ct, m_b], axisMarker0=[-e[0], -e[1], 0.0],
                                         normalMarker1=[-e[1], e[0], 0.0], constrainRotation=True))
    ahead = t_local + AXIS_LENGTH * e
    m_ahead = mbs.AddMarker(MarkerBodyPosition(bodyNumber=o_c, localPosition=[ahead[0], ahead[1], 0.0]))
    x_preload = -M_B * G * math.sin(theta + q0[2]) / K_REC   # the weight along the settled axis
    # tension k (|d| - L0) + c |d|' with |d| = L + x_b: k (x_b - x_0) + c x_b', pulling the barrel forward
    mbs.AddObject(ObjectConnectorSpringDamper(markerNumbers=[m_ahead, m_b], referenceLength=AXIS_LENGTH + x_preload,
                                              stiffness=K_REC, damping=C_REC))
    o_ground = mbs.AddObject(ObjectGround())
    for point, law in ((SPADE, spade_law), (WHEEL, wheel_law)):
        m_g = mbs.AddMarker(MarkerBodyPosition(bodyNumber=o_ground, localPosition=[point[0], point[1], 0.0]))
        local = point - CG_C
        m_c = mbs.AddMarker(MarkerBodyPosition(bodyNumber=o_c, localPosition=[local[0], local[1], 0.0]))
        o = mbs.AddObject(ObjectConnectorCartesianSpringDamper(markerNumbers=[m_g, m_c]))
        uf, sym = cartesian_user_function(law, backend, mbs, o)
        keep.append(sym)
        mbs.SetObjectParameter(o, "springForceUserFunction", uf)
    sensors = {name: mbs.AddSensor(SensorNode(nodeNumber=n, outputVariableType=ovt, storeInternal=True,
                                              writeToFile=False))
               for name, n, ovt in (("c", n_c, OVT.Coordinates), ("cd", n_c, OVT.Coordinates_t),
                                    ("b", n_b, OVT.Coordinates), ("bd", n_b, OVT.Coordinates_t))}
    mbs.Assemble()
    return SC, mbs, {"keep": keep, "sensors": sensors, "theta": theta}


def redundant_history(mbs, info):
    """t, q, qd in route A's coordinates (x_c, y_c, phi, x_b) from route B's node coordinates."""
    s = info["sensors"]
    c, cd = mbs.GetSensorStoredData(s["c"]), mbs.GetSensorStoredData(s["cd"])
    b, bd = mbs.GetSensorStoredData(s["b"]), mbs.GetSensorStoredData(s["bd"])
    t = c[:, 0]
    th = info["theta"]
    phi, omega = c[:, 3], cd[:, 3]
    pc = CG_C + c[:, 1:3]
    pb = TRUNNION + b[:, 1:3]
    tl = TRUNNION - CG_C
    cph, sph = np.cos(phi), np.sin(phi)
    r = np.stack([cph * tl[0] - sph * tl[1], sph * tl[0] + cph * tl[1]], axis=1)     # R(phi) t_local
    axis = -np.stack([np.cos(th + phi), np.sin(th + phi)], axis=1)                    # rearward, world
    rel = pb - pc - r
    xb = np.sum(rel * axis, axis=1)
    # d/dt: rel' = v_b - v_c - omega x r ; axis' = omega x axis
    rel_d = bd[:, 1:3] - cd[:, 1:3] - omega[:, None] * np.stack([-r[:, 1], r[:, 0]], axis=1)
    axis_d = omega[:, None] * np.stack([-axis[:, 1], axis[:, 0]], axis=1)
    xbd = np.sum(rel_d * axis, axis=1) + np.sum(rel * axis_d, axis=1)
    q = np.column_stack([c[:, 1], c[:, 2], phi, xb])
    qd = np.column_stack([cd[:, 1], cd[:, 2], omega, xbd])
    return t, q, qd


# ---------------------------------------------------------------------------------------------------------
# The 1-D model: the barrel alone on the recoil spring-damper
# ---------------------------------------------------------------------------------------------------------
def build_1d(theta, backend="builtin"):
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    n = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0], initialCoordinates=[0.0], initialCoordinates_t=[V_SHOT],
                                    numberOfODE2Coordinates=1))
    o = mbs.AddObject(ObjectMass1D(mass=M_B, nodeNumber=n))
    n_g = mbs.AddNode(NodePointGround())
    m_g = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n_g, coordinate=0))
    m_b = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n, coordinate=0))
    mbs.AddObject(ObjectConnectorCoordinateSpringDamper(markerNumbers=[m_g, m_b], stiffness=K_REC, damping=C_REC,
                                                        offset=-M_B * G * math.sin(theta) / K_REC))
    mbs.AddLoad(LoadCoordinate(markerNumber=m_b, load=M_B * G * math.sin(theta)))
    s = mbs.AddSensor(SensorNode(nodeNumber=n, outputVariableType=OVT.Coordinates, storeInternal=True,
                                 writeToFile=False))
    mbs.Assemble()
    return SC, mbs, {"keep": [], "sensors": {"q": s}}


# ---------------------------------------------------------------------------------------------------------
# Solving
# ---------------------------------------------------------------------------------------------------------
def settings(solver, tol=None, step=None, end_time=END_TIME, start_time=0.0):
    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.endTime = end_time
    ti.startTime = start_time
    ti.verboseMode = 0
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = 0.0
    if solver in ("DOPRI5", "ODE23"):
        ti.explicit.computeEndOfStepAccelerations = False
    if tol is not None:
        # Exudyn scales the error by atol + max(y0, y1) rtol (signed): atol = rtol puts its zero at -1 (m, m/s)
        ti.automaticStepSize = True
        ti.relativeTolerance = tol
        ti.absoluteTolerance = tol
        ti.numberOfSteps = int(round(end_time - start_time) * 1000) or 1000   # max step 1 ms
        ti.minimumStepSize = 1e-12
        ti.initialStepSize = 1e-6
    else:
        ti.automaticStepSize = False
        ti.numberOfSteps = int(round((end_time - start_time) / step))
        ti.newton.relativeTolerance = 1e-10
        ti.newton.absoluteTolerance = 1e-12
        ti.generalizedAlpha.spectralRadius = 0.9
    return ss


def solve(mbs, solver, tol=None, step=None, end_time=END_TIME, start_time=0.0):
    """(wall time s, steps, success)."""
    ss = settings(solver, tol, step, end_time, start_time)
    t0 = time.perf_counter()
    ok = mbs.SolveDynamic(ss, solverType=getattr(exu.DynamicSolverType, solver))
    wall = time.perf_counter() - t0
    it = mbs.sys["dynamicSolver"].it
    return wall, int(it.currentStepIndex), bool(ok) and it.currentTime >= end_time * (1 - 1e-9)


def timed(build, run_solver, repeats=3):
    """Median wall time (s) of ``repeats`` fresh builds + solves (only the solve is timed), the steps, and the
    last run's (SC, mbs, info)."""
    walls, steps = [], None
    for _ in range(repeats):
        SC, mbs, info = build()
        wall, steps, ok = run_solver(mbs)
        if not ok:
            raise RuntimeError("solve failed")
        walls.append(wall)
    return statistics.median(walls), steps, (SC, mbs, info)


def loadavg():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def max_error(t, q, ref):
    """Max |q - reference| per coordinate over the test's output times (reference: cubic Hermite through the
    tight solution's positions and velocities)."""
    return np.array([np.max(np.abs(q[:, i] - ref[i](t))) for i in range(4)])


def hermite(t, q, qd):
    keep = np.concatenate([[True], np.diff(t) > 0])
    return [CubicHermiteSpline(t[keep], q[keep, i], qd[keep, i]) for i in range(4)]


# ---------------------------------------------------------------------------------------------------------
# API checks
# ---------------------------------------------------------------------------------------------------------
def check_cartesian_sign():
    """Q1: what the Cartesian connector's user function receives and where its returned f acts."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    og = mbs.AddObject(ObjectGround())
    from exudyn.itemInterface import NodePoint2D, ObjectMassPoint2D
    n = mbs.AddNode(NodePoint2D(referenceCoordinates=[1.0, 2.0], initialVelocities=[0.3, 0.4]))
    o = mbs.AddObject(ObjectMassPoint2D(mass=2.0, nodeNumber=n))
    m0 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=og, localPosition=[0.5, 0.5, 0.0]))
    m1 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=o, localPosition=[0.0, 0.0, 0.0]))
    seen = []

    def uf(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        seen.append((t, list(displacement), list(velocity)))
        return [10.0, 20.0, 0.0]
    mbs.AddObject(ObjectConnectorCartesianSpringDamper(markerNumbers=[m0, m1], springForceUserFunction=uf))
    mbs.Assemble()
    mbs.SolveDynamic(settings("ExplicitEuler", step=1e-3, end_time=1e-3),
                     solverType=exu.DynamicSolverType.ExplicitEuler)
    acc = mbs.GetNodeOutput(n, OVT.Coordinates_tt)
    print("Q1 Cartesian connector: marker0 ground at (0.5, 0.5), marker1 point at (1, 2) moving (0.3, 0.4) m/s")
    print(f"   first call: d = {seen[0][1][:2]}, v = {seen[0][2][:2]}  (d = p1 - p0, v = v1 - v0)")
    print(f"   user function returns f = (10, 20): point (2 kg) accelerates {list(acc)} -> marker1 gets -f, marker0 +f")


def check_coordinate_marker_on_tree():
    """Q2: a 1-link tree (prismatic along -e, 45 deg) with the coordinate spring: q'' against the hand value."""
    theta = math.radians(45.0)
    results = {}
    for recoil in ("builtin", "symbolic", "python"):
        SC = exu.SystemContainer()
        mbs = SC.AddSystem()
        n = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0], initialCoordinates=[0.1],
                                        initialCoordinates_t=[2.0], numberOfODE2Coordinates=1))
        mbs.AddObject(ObjectKinematicTree(nodeNumber=n, gravity=[0.0, -G, 0.0], jointTypes=[exu.JointType.PrismaticX],
                                          linkParents=[-1],
                                          jointTransformations=exu.Matrix3DList([rotz3(theta + math.pi)]),
                                          jointOffsets=exu.Vector3DList([[0.0, 0.0, 0.0]]),
                                          linkInertiasCOM=exu.Matrix3DList([np.eye(3)]),
                                          linkCOMs=exu.Vector3DList([[0.0, 0.0, 0.0]]), linkMasses=[M_B]))
        n_g = mbs.AddNode(NodePointGround())
        mg = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n_g, coordinate=0))
        mq = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n, coordinate=0))
        o = mbs.AddObject(ObjectConnectorCoordinateSpringDamper(markerNumbers=[mg, mq], stiffness=K_REC, damping=C_REC,
                                                                offset=0.02))
        keep = None
        if recoil != "builtin":
            uf, keep = recoil_user_function(recoil, mbs, o)
            mbs.SetObjectParameter(o, "springForceUserFunction", uf)
        s = mbs.AddSensor(SensorNode(nodeNumber=n, outputVariableType=OVT.Coordinates_tt, storeInternal=True,
                                     writeToFile=False))
        mbs.Assemble()
        ss = settings("DOPRI5", step=1e-9, end_time=1e-9)
        ss.timeIntegration.explicit.computeEndOfStepAccelerations = True
        mbs.SolveDynamic(ss, solverType=exu.DynamicSolverType.DOPRI5)
        results[recoil] = mbs.GetSensorStoredData(s)[-1, 1]
        del keep
    hand = (M_B * G * math.sin(theta) - K_REC * (0.1 - 0.02) - C_REC * 2.0) / M_B
    print("Q2 coordinate spring-damper on the tree node coordinate (1 prismatic link along -e, 45 deg, x=0.1, v=2):")
    print(f"   q'' at t=0: builtin {results['builtin']:.10g}, symbolic {results['symbolic']:.10g}, "
          f"python {results['python']:.10g}; hand (m g sin th - k (x - off) - c v)/m = {hand:.10g}")


def check_statics(theta, q0):
    """Run route A with no shot for 0.2 s: the statics must hold (drift)."""
    SC, mbs, info = build_tree(theta, q0, v_shot=0.0)
    wall, steps, ok = solve(mbs, "DOPRI5", tol=1e-8, end_time=0.2)
    t, q, qd = tree_history(mbs, info)
    drift = np.max(np.abs(q - q[0]), axis=0)
    print(f"   statics th={math.degrees(theta):.0f} deg: q0 = ({q0[0]:.3e} m, {q0[1]:.4e} m, {q0[2]:.4e} rad); "
          f"no-shot drift over 0.2 s: {drift[0]:.1e} m, {drift[1]:.1e} m, {drift[2]:.1e} rad, {drift[3]:.1e} m "
          f"({steps} steps)")


def check_zero_mass_base(theta, q0):
    """Q3: base links of zero mass against base links of 1e-6 kg (and 1 kg)."""
    out = {}
    for mass in (0.0, 1e-6):
        SC, mbs, info = build_tree(theta, q0, base_mass=mass)
        wall, steps, ok = solve(mbs, "DOPRI5", tol=1e-8)
        t, q, qd = tree_history(mbs, info)
        out[mass] = (ok, steps, q[-1])
    d = np.abs(out[0.0][2] - out[1e-6][2])
    print(f"Q3 zero-mass base links: DOPRI5 ok={out[0.0][0]} ({out[0.0][1]} steps); vs 1e-6 kg base links "
          f"({out[1e-6][1]} steps): |q(1 s)| differences {d[0]:.1e}, {d[1]:.1e}, {d[2]:.1e}, {d[3]:.1e}")


def check_sensors(theta, q0):
    """Q4: shapes of the tree sensors; the wheel point from SensorKinematicTree vs SensorMarker vs q."""
    SC, mbs, info = build_tree(theta, q0)
    solve(mbs, "DOPRI5", tol=1e-6, end_time=0.01)
    s = info["sensors"]
    q = mbs.GetSensorStoredData(s["q"])
    kt = mbs.GetSensorStoredData(s["wheel_pos_kt"])
    sm = mbs.GetSensorStoredData(s["wheel_force"])
    local = WHEEL - CG_C
    phi = q[:, 3]
    by_hand = np.stack([CG_C[0] + q[:, 1] + np.cos(phi) * local[0] - np.sin(phi) * local[1],
                        CG_C[1] + q[:, 2] + np.sin(phi) * local[0] + np.cos(phi) * local[1]], axis=1)
    print(f"Q4 SensorNode(Coordinates) stored data shape {q.shape} (rows: output steps; columns: t, q0..q3); "
          f"SensorKinematicTree(Position) {kt.shape}; SensorMarker(MarkerKinematicTreeRigid, Position) {sm.shape}")
    print(f"   wheel point: max |KinematicTree - by hand from q| = {np.max(np.abs(kt[:, 1:3] - by_hand)):.1e} m, "
          f"max |Marker - KinematicTree| = {np.max(np.abs(sm[:, 1:4] - kt[:, 1:4])):.1e} m")


def check_restart(theta, q0):
    """Q5: solve to 0.3 s without the shot, then jump the barrel coordinate's velocity and continue to 1 s;
    against one solve with the shot applied at 0.3 s from the same state (a fresh system)."""
    SC, mbs, info = build_tree(theta, q0, v_shot=0.0)
    solve(mbs, "DOPRI5", tol=1e-8, end_time=0.3)
    node_ltg = mbs.systemData.GetNodeLTGODE2(info["node"])
    qd_now = mbs.systemData.GetODE2Coordinates_t()
    q_now = mbs.systemData.GetODE2Coordinates()
    qd_now[node_ltg[3]] += V_SHOT
    mbs.systemData.SetODE2Coordinates_t(qd_now, configuration=exu.ConfigurationType.Initial)
    mbs.systemData.SetODE2Coordinates(q_now, configuration=exu.ConfigurationType.Initial)
    ss = settings("DOPRI5", tol=1e-8, start_time=0.3, end_time=1.0)
    ss.timeIntegration.initialStepSize = 1e-6
    ok = mbs.SolveDynamic(ss, solverType=exu.DynamicSolverType.DOPRI5)
    t, q, qd = tree_history(mbs, info)
    # the same from a fresh system started at the 0.3 s state with the shot
    SC2, mbs2, info2 = build_tree(theta, q0)
    ss2 = settings("DOPRI5", tol=1e-8, start_time=0.3, end_time=1.0)
    init = q_now.copy()
    mbs2.systemData.SetODE2Coordinates(init, configuration=exu.ConfigurationType.Initial)
    qd2 = np.zeros(4)
    qd2[:] = qd_now[node_ltg]
    full = mbs2.systemData.GetODE2Coordinates_t(configuration=exu.ConfigurationType.Initial)
    full[node_ltg] = qd2
    mbs2.systemData.SetODE2Coordinates_t(full, configuration=exu.ConfigurationType.Initial)
    mbs2.SolveDynamic(ss2, solverType=exu.DynamicSolverType.DOPRI5)
    t2, q2, qd2h = tree_history(mbs2, info2)
    print(f"Q5 velocity jump between two solves: LTG of the tree node = {list(node_ltg)}; second solve ok={ok}, "
          f"starts at t={t[0]:.3f} with x_b'={qd[0, 3]:.4f} m/s; |q(1 s) - fresh solve from that state| = "
          f"{np.max(np.abs(q[-1] - q2[-1])):.1e}")


def check_dopri5_with_constraints(theta, q0):
    """Route B with DOPRI5: what happens."""
    SC, mbs, info = build_redundant(theta, q0)
    exu.config.printToConsole = False
    try:
        wall, steps, ok = solve(mbs, "DOPRI5", tol=1e-6, end_time=0.01)
        msg = f"returned ok={ok} after {steps} steps"
    except Exception as exc:  # noqa: BLE001 -- what Exudyn says is the answer
        msg = "raised: " + " ".join(str(exc).split())[:300]
    finally:
        exu.config.printToConsole = True
    print(f"   route B with DOPRI5: {msg}")


def step_limiter_table(theta):
    """What sets DOPRI5's step in route A: the wheel friction's band (a damper mu N / v_reg ~ 9e7 N s/m) or the
    spade.  Re-runs route A with one support parameter changed (module constants, restored after)."""
    global V_REG, MU_WHEEL, K_SPADE, C_SPADE
    saved = (V_REG, MU_WHEEL, K_SPADE, C_SPADE)
    print(f"what limits DOPRI5's steps (route A, {math.degrees(theta):.0f} deg, symbolic; steps at tol 1e-4 / 1e-6):")
    cases = (("as given", {}), ("wheel v_reg 1e-3 m/s", {"V_REG": 1e-3}), ("wheel v_reg 1e-2 m/s", {"V_REG": 1e-2}),
             ("no wheel friction", {"MU_WHEEL": 0.0}), ("spade k 5e7, c 2e5", {"K_SPADE": 5e7, "C_SPADE": 2e5}))
    try:
        for label, change in cases:
            V_REG, MU_WHEEL, K_SPADE, C_SPADE = saved
            globals().update(change)
            q0 = statics(theta)
            counts = []
            for tol in (1e-4, 1e-6):
                SC, mbs, info = build_tree(theta, q0)
                wall, steps, ok = solve(mbs, "DOPRI5", tol=tol)
                counts.append(f"{steps:6d} steps {wall:6.3f} s")
            print(f"   {label:24s} " + "   ".join(counts))
    finally:
        V_REG, MU_WHEEL, K_SPADE, C_SPADE = saved


# ---------------------------------------------------------------------------------------------------------
def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one timing repeat, fewer tolerances")
    args = parser.parse_args()
    repeats = 1 if args.quick else 3
    print(f"exudyn {exu.__version__}, numpy {np.__version__}; load at start: {loadavg()}; {os.cpu_count()} cores")
    print()
    print("== API checks ==")
    check_cartesian_sign()
    check_coordinate_marker_on_tree()
    for deg in (0.0, 45.0):
        th = math.radians(deg)
        check_statics(th, statics(th))
    th45 = math.radians(45.0)
    q45 = statics(th45)
    check_zero_mass_base(th45, q45)
    check_sensors(th45, q45)
    check_restart(th45, q45)
    check_dopri5_with_constraints(th45, q45)
    print()

    tols = [1e-4, 1e-6, 1e-8] if not args.quick else [1e-4, 1e-6]
    steps_b = [1e-3, 1e-4, 1e-5] if not args.quick else [1e-3, 1e-4]
    for deg in (0.0, 45.0):
        th = math.radians(deg)
        q0 = statics(th)
        print(f"== elevation {deg:.0f} deg ==")
        # reference: route A, DOPRI5 rtol = atol = 1e-11
        SC, mbs, info = build_tree(th, q0)
        wall, steps, ok = solve(mbs, "DOPRI5", tol=1e-11)
        tr, qr, qdr = tree_history(mbs, info)
        ref = hermite(tr, qr, qdr)
        extremes = (f"x_c in [{qr[:, 0].min():.4g}, {qr[:, 0].max():.4g}] m, y_c in [{qr[:, 1].min():.4g}, "
                    f"{qr[:, 1].max():.4g}] m, phi in [{qr[:, 2].min():.4g}, {qr[:, 2].max():.4g}] rad, "
                    f"x_b in [{qr[:, 3].min():.4g}, {qr[:, 3].max():.4g}] m")
        print(f"reference (A, DOPRI5 tol 1e-11, symbolic): {steps} steps, ok={ok}; {extremes}")
        rows, last = [], {}
        runs = [(f"A tree DOPRI5 tol {tol:.0e} ({backend})", "A", backend, "DOPRI5", tol, None)
                for backend in ("symbolic", "python") for tol in tols if backend == "symbolic" or tol == 1e-6]
        runs += [(f"A tree GenAlpha h {h:.0e} (symbolic)", "A", "symbolic", "GeneralizedAlpha", None, h)
                 for h in steps_b[:2]]
        runs += [(f"B bodies+prismatic GenAlpha h {h:.0e} ({backend})", "B", backend, "GeneralizedAlpha", None, h)
                 for backend in ("symbolic", "python") for h in steps_b if backend == "symbolic" or h == 1e-4]
        runs += [(f"B bodies+prismatic TrapIndex2 h {h:.0e} (symbolic)", "B", "symbolic", "TrapezoidalIndex2", None, h)
                 for h in steps_b[:2]]
        for name, route, backend, solver, tol, h in runs:
            builder, history = (build_tree, tree_history) if route == "A" else (build_redundant, redundant_history)
            build = (lambda: builder(th, q0, backend=backend))
            wall, st, (SC, mbs, info) = timed(build, lambda m: solve(m, solver, tol=tol, step=h), repeats)
            t, q, qd = history(mbs, info)
            last[name] = (t, q, qd)
            rows.append((name, st, wall, max_error(t, q, ref)))
        wall_1d, st_1d, _ = timed(lambda: build_1d(th), lambda m: solve(m, "DOPRI5", tol=1e-6), repeats)
        print(f"{'run':46s} {'steps':>7s} {'wall/sim s':>10s} {'us/step':>8s} {'x 1-D':>6s}  max |error| vs reference:"
              f" {'x_c m':>8s} {'y_c m':>8s} {'phi rad':>8s} {'x_b m':>8s}")
        for name, st, wall, err in rows:
            print(f"{name:46s} {st:7d} {wall:9.4f}s {1e6 * wall / st:8.1f} {wall / wall_1d:6.0f}  {'':25s}"
                  + " ".join(f"{e:8.1e}" for e in err))
        print(f"{'1-D barrel alone, DOPRI5 tol 1e-06 (builtin)':46s} {st_1d:7d} {wall_1d:9.5f}s "
              f"{1e6 * wall_1d / st_1d:8.1f} {1:6d}")
        a_name = f"A tree DOPRI5 tol {tols[-1]:.0e} (symbolic)"
        b_name = f"B bodies+prismatic GenAlpha h {steps_b[-1]:.0e} (symbolic)"
        ta, qa, qda = last[a_name]
        tb, qb, qdb = last[b_name]
        diff = max_error(tb, qb, hermite(ta, qa, qda))
        print(f"A vs B: max |{b_name} - {a_name}| = " + ", ".join(f"{d:.1e}" for d in diff)
              + " (x_c m, y_c m, phi rad, x_b m)")
        sp, py = last[f"A tree DOPRI5 tol 1e-06 (symbolic)"], last[f"A tree DOPRI5 tol 1e-06 (python)"]
        same = sp[0].shape == py[0].shape and np.array_equal(sp[1], py[1])
        print(f"A symbolic vs Python user functions, tol 1e-6: same steps and bit-identical q: {same}"
              + ("" if same else f" (max |dq| {np.max(np.abs(sp[1][-1] - py[1][-1])):.1e} at the end)"))
        print(f"load now: {loadavg()}")
        print()
    step_limiter_table(math.radians(45.0))


if __name__ == "__main__":
    sys.exit(main())
