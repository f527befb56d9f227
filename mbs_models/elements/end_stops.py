"""End stops: the barrel against the ground at the end of the stroke and at battery, any contact law.

Tables (version 2)::

    [recoil_stop]              # contact while x_M > position: stops the recoil
    position = 0.30            # m, > 0 (the barrel starts at 0)
    law = "hunt-crossley"      # and the law's fields (mbs_models.elements.contact_laws)
    stiffness = 1.0e9
    exponent = 1.5
    damping_factor = 0.5

    [battery_stop]             # contact while x_M < position: the counter-recoil buffer at battery
    position = 0.0             # m, <= 0
    law = "kelvin-voigt"
    stiffness = 5.0e7
    damping = 2.0e5

The recoil stop is a contact ground -> barrel with ``p = x_M - position`` (it pushes the barrel back and
the ground forward: support force ``+F``); the battery stop a contact barrel -> ground with
``p = position - x_M`` (it pushes the barrel forward, the ground back: ``-F``).  Outputs, energies and
impacts are keyed ``recoil_stop`` and ``battery_stop``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from .barrel import BARREL
from .connector import GROUND, Connector
from .contact_laws import LAW_RULES, ContactConnector, LawFields
from .declaration import END_STOP
from .table import Rule, Table


@dataclass(frozen=True, kw_only=True)
class _Stop(LawFields, Table):
    """The fields of a stop: its ``position`` (m) and a contact law with the law's fields: ``stiffness``,
    ``exponent``, ``damping_factor``, ``restitution``, ``damping``, ``minimum_impact_velocity`` as the law
    needs (see :mod:`mbs_models.elements.contact_laws`; default law ``hunt-crossley``).

    Attributes
    ----------
    position: where the stop begins, barrel displacement x_M in m (recoil stop: > 0; battery stop: <= 0).
    law: the contact law of the stop (the laws of :mod:`mbs_models.elements.contact_laws`).
    stiffness: k in N/m^exponent (N/m for kelvin-voigt), > 0.
    exponent: n (> 0) of the power-law laws (not a field of kelvin-voigt).
    damping_factor: hunt-crossley's lambda in s/m (>= 0).
    restitution: e in (0, 1] of the restitution laws (lankarani-nikravesh, flores, gonthier, exact-restitution).
    damping: kelvin-voigt's c in N s/m (>= 0).
    minimum_impact_velocity: restitution laws: impacts slower than this (m/s, > 0) are damped as at this speed.
    """

    position: float
    law: str = "hunt-crossley"
    stiffness: float
    exponent: float | None = None
    damping_factor: float | None = None
    restitution: float | None = None
    damping: float | None = None
    minimum_impact_velocity: float | None = None
    SINCE_VERSION: ClassVar[int] = 2
    ROLES: ClassVar = (END_STOP,)  # its contact is an end stop

    def bodies(self, scene, name: str) -> list:
        return []


@dataclass(frozen=True, kw_only=True)
class RecoilStop(_Stop):
    """The stop at the end of the recoil stroke: a contact ground -> barrel while ``x_M > position``
    (position in m, > 0); fields as :class:`_Stop`."""

    TABLE: ClassVar[str] = "recoil_stop"
    ORDER: ClassVar[int] = 60
    RULES: ClassVar = {"position": Rule(0.0, strict=True, unit="m"), **LAW_RULES}

    def connectors(self, scene, name: str) -> list[Connector]:
        return [ContactConnector(name, name, GROUND, BARREL, self, self.position)]


@dataclass(frozen=True, kw_only=True)
class BatteryStop(_Stop):
    """The counter-recoil buffer at battery: a contact barrel -> ground while ``x_M < position``
    (position in m, <= 0; 0 = the barrel touches it at the start); fields as :class:`_Stop`."""

    TABLE: ClassVar[str] = "battery_stop"
    ORDER: ClassVar[int] = 61
    RULES: ClassVar = {"position": Rule(maximum=0.0, unit="m"), **LAW_RULES}

    def connectors(self, scene, name: str) -> list[Connector]:
        return [ContactConnector(name, name, BARREL, GROUND, self, -self.position)]
