"""Assemble a :class:`~mbs_models.scene.Scene` into an Exudyn system, adding only what its elements call for.

The assembly iterates over the scene's elements (:class:`~mbs_models.engine.mechanism.Mechanism`):
each body is a ``NodeGenericODE2`` (1 coordinate) with an ``ObjectMass1D`` and a coordinate marker and
position/velocity/acceleration sensors; each connector an ``ObjectConnectorCoordinateSpringDamper``
between its two markers (Exudyn's linear law, or the element's user function), and each contact a force
sensor.  Connectors between the same two points share one item (:mod:`.folding`: the linear law of their summed
coefficients, or one user function of their summed forces).  For the paper's model (ii)::

    ground --[recoil_spring k + recoil_damper c(v)]-- barrel (NodeGenericODE2 + ObjectMass1D, mass M)
                                        one item: k x + c(v) v, a user function only if c is asymmetric
    ground --[absorber_damper k_r, c_r]-- absorber (mass m)
    absorber --[contact]----------------- barrel   (user function)

An element the scene lacks adds nothing (no absorber: no absorber node, connector or sensor); a
symmetric damper is the built-in linear one; a zero stiffness or damping leaves the connector out.

The :class:`Assembly` owns the Exudyn ``SystemContainer``; call :meth:`Assembly.close` (or use it as
a context manager) so that Exudyn releases the model -- symbolic user functions otherwise keep it alive.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import exudyn
from exudyn.itemInterface import MarkerNodeCoordinate, NodeGenericODE2, NodePointGround, ObjectMass1D, SensorNode, SensorObject

from ..elements.connector import GROUND
from ..scene import Scene
from .folding import add_item, connector_items, update_item
from .mechanism import Mechanism

_OVT = exudyn.OutputVariableType
USER_FUNCTION_BACKENDS = ("symbolic", "python")


@dataclass
class Assembly:
    """An assembled Exudyn system and the indices of what was added.

    Attributes
    ----------
    scene, mechanism: the scene and its bodies and connectors.
    system_container, mbs: the Exudyn SystemContainer and MainSystem.
    backend: ``"symbolic"`` or ``"python"`` user functions.
    nodes: body name -> NodeIndex; ``markers``: body name (and ``"ground"``) -> MarkerIndex.
    connectors: connector name -> ObjectIndex (``recoil_spring``, ``recoil_damper``, ``absorber_damper``,
        ``contact``, ...); absent effects are absent keys; connectors that share an item (:mod:`.folding`) have
        the same index.
    user_function_connectors: names of the connectors driven by a user function (their own, or their share of a
        folded item's).
    loads: load name -> LoadIndex (``breech_force``, ``gravity``): external forces on a body.
    sensors: name -> SensorIndex (``barrel_position`` ... ``absorber_acceleration``, ``contact_force``).
    coordinates: body name -> index of its coordinate in the system's ODE2 coordinates.
    masses: body name -> ObjectIndex of its ``ObjectMass1D``.
    structure: :func:`structure_key` of the system (what :func:`refill` needs to match).
    item_layout: ``(object index, its ODE2 coordinates, has a mass matrix, has an ODE2 LHS, the body whose
        ObjectMass1D it is or None)`` per object with ODE2 coordinates, filled by the first evaluation of the
        initial accelerations (:func:`~mbs_models.engine.driver._initial_accelerations`) and kept by
        :func:`refill` (the structure's).
    simulation_settings: Exudyn ``SimulationSettings`` per ``(SolverSettings, end time, start time)`` solved with
        (:func:`~mbs_models.engine.driver._simulation_settings`), kept by :func:`refill`.
    planar: the carriage's items (:class:`~mbs_models.engine.planar.PlanarItems`) of a scene with a
        ``[carriage]``, else None.
    columns: output name -> (sensor name, column) for outputs read from a sensor of several columns (the
        carriage's tree node holds every coordinate: ``barrel_position`` is one column of ``tree_position``).
    """

    scene: Scene
    mechanism: Mechanism
    system_container: Any
    mbs: Any
    backend: str
    nodes: dict[str, Any] = field(default_factory=dict)
    markers: dict[str, Any] = field(default_factory=dict)
    connectors: dict[str, Any] = field(default_factory=dict)
    user_function_connectors: list[str] = field(default_factory=list)
    loads: dict[str, Any] = field(default_factory=dict)
    sensors: dict[str, Any] = field(default_factory=dict)
    coordinates: dict[str, int] = field(default_factory=dict)
    masses: dict[str, Any] = field(default_factory=dict)
    structure: tuple = ()
    planar: Any = None
    columns: dict[str, tuple[str, int]] = field(default_factory=dict)
    item_layout: list[tuple[Any, list[int], bool, bool, str | None]] = field(default_factory=list)
    simulation_settings: dict[tuple, Any] = field(default_factory=dict)

    def close(self) -> None:
        """Release the Exudyn model (needed for symbolic user functions to be freed)."""
        if self.system_container is not None:
            self.system_container.Reset()
            self.system_container = None
            self.mbs = None
            for item in self.mechanism.connectors + self.mechanism.loads:
                item.__dict__.pop("_user_function", None)

    def __enter__(self) -> "Assembly":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def add_body(mbs, mass: float, initial_velocity: float = 0.0, initial_position: float = 0.0, *,
             with_mass_object: bool = False):
    """Add a 1-D body (m in kg, at ``initial_position`` m, default 0, with ``initial_velocity`` m/s) to ``mbs``:
    (node, coordinate marker), and the ``ObjectMass1D``'s index third if ``with_mass_object``.  The reference
    coordinate is 0: the node's coordinate is the position x."""
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0], initialCoordinates=[initial_position],
                                       initialCoordinates_t=[initial_velocity], numberOfODE2Coordinates=1))
    mass_object = mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=mass))
    marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
    return (node, marker, mass_object) if with_mass_object else (node, marker)


