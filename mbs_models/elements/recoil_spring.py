"""The recoil spring between the ground and the barrel, stiffness k of the paper (Eq. 1).

Table ``[recoil_spring]``: ``stiffness`` (N/m, >= 0; 27500 N/m in the paper).  Force on the barrel
``-k x_M``, on the ground (the support) ``+k x_M``; stored energy ``k x_M^2 / 2``.  It is Exudyn's
built-in linear connector (:class:`~.connector.LinearSpringDamper`, no user function); a zero stiffness adds nothing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from .barrel import BARREL
from .connector import GROUND, Connector, LinearSpringDamper
from .table import Rule, Table


@dataclass(frozen=True)
class RecoilSpring(Table):
    """Recoil spring between ground and barrel, stiffness ``k`` in N/m (Eq. 1).

    Attributes
    ----------
    stiffness: k in N/m (>= 0; 0 = no spring), the linear spring's force ``k x_M`` returning the barrel.
    """

    stiffness: float
    TABLE: ClassVar[str] = "recoil_spring"
    ORDER: ClassVar[int] = 20
    RULES: ClassVar = {"stiffness": Rule(0.0, unit="N/m")}

    def bodies(self, scene, name: str) -> list:
        return []

    def connectors(self, scene, name: str) -> list[Connector]:
        """One linear spring ground -> barrel (none if the stiffness is 0)."""
        if self.stiffness <= 0:
            return []
        return [LinearSpringDamper(self.TABLE, self.TABLE, GROUND, BARREL, stiffness=self.stiffness)]
