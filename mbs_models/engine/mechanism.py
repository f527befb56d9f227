"""The scene as bodies and connectors: what assembly, post-processing, the early stop and the checks iterate over.

:class:`Mechanism` asks every element of a scene (in the scene's order) for its bodies and connectors
(:mod:`mbs_models.elements`) and offers the few generic views the engine needs: body indices, the
contacts, relative coordinates of a connector from body values, the support force.  It needs no
Exudyn; a new one is built for every solve (contact connectors carry the onset capture of one solve).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..elements.barrel import BARREL
from ..elements.connector import GROUND, Body, Connector, Load
from ..elements.declaration import ABSORBER, END_STOP
from ..scene import Scene


@dataclass
class ElementParts:
    """One element of the scene: its name, table, and the bodies and connectors it adds."""

    name: str
    table: object
    bodies: list[Body] = field(default_factory=list)
    connectors: list[Connector] = field(default_factory=list)
    loads: list[Load] = field(default_factory=list)
    impulses: list[tuple[float, str, float]] = field(default_factory=list)


class Mechanism:
    """Bodies and connectors of one scene, in assembly order (the barrel first).

    Attributes
    ----------
    scene: the scene.
    elements: :class:`ElementParts` per element, in the scene's order.
    bodies: every body (the barrel first); ``body_index[name]`` its position.
    connectors: every connector, in element order; ``connector[name]`` by name.
    loads: every external load (:class:`~mbs_models.elements.connector.Load`), in element order.
    impulses: ``(time s, body, velocity jump m/s)`` of every instantaneous shot after t = 0, in time order.
    """

    def __init__(self, scene: Scene):
        self.scene = scene
        self.elements: list[ElementParts] = []
        for name, table in scene.elements():
            loads = table.loads(scene, name) if hasattr(table, "loads") else []
            impulses = table.impulses(scene, name) if hasattr(table, "impulses") else []
            self.elements.append(ElementParts(name, table, table.bodies(scene, name), table.connectors(scene, name),
                                              loads, impulses))
        self.bodies: list[Body] = [b for e in self.elements for b in e.bodies]
        self.connectors: list[Connector] = [c for e in self.elements for c in e.connectors]
        self.loads: list[Load] = [load for e in self.elements for load in e.loads]
        self.impulses: list[tuple[float, str, float]] = sorted(i for e in self.elements for i in e.impulses)
        self.impulse_element = {(t, body): e.name for e in self.elements for t, body, _ in e.impulses}
        self._place_bodies()
        self.body_index = {body.name: i for i, body in enumerate(self.bodies)}
        self.connector = {c.name: c for c in self.connectors}
        if not self.bodies or self.bodies[0].name != BARREL:
            raise ValueError("the barrel must be the first body")

    def _place_bodies(self) -> None:
        """Give the bodies the initial positions the elements impose (a preload holding the barrel in battery:
        :meth:`~mbs_models.elements.table.Table.initial_positions`); without any, every body stays at x = 0."""
        positions: dict[str, float] = {}
        for element in self.elements:
            positions.update(element.table.initial_positions(self.scene, element.name, self.bodies, self.connectors))
        if not positions:
            return
        for element in self.elements:
            element.bodies = [replace(b, initial_position=float(positions[b.name])) if b.name in positions else b
                              for b in element.bodies]
        self.bodies = [b for e in self.elements for b in e.bodies]

    # ------------------------------------------------------------------ views
    @property
    def contacts(self) -> list[Connector]:
        """Every contact connector (absorbers' contacts and stops)."""
        return [c for c in self.connectors if c.is_contact]

    def _of_role(self, role: str) -> set[str]:
        """The names of the elements that declare ``role`` (:mod:`~mbs_models.elements.declaration`)."""
        return {e.name for e in self.elements if role in getattr(e.table, "ROLES", ())}

    @property
    def absorber_contacts(self) -> list[Connector]:
        """The contacts of the elements whose role is an absorber (wall A against it): the version-1 contact
        metrics."""
        absorbers = self._of_role(ABSORBER)
        return [c for c in self.contacts if c.element in absorbers]

    @property
    def stop_contacts(self) -> list[Connector]:
        """The contacts of the elements whose role is an end stop."""
        stops = self._of_role(END_STOP)
        return [c for c in self.contacts if c.element in stops]

    @property
    def absorber_bodies(self) -> list[Body]:
        """The bodies of the elements whose role is an absorber."""
        absorbers = self._of_role(ABSORBER)
        return [b for b in self.bodies if b.element in absorbers]

    @property
    def capturing_contacts(self) -> list[Connector]:
        """Contacts whose law needs the onset rate v- (restitution laws)."""
        return [c for c in self.contacts if getattr(c, "capture", None) is not None]

    @property
    def last_input_time(self) -> float:
        """Time (s) after which no load or impulse adds energy: 0 for the paper's scenes, inf under a
        constant load (gravity); energy bounds hold only after it."""
        if getattr(self.scene, "carriage", None) is not None:  # gravity pulls every body of the planar model
            return math.inf
        last = 0.0
        for load in self.loads:
            last = max(last, load.last_input_time)
        for t, _, _ in self.impulses:
            last = max(last, t)
        return last

    @property
    def breakpoints(self) -> list[float]:
        """Times (s) where the solve is split: impulses and the jumps and kinks of loads, in (0, inf), sorted."""
        times = {t for t, _, _ in self.impulses}
        for load in self.loads:
            times.update(load.breakpoints)
        return sorted(t for t in times if t > 0.0)

    @property
    def sensor_count(self) -> int:
        """Sensors the assembled system stores every step: position, velocity and acceleration of every body, and
        the force of every connector that records it (:func:`~mbs_models.engine.assembly.assemble`)."""
        return 3 * len(self.bodies) + sum(1 for c in self.connectors if c.records_force)

    @property
    def masses(self) -> np.ndarray:
        """Body masses (kg) in body order."""
        return np.array([b.mass for b in self.bodies])

    def initial_velocities(self) -> list[float]:
        """Body velocities (m/s) at t = 0, in body order."""
        return [b.initial_velocity for b in self.bodies]

    # ------------------------------------------------------------------ connector kinematics
    @staticmethod
    def relative(connector: Connector, values: dict):
        """``value_b - value_a`` of a connector from per-body values (the ground's are 0): d or d'."""
        if connector.a == GROUND:
            return values[connector.b]
        if connector.b == GROUND:
            return -values[connector.a]
        return values[connector.b] - values[connector.a]

    def relative_at(self, connector: Connector, vector) -> float:
        """``d`` (or ``d'``) of a connector from a vector of body values in body order (plain floats)."""
        a = 0.0 if connector.a == GROUND else vector[self.body_index[connector.a]]
        b = 0.0 if connector.b == GROUND else vector[self.body_index[connector.b]]
        return b - a

    def direction(self, connector: Connector) -> np.ndarray:
        """The vector c with ``d = c . x`` (x: body positions in body order)."""
        c = np.zeros(len(self.bodies))
        if connector.b != GROUND:
            c[self.body_index[connector.b]] += 1.0
        if connector.a != GROUND:
            c[self.body_index[connector.a]] -= 1.0
        return c

    def initial_positions(self) -> list[float]:
        """Body positions (m) at t = 0, in body order."""
        return [b.initial_position for b in self.bodies]

    def initial_relative(self, connector: Connector) -> float:
        """``d`` (m) of a connector at t = 0."""
        return self.relative_at(connector, self.initial_positions())

    def initial_stored_energy(self) -> float:
        """Stored energy (J) at t = 0, at the initial positions: a contact's initial interference, a preload."""
        return self._initial_stored_energies()[0]

    def _initial_stored_energies(self) -> tuple[float, float]:
        """``(sum U_c, sum |U_c|)`` (J) over the connectors storing energy, at the initial positions."""
        signed = magnitude = 0.0
        for connector in self.connectors:
            if connector.stores_energy:
                energy = float(connector.stored_energy(self.initial_relative(connector)))
                signed += energy
                magnitude += abs(energy)
        return signed, magnitude

    def initial_energy(self) -> float:
        """Mechanical energy at t = 0 in J: kinetic + stored (an initial interference, a preload)."""
        return self.initial_energy_and_scale()[0]

    def energy_scale(self) -> float:
        """The scale (J) of the energy-balance errors: the initial kinetic energy plus the magnitude of every
        initial stored energy.  It is :meth:`initial_energy` unless a potential is negative at t = 0 (a gas
        spring expanded beyond battery by its preload), where the initial energy may be ~0 while the
        stored energies are not."""
        return self.initial_energy_and_scale()[1]

    def initial_energy_and_scale(self) -> tuple[float, float]:
        """``(initial_energy(), energy_scale())`` in J, from one evaluation of the initial stored energies."""
        kinetic = self.scene.initial_kinetic_energy
        signed, magnitude = self._initial_stored_energies()
        return kinetic + signed, kinetic + magnitude
