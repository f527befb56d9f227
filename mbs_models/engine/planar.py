"""The carriage in Exudyn: one minimal-coordinate ``ObjectKinematicTree`` for the whole gun, supports as contacts.

Only a scene with a ``[carriage]`` table gets these items (:func:`~mbs_models.engine.assembly.assemble` calls
:func:`add_carriage` instead of adding a 1-D node per body); without it nothing here is assembled.

The tree (one ``NodeGenericODE2`` of ``3 + n`` coordinates ``q = (X, Y, phi, x_1 .. x_n)``)::

    link 0  PrismaticX   parent -1   mass 0         X: the carriage frame's horizontal offset (m)
    link 1  PrismaticY   parent 0    mass 0         Y: its vertical offset (m)
    link 2  RevoluteZ    parent 1    m_c, I_c, CG   phi: the pitch (rad, nose up)
    link 3+i PrismaticX  parent 2    m_i, I_i       x_i: body i along the recoil axis, rearward from battery (m)

A body's joint sits at ``trunnion + b e`` in the carriage frame, turned by ``theta + pi`` so that its joint axis
(local x) is ``-e``: the coordinate grows rearward exactly as the 1-D model's, and its CG is at
``trunnion + (b - x_i) e``.  Because every axis coordinate is relative to the carriage, each 1-D element's
coordinate connector (between the ground's coordinate marker, now meaning the cradle, and the body's coordinate
marker on the tree's node) acts unchanged along the axis, and its reaction goes into the carriage through the
tree's equations.  Gravity is the tree's ``gravity`` (every link, vertically).  An external load of a body (the
breech force) is a ``LoadForceVector`` along the body's local x on a ``MarkerKinematicTreeRigid`` of its link:
a force on that body alone, not on the carriage.

The supports and the external loads act through the tree's force user function (:func:`generalized_forces`, one
function over the backend ops, recorded once as an Exudyn symbolic function): a support at the carriage-frame
point ``r`` is at ``P = (X, Y) + R(phi) r`` with ``dP/dphi = R'(phi) r``; its force ``(T, N)`` (the support law of
:mod:`mbs_models.elements.carriage`) adds ``(T, N, (T, N) . dP/dphi)`` to ``(Q_X, Q_Y, Q_phi)``.  A load ``F(t)``
pulling body ``i`` rearward along the axis, ``f = F (-R(phi) e)`` at its CG ``r_i = (X, Y) + R(phi) a_i``, adds
``f . dr_i/dq``: ``(f, f . R'(phi) a_i)`` to the carriage's and ``F`` to ``Q_i`` (``dr_i/dx_i = -R e``).
(Measured, Exudyn 1.13.6: a ``CartesianSpringDamper`` on a ``MarkerKinematicTreeRigid`` per support cost ~17 us
per step each; the tree's force user function with both supports ~8 us in all: ``scripts/carriage_routes.py``,
``scripts/bench_carriage.py``.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..elements.carriage import (AnchorCapture, AxisBody, StaticState, elevation_of, onset_capture, gravity_of, static_equilibrium,
                                 support_normal_force, support_tangential_force)
from ..elements.ops import PYTHON_OPS, Ops, ops_for

#: Tree coordinates before the axis bodies: X, Y, phi.
CARRIAGE_COORDINATES = ("carriage_x", "carriage_y", "carriage_pitch")


@dataclass
class PlanarItems:
    """What :func:`add_carriage` added: the tree node and object, each body's coordinate index in the node, the
    static state and the user function (kept alive as long as the system)."""

    node: Any
    tree: Any
    static: StaticState
    body_coordinate: dict[str, int]
    keep: list = field(default_factory=list)
    #: support name -> its :class:`~mbs_models.elements.carriage.AnchorCapture` (``anchor = "touchdown"`` spades)
    anchors: dict = field(default_factory=dict)
    #: support name -> its :class:`~mbs_models.elements.contact_laws.OnsetCapture` (restitution laws: ``v-``)
    onsets: dict = field(default_factory=dict)
    #: support name -> its carriage-frame point (m), for the captures
    anchor_points: dict = field(default_factory=dict)

    @property
    def captures(self) -> bool:
        """Does a support capture anything at the step starts (a touchdown anchor, a restitution law's ``v-``)?"""
        return bool(self.anchors or self.onsets)

    def observe(self, t: float, q, v) -> None:
        """The tree's state (``q``, ``v``: its coordinates in order) at the step start ``t``: the touchdown anchors
        follow their points while off the ground; the restitution laws see the penetration and its rate."""
        X, Y, phi = q[0], q[1], q[2]
        c, s = math.cos(phi), math.sin(phi)
        for support, capture in self.anchors.items():
            rx, ry = self.anchor_points[support]
            capture.observe(t, X + c * rx - s * ry, Y + s * rx + c * ry)
        for support, capture in self.onsets.items():
            rx, ry = self.anchor_points[support]
            height = Y + s * rx + c * ry
            rate = v[1] + v[2] * (c * rx - s * ry)
            capture.observe(t, -height, -rate)


def axis_bodies(mechanism) -> list[AxisBody]:
    """The mechanism's bodies as the planar model sees them (the barrel carries ``barrel_inertia``)."""
    inertia = mechanism.scene.carriage.barrel_inertia
    return [AxisBody(b.name, b.mass, inertia if i == 0 else 0.0, b.initial_position)
            for i, b in enumerate(mechanism.bodies)]


def _rotation_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def generalized_forces(scene, supports, anchors: dict, loads, q, q_t, t, ops: Ops, lams: dict | None = None) -> list:
    """The ``supports``' and the loads' generalised forces ``[Q_X, Q_Y, Q_phi, Q_1 .. Q_n]`` (N, N, N m, N ...) at
    the tree state ``q``, ``q_t`` and time ``t`` (s), over ``ops`` (module docstring).  ``anchors``: each support's
    static x (m); ``loads``: ``(tree coordinate, law)`` pairs, ``law(t)`` the force (N, + = rearward) over ``ops``;
    ``lams``: the restitution laws' ``chi / max(v-, floor)`` (s/m) by support name."""
    carriage, theta = scene.carriage, elevation_of(scene)
    X, Y, phi = q[0], q[1], q[2]
    c, s = ops.cos(phi), ops.sin(phi)
    zero = 0.0 * X
    out = [zero] * len(q)
    for support in supports:
        rx, ry = support.position
        dx, dy = -s * rx - c * ry, c * rx - s * ry           # dP/dphi
        x, y = X + c * rx - s * ry, Y + s * rx + c * ry
        u, v = q_t[0] + q_t[2] * dx, q_t[1] + q_t[2] * dy
        normal = support_normal_force(support, y, v, ops, (lams or {}).get(support.name))
        tangential = support_tangential_force(support, normal, x, u, anchors[support.name], ops, y)
        out[0], out[1] = out[0] + tangential, out[1] + normal
        out[2] = out[2] + tangential * dx + normal * dy
    ex, ey = math.cos(theta), math.sin(theta)
    for k, law in loads:
        force = law(t)
        along = carriage.barrel_center_of_mass - q[k]
        ax, ay = carriage.trunnion[0] + along * ex, carriage.trunnion[1] + along * ey
        fx, fy = -force * (c * ex - s * ey), -force * (s * ex + c * ey)
        out[0], out[1] = out[0] + fx, out[1] + fy
        out[2] = out[2] + fx * (-s * ax - c * ay) + fy * (c * ax - s * ay)
        out[k] = out[k] + force
    return out


def add_carriage(mbs, mechanism, user_functions: str) -> PlanarItems:
    """Add the gun's tree (with its supports and its bodies' loads in the tree's force user function) to ``mbs``
    (module docstring); the tree starts in the static equilibrium
    (:func:`~mbs_models.elements.carriage.static_equilibrium`) with the axis bodies at their initial positions and
    velocities."""
    import exudyn
    from exudyn.itemInterface import NodeGenericODE2, ObjectKinematicTree

    scene = mechanism.scene
    carriage = scene.carriage
    theta, g = elevation_of(scene), gravity_of(scene)
    bodies = axis_bodies(mechanism)
    static = static_equilibrium(carriage, theta, g, bodies)
    n = 3 + len(bodies)
    initial = [0.0, static.height, static.pitch] + [b.position for b in bodies]
    initial_velocity = [0.0, 0.0, 0.0] + [b.initial_velocity for b in mechanism.bodies]
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n, initialCoordinates=initial,
                                       initialCoordinates_t=initial_velocity, numberOfODE2Coordinates=n))
    joint = exudyn.JointType
    zero = np.zeros((3, 3))
    joint_at = (carriage.trunnion[0] + carriage.barrel_center_of_mass * math.cos(theta),
                carriage.trunnion[1] + carriage.barrel_center_of_mass * math.sin(theta), 0.0)
    tree = mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node,
        jointTypes=[joint.PrismaticX, joint.PrismaticY, joint.RevoluteZ] + [joint.PrismaticX] * len(bodies),
        linkParents=[-1, 0, 1] + [2] * len(bodies),
        jointTransformations=exudyn.Matrix3DList([np.eye(3)] * 3 + [_rotation_z(theta + math.pi)] * len(bodies)),
        jointOffsets=exudyn.Vector3DList([[0.0, 0.0, 0.0]] * 3 + [list(joint_at)] * len(bodies)),
        linkInertiasCOM=exudyn.Matrix3DList([zero, zero, np.eye(3) * carriage.inertia]
                                            + [np.eye(3) * b.inertia for b in bodies]),
        linkCOMs=exudyn.Vector3DList([[0.0, 0.0, 0.0]] * 2 + [[*carriage.center_of_mass, 0.0]]
                                     + [[0.0, 0.0, 0.0]] * len(bodies)),
        linkMasses=[0.0, 0.0, carriage.mass] + [b.mass for b in bodies],
        gravity=[0.0, -g, 0.0]))
    items = PlanarItems(node=node, tree=tree, static=static,
                        body_coordinate={b.name: 3 + i for i, b in enumerate(bodies)})
    for support in carriage.supports:
        items.anchor_points[support.name] = support.position
        if support.anchored and support.anchor == "touchdown":
            items.anchors[support.name] = AnchorCapture(static.anchors[support.name])
        capture = onset_capture(support, static.loads[support.name])  # v- of each touch-down (restitution laws)
        if capture is not None:
            items.onsets[support.name] = capture
    _set_tree_forces(mbs, items, mechanism, user_functions, n)
    return items