def update_body(mbs, node, mass_object, mass: float, initial_velocity: float, initial_position: float) -> None:
    """Write a body's mass (kg) and initial state (m, m/s) into the node and ``ObjectMass1D`` :func:`add_body` made;
    the system must be assembled again (``mbs.Assemble()``) for the initial state to take effect."""
    mbs.SetObjectParameter(mass_object, "mass", mass)
    mbs.SetNodeParameter(node, "initialCoordinates", [initial_position])
    mbs.SetNodeParameter(node, "initialCoordinates_t", [initial_velocity])


def structure_key(mechanism: Mechanism, user_functions: str, fold: bool = True) -> tuple:
    """What an assembled system is made of, without its numbers: the backend, the bodies (names, in order), the
    connectors (class, name, ends, whether a user function and a force sensor) and the loads (class, name, body,
    user function), element by element.  Two scenes with the same key assemble to the same items; only
    masses, stiffnesses, laws' constants and initial states differ (see :func:`refill`); ``fold``: whether
    connectors on the same ends share an item (:func:`assemble`; the grouping follows from the rest of the key)."""
    return (user_functions, fold, tuple(
        (element.name, type(element.table).__name__,
         tuple(body.name for body in element.bodies),
         tuple((type(c).__qualname__, c.name, c.a, c.b, c.needs_user_function, c.records_force)
               for c in element.connectors),
         tuple((type(load).__qualname__, load.name, load.body, load.needs_user_function) for load in element.loads))
        for element in mechanism.elements))


def assemble(scene: Scene, user_functions: str = "symbolic", mechanism: Mechanism | None = None, *,
             fold: bool = True) -> Assembly:
    """Build the Exudyn system of ``scene``; ``user_functions`` is ``"symbolic"`` or ``"python"``.

    ``fold``: connectors between the same two points share one Exudyn item (:mod:`.folding`); False: one item
    per connector (the same forces to round-off: to compare, and Exudyn's floor in ``scripts/bench.py``)."""
    if user_functions not in USER_FUNCTION_BACKENDS:
        raise ValueError(f"user_functions must be 'symbolic' or 'python', got {user_functions!r}")
    mechanism = Mechanism(scene) if mechanism is None else mechanism
    system_container = exudyn.SystemContainer()
    mbs = system_container.AddSystem()
    assembly = Assembly(scene=scene, mechanism=mechanism, system_container=system_container, mbs=mbs,
                        backend=user_functions)
    ground = mbs.AddNode(NodePointGround())
    assembly.markers[GROUND] = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
    items = connector_items(mechanism.connectors) if fold else [(c,) for c in mechanism.connectors]
    first_of = {members[0].name: members for members in items}
    planar = None
    if scene.carriage is not None:  # the planar model: every body a coordinate of the gun's tree
        from .planar import add_carriage
        planar = assembly.planar = add_carriage(mbs, mechanism, user_functions)
    for element in mechanism.elements:
        for body in element.bodies:
            if planar is not None:
                assembly.nodes[body.name] = planar.node
                assembly.markers[body.name] = mbs.AddMarker(MarkerNodeCoordinate(
                    nodeNumber=planar.node, coordinate=planar.body_coordinate[body.name]))
                continue
            node, marker, mass_object = add_body(mbs, body.mass, body.initial_velocity, body.initial_position,
                                                 with_mass_object=True)
            assembly.nodes[body.name], assembly.markers[body.name] = node, marker
            assembly.masses[body.name] = mass_object
            for quantity, ovt in (("position", _OVT.Coordinates), ("velocity", _OVT.Coordinates_t),
                                  ("acceleration", _OVT.Coordinates_tt)):
                assembly.sensors[f"{body.name}_{quantity}"] = mbs.AddSensor(
                    SensorNode(nodeNumber=node, outputVariableType=ovt, storeInternal=True))
        for connector in element.connectors:
            members = first_of.get(connector.name)
            if members is not None:  # the first of the connectors its item holds (engine/folding.py)
                index = add_item(mbs, members, assembly.markers[connector.a], assembly.markers[connector.b],
                                 user_functions)
                for member in members:
                    assembly.connectors[member.name] = index
            index = assembly.connectors[connector.name]
            if connector.needs_user_function:
                assembly.user_function_connectors.append(connector.name)
            if connector.records_force:
                assembly.sensors[f"{connector.name}_force"] = mbs.AddSensor(
                    SensorObject(objectNumber=index, outputVariableType=_OVT.Force, storeInternal=True))
        if planar is not None:  # a carriage scene: its loads act through the tree's force user function
            continue
        for load in element.loads:
            assembly.loads[load.name] = load.add_items(mbs, assembly.markers[load.body], user_functions)
    if planar is not None:
        _add_planar_sensors(assembly)
    mbs.Assemble()
    data = mbs.systemData
    if planar is not None:
        ltg = list(data.GetNodeLTGODE2(planar.node))
        assembly.coordinates = {name: ltg[k] for name, k in planar.body_coordinate.items()}
    else:
        assembly.coordinates = {name: data.GetNodeLTGODE2(node)[0] for name, node in assembly.nodes.items()}
    assembly.structure = structure_key(mechanism, user_functions, fold)
    _start_contacts(mechanism)
    return assembly


