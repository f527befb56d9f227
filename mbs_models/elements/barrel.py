"""The barrel: the recoiling mass M of the paper (Eq. 1), the body every other element acts on.

Table ``[barrel]``: ``mass`` (kg, > 0) and, unless a ``[firing]`` table gives it, ``initial_velocity``
(m/s).  It adds one body, ``"barrel"``, starting at x = 0 with the scene's initial velocity.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from .connector import Body
from .table import Rule, Table, check_derived

BARREL = "barrel"


def free_recoil_speed(scene) -> float:
    """``shots |v0|`` (m/s): the speed the shots of the scene give the barrel free of any force -- its recoil
    velocity ``v0 = I / M`` (``barrel.initial_velocity``; a pulse's ``impulse / M``) once per shot of a ``[burst]``.
    The paper's readings of v0 (rounded, or shared with an absorber) change it by less than a shot's own."""
    firing = getattr(scene, "firing", None)
    velocity = scene.barrel.initial_velocity if firing is None else firing.shot_momentum / scene.barrel.mass
    burst = getattr(scene, "burst", None)
    return abs(velocity) * (burst.shots if burst is not None else 1)


def shot_keys(scene) -> dict[str, float]:
    """The keys the barrel's recoil velocity v0 depends on, with their values (for errors naming them):
    ``barrel.mass`` and ``barrel.initial_velocity``, or the firing's (:meth:`Firing.shot_keys`)."""
    keys = {"barrel.mass": scene.barrel.mass}
    firing = getattr(scene, "firing", None)
    if firing is None:
        keys["barrel.initial_velocity"] = scene.barrel.initial_velocity
    else:
        keys.update(firing.shot_keys())
    return keys


def free_recoil_energy(scene) -> float:
    """``M (shots v0)^2 / 2`` (J): the kinetic energy of the barrel at its :func:`free_recoil_speed`."""
    speed = free_recoil_speed(scene)
    return 0.5 * scene.barrel.mass * speed * speed


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

    def check_in_scene(self, scene, key: str) -> None:
        """The shot's recoil velocity ``v0 = I / M`` (or ``initial_velocity``; the pulse's impulse / M) must be
        finite (and not 0 when a firing momentum gives it), and the largest kinetic energy the shots give the
        barrel, ``M (shots v0)^2 / 2``, and ``(shots v0)^2`` finite: a magnitude beyond double precision is bad
        input (DESIGN.md, "Bad input beyond the ranges")."""
        keys = shot_keys(scene)
        speed = free_recoil_speed(scene)
        if scene.firing is not None:
            check_derived(keys, "the recoil velocity v0 = I / M", scene.firing.shot_momentum / self.mass, "m/s",
                          positive=True)
        check_derived(keys, "the square of the barrel's largest free-recoil speed (shots v0)^2", speed * speed, "m^2/s^2")
        check_derived(keys, "the barrel's largest kinetic energy M (shots v0)^2 / 2", 0.5 * self.mass * speed * speed, "J")

    def bodies(self, scene, name: str) -> list[Body]:
        """The barrel body, at the scene's initial velocity."""
        return [Body(BARREL, self.mass, scene.initial_velocity, element=name)]

    def connectors(self, scene, name: str) -> list:
        return []
