"""The shot that starts the motion: v0 from the conservation of momentum (Section 2.1 of the paper).

Table ``[firing]``: ``projectile_mass`` (kg) and ``muzzle_velocity`` (m/s); the barrel starts at
``v0 = projectile_mass * muzzle_velocity / M`` (6.86 kg x 564 m/s / 5600 kg = 0.6909 m/s; the paper prints
the rounded 0.7 m/s).  The scene's conventions may read it differently (``v0_includes_absorber``: the
momentum accelerates the barrel and every absorber it carries; ``rounded_initial_velocity``).
It adds no body and no force: its effect is the barrel's initial velocity.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from .table import Rule, Table


@dataclass(frozen=True)
class Firing(Table):
    """The projectile whose momentum sets the barrel moving.

    Attributes
    ----------
    projectile_mass: kg (> 0), 6.86 kg in the paper.
    muzzle_velocity: m/s (> 0), 564 m/s in the paper.
    """

    projectile_mass: float
    muzzle_velocity: float
    TABLE: ClassVar[str] = "firing"
    ORDER: ClassVar[int] = 5
    RULES: ClassVar = {"projectile_mass": Rule(0.0, strict=True, unit="kg"),
                       "muzzle_velocity": Rule(0.0, strict=True, unit="m/s")}

    @property
    def momentum(self) -> float:
        """Projectile momentum in kg m/s."""
        return self.projectile_mass * self.muzzle_velocity

    def initial_velocity(self, moving_mass: float) -> float:
        """v0 (m/s) of a recoiling mass ``moving_mass`` (kg): momentum / mass."""
        return self.momentum / moving_mass

    def bodies(self, scene, name: str) -> list:
        return []

    def connectors(self, scene, name: str) -> list:
        return []