def _set_tree_forces(mbs, items: PlanarItems, mechanism, user_functions: str, n: int) -> None:
    """:func:`generalized_forces` as the tree's force user function (Python, or recorded as a symbolic function
    with state vectors of the tree's size: Exudyn's own conversion records them empty)."""
    ops = ops_for(user_functions)
    loads = [(items.body_coordinate[load.body], load.user_function_law(ops)) for load in mechanism.loads]
    scene, anchors, lams = mechanism.scene, dict(items.static.anchors), {}
    captures, onsets = items.anchors, items.onsets
    if user_functions == "symbolic":  # the captured values: variables the pre-step function sets
        import exudyn
        for name, capture in captures.items():
            capture._variable = exudyn.symbolic.Real(f"anchor_{name}_{id(capture)}", capture.anchor)
            anchors[name] = capture._variable
        for name, capture in onsets.items():
            capture._variable = exudyn.symbolic.Real(f"lam_{name}_{id(capture)}", capture.lam)
            lams[name] = capture._variable
        captures, onsets = {}, {}

    def user_function(mbs, t, itemNumber, q, q_t):
        for name, capture in captures.items():  # (Python: read at every call)
            anchors[name] = capture.anchor
        for name, capture in onsets.items():
            lams[name] = capture.lam
        return generalized_forces(scene, scene.carriage.supports, anchors, loads, q, q_t, t, ops, lams)

    if user_functions == "python":
        function = user_function
    else:
        function = _symbolic_vector_function(mbs, user_function, "ObjectKinematicTree", "forceUserFunction",
                                             items.tree, n)
    items.keep.append(function)
    mbs.SetObjectParameter(items.tree, "forceUserFunction", function)


def _symbolic_vector_function(mbs, function, item_type: str, name: str, index, size: int):
    """``function`` recorded as an Exudyn symbolic user function whose vector arguments have ``size`` entries."""
    import exudyn
    from exudyn.itemInterface import userFunctionArgsDict

    esym = exudyn.symbolic
    types, _, returned = userFunctionArgsDict[f"{item_type},{name}"][:3]
    names = function.__code__.co_varnames[:len(types)]
    arguments = []
    for kind, argument in zip(types, names):
        if kind == "MainSystem":
            arguments.append(mbs)
        elif kind in ("Real", "Index"):
            arguments.append(esym.Real(argument, 0.0))
        else:
            arguments.append(esym.Vector(argument, [0.0] * size))
    recording = esym.GetRecording()
    esym.SetRecording(True)
    try:
        value = esym.Vector(function(*arguments))
    finally:
        esym.SetRecording(recording)
    symbolic = esym.UserFunction()
    symbolic.SetUserFunctionFromDict(mbs, {"functionName": function.__name__, "argList": arguments,
                                           "argTypeList": list(types), "returnValue": value,
                                           "returnType": returned[0]}, name, index, "None")
    return symbolic
