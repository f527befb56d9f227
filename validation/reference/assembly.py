"""From a scene to the reference's :class:`~validation.reference.model.Model`, by the terms.

The scene is read as data (duck typing, no import of the engine): ``scene.tables()`` lists what it has
as ``(key, table)``; each table is given to the term of its name (the key without an index:
``absorber.1`` -> ``absorber``) in :data:`validation.reference.terms.TERMS`.  A table without a term is an
error: the reference would silently leave an effect out.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

from .model import BARREL, AbsorberRole, Body, Connector, Impulse, Load, Model, ReferenceModelError
from .terms import TERMS


class ModelBuilder:
    """What the terms add while a scene is read: bodies, connectors, absorbers and stops (by name), external
    loads and velocity jumps, the shot times of a burst (None unless a term sets them), and finishers:
    functions of the complete builder, run before the model is made (a preload's initial state needs every
    connector), that may set bodies' initial positions (:attr:`positions`, m)."""

    def __init__(self, scene):
        self.scene = scene
        self.bodies: list[Body] = []
        self.connectors: list[Connector] = []
        self.absorbers: list[AbsorberRole] = []
        self.stops: list[str] = []
        self.loads: list[Load] = []
        self.impulses: list[Impulse] = []
        self.shot_times: tuple[float, ...] | None = None
        self.positions: dict[str, float] = {}
        self.finishers: list[Callable] = []

    def add_body(self, body: Body) -> None:
        self.bodies.append(body)

    def add_connector(self, connector: Connector) -> None:
        self.connectors.append(connector)

    def add_absorber(self, role: AbsorberRole) -> None:
        self.absorbers.append(role)

    def add_stop(self, name: str) -> None:
        self.stops.append(name)

    def add_load(self, load: Load) -> None:
        """An external force L(t) on one body (:class:`~validation.reference.model.Load`)."""
        self.loads.append(load)

    def add_impulse(self, impulse: Impulse) -> None:
        """Velocity jumps of one body at given times (:class:`~validation.reference.model.Impulse`)."""
        self.impulses.append(impulse)

    def set_shot_times(self, times) -> None:
        """The times (s) the shots of a burst fire, from 0 (the per-shot outputs and time events)."""
        self.shot_times = tuple(float(t) for t in times)

    def add_finisher(self, finisher: Callable) -> None:
        """``finisher(builder)`` runs once every table is read, before the model is made."""
        self.finishers.append(finisher)

    def model(self) -> Model:
        """The model: the barrel first, then the other bodies in the order they were added, at the initial
        positions the finishers set (0 for the others)."""
        for finisher in self.finishers:
            finisher(self)
        bodies = [replace(b, initial_position=float(self.positions[b.name])) if b.name in self.positions else b
                  for b in self.bodies]
        bodies = sorted(bodies, key=lambda b: b.name != BARREL)
        return Model(getattr(self.scene, "name", ""), bodies, self.connectors, self.absorbers, self.stops,
                     self.loads, self.impulses, self.shot_times)


def table_name(key: str) -> str:
    """The table's name of a scene key: ``absorber.1`` -> ``absorber``."""
    return key.split(".")[0]


def build_model(scene) -> Model:
    """The reference model of ``scene`` (ReferenceModelError for a table without a reference term)."""
    builder = ModelBuilder(scene)
    for key, table in scene.tables():
        term = TERMS.get(table_name(key))
        if term is None:
            raise ReferenceModelError(f"no reference term for [{table_name(key)}] (known: {', '.join(sorted(TERMS))})")
        term.build(builder, key, table)
    return builder.model()
