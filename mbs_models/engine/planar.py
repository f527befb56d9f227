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

Each support is an ``ObjectConnectorCartesianSpringDamper`` between a ground marker at the origin and a
``MarkerKinematicTreeRigid`` of the carriage link at the support point, whose spring-force user function (its
displacement is the point's position, its velocity the point's velocity) returns ``-(T, N, 0)``: Exudyn applies
``-f`` to the second marker, so the carriage receives ``(T, N)`` with the support law of
:mod:`mbs_models.elements.carriage` (written once over the backend ops, as every law).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..elements.carriage import (AxisBody, StaticState, elevation_of, gravity_of, static_equilibrium,
                                 support_normal_force, support_tangential_force)
from ..elements.ops import ops_for

#: Tree coordinates before the axis bodies: X, Y, phi.
CARRIAGE_COORDINATES = ("carriage_x", "carriage_y", "carriage_pitch")


@dataclass
class PlanarItems:
    """What :func:`add_carriage` added: the tree node and object, each body's coordinate index in the node, each
    support's connector, the rigid markers of the bodies (for loads), the static state and the user functions
    (kept alive as long as the system)."""

    node: Any
    tree: Any
    static: StaticState
    body_coordinate: dict[str, int]
    support_connectors: dict[str, Any] = field(default_factory=dict)
    body_markers: dict[str, Any] = field(default_factory=dict)
    keep: list = field(default_factory=list)


def axis_bodies(mechanism) -> list[AxisBody]:
    """The mechanism's bodies as the planar model sees them (the barrel carries ``barrel_inertia``)."""
    inertia = mechanism.scene.carriage.barrel_inertia
    return [AxisBody(b.name, b.mass, inertia if i == 0 else 0.0, b.initial_position)
            for i, b in enumerate(mechanism.bodies)]


def _rotation_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def add_carriage(mbs, mechanism, user_functions: str) -> PlanarItems:
    """Add the gun's tree, its supports and its loads' items to ``mbs`` (module docstring); the tree starts in the
    static equilibrium (:func:`~mbs_models.elements.carriage.static_equilibrium`) with the axis bodies at their
    initial positions and velocities."""
    import exudyn
    from exudyn.itemInterface import (MarkerBodyPosition, MarkerKinematicTreeRigid, NodeGenericODE2, ObjectGround,
                                      ObjectKinematicTree, ObjectConnectorCartesianSpringDamper)

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
    ground = mbs.AddObject(ObjectGround())
    origin = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))
    for support in carriage.supports:
        point = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=2,
                                                       localPosition=[*support.position, 0.0]))
        index = mbs.AddObject(ObjectConnectorCartesianSpringDamper(markerNumbers=[origin, point],
                                                                   ))
        _set_support_function(mbs, index, support, static.anchors[support.name], user_functions, items.keep)
        items.support_connectors[support.name] = index
    for i, body in enumerate(bodies):
        items.body_markers[body.name] = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=3 + i,
                                                                               localPosition=[0.0, 0.0, 0.0]))
    return items


def _set_support_function(mbs, index, support, anchor: float, user_functions: str, keep: list) -> None:
    """The support's law as the connector's spring-force user function: ``-(T, N, 0)`` from the point's position
    (``displacement``) and velocity."""
    ops = ops_for(user_functions)

    def user_function(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        normal = support_normal_force(support, displacement[1], velocity[1], ops)
        tangential = support_tangential_force(support, normal, displacement[0], velocity[0], anchor, ops,
                                              displacement[1])
        return [-tangential, -normal, 0.0 * normal]

    if user_functions == "python":
        function = user_function
    else:
        from exudyn.advancedUtilities import CreateSymbolicUserFunction
        function = CreateSymbolicUserFunction(mbs, user_function, "springForceUserFunction", index)
    keep.append(function)
    mbs.SetObjectParameter(index, "springForceUserFunction", function)


def add_planar_load(mbs, load, marker, user_functions: str, keep: list):
    """A body's external load (N, + = rearward along the axis) as a ``LoadForceVector`` along the body's local x
    (``bodyFixed``) on its rigid marker: a force on that body alone; returns the LoadIndex."""
    from exudyn.itemInterface import LoadForceVector

    index = mbs.AddLoad(LoadForceVector(markerNumber=marker, loadVector=[load.constant, 0.0, 0.0], bodyFixed=True))
    if load.needs_user_function:
        law = load.user_function_law(ops_for(user_functions))

        def user_function(mbs, t, vector):
            return [law(t), 0.0, 0.0]

        if user_functions == "python":
            function = user_function
        else:
            from exudyn.advancedUtilities import CreateSymbolicUserFunction
            function = CreateSymbolicUserFunction(mbs, user_function, "loadVectorUserFunction", index)
        keep.append(function)
        mbs.SetLoadParameter(index, "loadVectorUserFunction", function)
    return index


def load_generalized_force(scene, q: np.ndarray, coordinate: int, force: float) -> np.ndarray:
    """The generalised force (N, N, N m, N, ...) of ``force`` (N) pulling the axis body of tree coordinate
    ``coordinate`` rearward along the axis, at the tree state ``q``: ``Q = J^T f`` with ``f = -force R(phi) e``
    at the body's CG ``r = (X, Y) + R(phi) a``, ``a = trunnion + (b - x) e``."""
    carriage, theta = scene.carriage, elevation_of(scene)
    phi, x = q[2], q[coordinate]
    e = np.array([math.cos(theta), math.sin(theta)])
    a = np.array(carriage.trunnion) + (carriage.barrel_center_of_mass - x) * e
    c, s = math.cos(phi), math.sin(phi)
    rotation = np.array([[c, -s], [s, c]])
    f = -force * (rotation @ e)
    d_phi = np.array([[-s, -c], [c, -s]]) @ a
    out = np.zeros(len(q))
    out[0], out[1], out[2] = f[0], f[1], float(f @ d_phi)
    out[coordinate] = float(f @ (-(rotation @ e)))
    return out
