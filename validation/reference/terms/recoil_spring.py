"""Term of ``[recoil_spring]``: connector ``recoil_spring`` ground -> barrel, ``F = k x_M`` (Eq. 1).

k in N/m; stored energy ``k x_M^2 / 2``; none if k = 0 (DESIGN.md).
"""

from __future__ import annotations

from ..model import BARREL, GROUND
from .spring_damper import LinearSpringDamper

TABLES = ("recoil_spring",)


def build(builder, key: str, table) -> None:
    """A linear spring ground -> barrel of stiffness ``table.stiffness`` (N/m), if it is > 0."""
    if table.stiffness > 0:
        builder.add_connector(LinearSpringDamper("recoil_spring", GROUND, BARREL, stiffness=table.stiffness))
