"""Assemble a :class:`~mbs_models.scene.Scene` into an Exudyn system, adding only what it calls for.

Items (1-D, positions positive in the recoil direction)::

    ground --[recoil_spring k]------- barrel (NodeGenericODE2 + ObjectMass1D, mass M)
    ground --[recoil_damper c(v)]---- barrel        user function only if c is asymmetric
    mount  --[absorber_spring_damper k_r, c_r]-- absorber (mass m)      only with an absorber
    absorber --[contact Hunt-Crossley]---------- barrel   (user function) only with an absorber

* no ``[absorber]``: no absorber node, no absorber connector, no contact, no contact sensor;
* equal recoil/counter-recoil coefficients: the recoil damper is Exudyn's built-in linear damper;
* zero spring stiffness or zero damping: that connector is left out altogether.

The :class:`Assembly` owns the Exudyn ``SystemContainer``; call :meth:`Assembly.close` (or use it as
a context manager) so that Exudyn releases the model -- symbolic user functions otherwise keep it alive.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import exudyn
from exudyn.itemInterface import (MarkerNodeCoordinate, NodeGenericODE2, NodePointGround, ObjectConnectorCoordinateSpringDamper,
                                  ObjectMass1D, SensorNode, SensorObject)

from . import forces
from .scene import Scene

_OVT = exudyn.OutputVariableType


@dataclass
class Assembly:
    """An assembled Exudyn system and the indices of what was added.

    Attributes
    ----------
    scene: the scene it was built from.
    system_container, mbs: the Exudyn SystemContainer and MainSystem.
    connectors: name -> ObjectIndex of each connector added (``recoil_spring``, ``recoil_damper``,
        ``absorber_spring_damper``, ``contact``); absent effects are absent keys.
    user_function_connectors: names of the connectors driven by a user function.
    sensors: name -> SensorIndex (``barrel_position`` ... ``absorber_acceleration``, ``contact_force``).
    backend: ``"symbolic"`` or ``"python"``.
    """

    scene: Scene
    system_container: Any
    mbs: Any
    backend: str
    connectors: dict[str, Any] = field(default_factory=dict)
    user_function_connectors: list[str] = field(default_factory=list)
    sensors: dict[str, Any] = field(default_factory=dict)
    nodes: dict[str, Any] = field(default_factory=dict)
    _keep_alive: list = field(default_factory=list, repr=False)

    def close(self) -> None:
        """Release the Exudyn model (needed for symbolic user functions to be freed)."""
        if self.system_container is not None:
            self.system_container.Reset()
            self.system_container = None
            self.mbs = None
            self._keep_alive.clear()

    def __enter__(self) -> "Assembly":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _add_point_mass(mbs, mass: float, initial_velocity: float):
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0], initialCoordinates=[0.0],
                                       initialCoordinates_t=[initial_velocity], numberOfODE2Coordinates=1))
    mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=mass))
    marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
    return node, marker


def _add_kinematic_sensors(assembly: Assembly, body: str, node) -> None:
    for quantity, ovt in (("position", _OVT.Coordinates), ("velocity", _OVT.Coordinates_t),
                          ("acceleration", _OVT.Coordinates_tt)):
        assembly.sensors[f"{body}_{quantity}"] = assembly.mbs.AddSensor(
            SensorNode(nodeNumber=node, outputVariableType=ovt, storeInternal=True))


def assemble(scene: Scene, user_functions: str = "symbolic") -> Assembly:
    """Build the Exudyn system of ``scene``; ``user_functions`` is ``"symbolic"`` or ``"python"``."""
    if user_functions not in ("symbolic", "python"):
        raise ValueError(f"user_functions must be 'symbolic' or 'python', got {user_functions!r}")
    system_container = exudyn.SystemContainer()
    mbs = system_container.AddSystem()
    assembly = Assembly(scene=scene, system_container=system_container, mbs=mbs, backend=user_functions)
    ops = forces._symbolic_ops() if user_functions == "symbolic" else forces.PYTHON_OPS

    def add_connector(name: str, markers, stiffness: float = 0.0, damping: float = 0.0, python_function=None):
        index = mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
            markerNumbers=list(markers), stiffness=stiffness, damping=damping,
            visualization={"show": False, "drawSize": -1.0, "color": [-1.0, -1.0, -1.0, -1.0]}))
        if python_function is not None:
            user_function = forces.make_user_function(mbs, python_function, user_functions, index)
            assembly._keep_alive.append(user_function)
            mbs.SetObjectParameter(index, "springForceUserFunction", user_function)
            assembly.user_function_connectors.append(name)
        assembly.connectors[name] = index
        return index

    ground = mbs.AddNode(NodePointGround())
    ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
    barrel_node, barrel_marker = _add_point_mass(mbs, scene.barrel.mass, scene.initial_velocity)
    assembly.nodes["barrel"] = barrel_node
    _add_kinematic_sensors(assembly, "barrel", barrel_node)

    if scene.recoil_spring.stiffness > 0:
        add_connector("recoil_spring", (ground_marker, barrel_marker), stiffness=scene.recoil_spring.stiffness)
    damper = scene.recoil_damper
    if damper.symmetric:
        if damper.recoil > 0:
            add_connector("recoil_damper", (ground_marker, barrel_marker), damping=damper.recoil)
    else:
        add_connector("recoil_damper", (ground_marker, barrel_marker),
                      python_function=forces.recoil_damper_user_function(damper, ops))

    if scene.absorber is not None:
        absorber = scene.absorber
        absorber_node, absorber_marker = _add_point_mass(mbs, absorber.mass, 0.0)
        assembly.nodes["absorber"] = absorber_node
        _add_kinematic_sensors(assembly, "absorber", absorber_node)
        mount_marker = barrel_marker if absorber.mount == "barrel" else ground_marker
        if absorber.stiffness > 0 or absorber.damping > 0:
            add_connector("absorber_spring_damper", (mount_marker, absorber_marker),
                          stiffness=absorber.stiffness, damping=absorber.damping)
        contact = add_connector("contact", (absorber_marker, barrel_marker),
                                python_function=forces.contact_user_function(scene.contact, scene.conventions, ops))
        assembly.sensors["contact_force"] = mbs.AddSensor(
            SensorObject(objectNumber=contact, outputVariableType=_OVT.Force, storeInternal=True))

    mbs.Assemble()
    return assembly
