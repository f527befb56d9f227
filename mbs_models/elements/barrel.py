"""The barrel: the recoiling mass M of the paper (Eq. 1), the body every other element acts on.

Table ``[barrel]``: ``mass`` (kg, > 0) and, unless a ``[firing]`` table gives it, ``initial_velocity``
(m/s).  It adds one body, ``"barrel"``, starting at x = 0 with the scene's initial velocity.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from .connector import Body
from .table import Rule, Table

BARREL = "barrel"


@dataclass(frozen=True)
class Barrel(Table):
    """The recoiling barrel, mass ``M`` of the paper (Eq. 1).

    Attributes
    ----------
    mass: barrel mass M in kg (> 0); 5600 kg in the paper.
    initial_velocity: v0 in m/s; give either this or a :class:`~mbs_models.elements.firing.Firing`.
    """

    mass: float
    initial_velocity: float | None = None
    TABLE: ClassVar[str] = "barrel"
    ORDER: ClassVar[int] = 0
    RULES: ClassVar = {"mass": Rule(0.0, strict=True, unit="kg"), "initial_velocity": Rule(unit="m/s")}

    def bodies(self, scene, name: str) -> list[Body]:
        """The barrel body, at the scene's initial velocity."""
        return [Body(BARREL, self.mass, scene.initial_velocity, element=name)]

    def connectors(self, scene, name: str) -> list:
        return []