def _add_planar_sensors(assembly: Assembly) -> None:
    """The carriage's sensors: the tree node's coordinates, velocities and accelerations (every body's and the
    carriage's are columns of them, :attr:`Assembly.columns`); the supports' forces are their law at these states
    (:mod:`mbs_models.results.carriage`)."""
    from .planar import CARRIAGE_COORDINATES

    mbs, planar = assembly.mbs, assembly.planar
    for quantity, ovt in (("position", _OVT.Coordinates), ("velocity", _OVT.Coordinates_t),
                          ("acceleration", _OVT.Coordinates_tt)):
        sensor = f"tree_{quantity}"
        assembly.sensors[sensor] = mbs.AddSensor(SensorNode(nodeNumber=planar.node, outputVariableType=ovt,
                                                            storeInternal=True))
        for k, name in enumerate(CARRIAGE_COORDINATES):
            assembly.columns[f"{name}_{quantity}"] = (sensor, k)
        for body, k in planar.body_coordinate.items():
            assembly.columns[f"{body}_{quantity}"] = (sensor, k)


def _start_contacts(mechanism: Mechanism) -> None:
    """Give the contacts that capture their onset rate the state at t = 0."""
    velocities = {body.name: body.initial_velocity for body in mechanism.bodies}
    for contact in mechanism.capturing_contacts:
        contact.start(mechanism.initial_relative(contact), mechanism.relative(contact, velocities))


def refill(assembly: Assembly, scene: Scene, mechanism: Mechanism, key: tuple | None = None) -> Assembly:
    """The system of ``assembly`` made into the one :func:`assemble` builds for ``scene`` (same
    :func:`structure_key`): every body's mass and initial state, and every connector's and load's numbers and user
    function (their ``update_items``), written in place (an item whose connectors have the laws it holds keeps its
    recorded user function: :func:`~mbs_models.engine.folding.update_item`); then ``mbs.Assemble()`` (the initial
    state, as at the first assembly), no pre-step function.  Returns the new :class:`Assembly` (``assembly`` must
    not be used any more).  ValueError if the structures differ (``key``: the scene's :func:`structure_key`, if
    already at hand)."""
    backend = assembly.backend
    if assembly.planar is not None or scene.carriage is not None:
        raise ValueError("a carriage scene is assembled anew for every solve")
    if key is None:
        key = structure_key(mechanism, backend, assembly.structure[1])
    if key != assembly.structure:
        raise ValueError("the scene's structure differs from the assembled system's")
    mbs = assembly.mbs
    for body in mechanism.bodies:
        update_body(mbs, assembly.nodes[body.name], assembly.masses[body.name], body.mass, body.initial_velocity,
                    body.initial_position)
    fold = key[1]
    held = assembly.mechanism.connector  # the connectors the items hold now (the previous point's), by name
    for members in (connector_items(mechanism.connectors) if fold else [(c,) for c in mechanism.connectors]):
        recorded = tuple(held.get(member.name) for member in members)
        update_item(mbs, assembly.connectors[members[0].name], members, backend,
                    None if any(old is None for old in recorded) else recorded)
    for load in mechanism.loads:
        load.update_items(mbs, assembly.loads[load.name], backend)
    mbs.SetPreStepUserFunction(0)
    mbs.Assemble()
    refilled = Assembly(scene=scene, mechanism=mechanism, system_container=assembly.system_container, mbs=mbs,
                        backend=backend, nodes=assembly.nodes, markers=assembly.markers,
                        connectors=assembly.connectors, user_function_connectors=assembly.user_function_connectors,
                        loads=assembly.loads, sensors=assembly.sensors, coordinates=assembly.coordinates,
                        masses=assembly.masses, structure=key, item_layout=assembly.item_layout,
                        simulation_settings=assembly.simulation_settings)
    assembly.system_container = assembly.mbs = None  # the system now belongs to the new Assembly
    _start_contacts(mechanism)
    return refilled
