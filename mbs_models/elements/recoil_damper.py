"""The asymmetric recoil damper between the ground and the barrel, Eqs. (2)-(3) of the paper.

Table ``[recoil_damper]``: ``recoil`` (c while the barrel moves in recoil, velocity > 0; 6239 N s/m)
and ``counter_recoil`` (c while it returns; 14050 N s/m), both N s/m, >= 0.  Force ``F = c(v) v`` on the
ground side (the barrel feels ``-F``), dissipated power ``c(v) v^2``.  Equal coefficients are Exudyn's
built-in linear damper; different ones a user function (symbolic by default); both 0 add nothing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from .barrel import BARREL
from .connector import GROUND, Connector
from .ops import NUMPY_OPS, PYTHON_OPS, Ops
from .table import Rule, Table


def recoil_damper_force(velocity, damper: "RecoilDamper", ops: Ops = PYTHON_OPS):
    """Asymmetric damper force in N (Eqs. 2-3): ``c(v) * v``, positive opposes positive velocity."""
    return ops.choose(velocity > 0, damper.recoil, damper.counter_recoil) * velocity


@dataclass(frozen=True)
class RecoilDamper(Table):
    """Asymmetric recoil damper ``c`` of Eqs. (2)-(3), in N s/m.

    Attributes
    ----------
    recoil: c while the barrel moves in recoil (barrel velocity > 0), 6239 N s/m in the paper.
    counter_recoil: c while the barrel returns (velocity < 0), 14050 N s/m in the paper.
    """

    recoil: float
    counter_recoil: float
    TABLE: ClassVar[str] = "recoil_damper"
    ORDER: ClassVar[int] = 30
    RULES: ClassVar = {"recoil": Rule(0.0, unit="N s/m"), "counter_recoil": Rule(0.0, unit="N s/m")}

    @property
    def symmetric(self) -> bool:
        """True when both coefficients are equal: a plain linear damper suffices."""
        return self.recoil == self.counter_recoil

    def bodies(self, scene, name: str) -> list:
        return []

    def connectors(self, scene, name: str) -> list[Connector]:
        """One damper ground -> barrel (none if both coefficients are 0)."""
        if self.recoil <= 0 and self.counter_recoil <= 0:
            return []
        return [RecoilDamperConnector(self)]


class RecoilDamperConnector(Connector):
    """The damper as a connector ground -> barrel (d = x_M, d' = v_M): built-in when symmetric."""

    def __init__(self, damper: RecoilDamper):
        super().__init__(RecoilDamper.TABLE, RecoilDamper.TABLE, GROUND, BARREL)
        self.damper = damper
        self.needs_user_function = not damper.symmetric

    #: ``c(v) v`` with c >= 0 is non-decreasing in v and independent of d
    monotone = True
    #: ``F(d, 0) = 0``: a pure damper
    stores_energy = False

    def builtin_coefficients(self) -> tuple[float, float]:
        """Exudyn's built-in linear damper ``(0, c)`` when symmetric; a user function otherwise."""
        return 0.0, (self.damper.recoil if self.damper.symmetric else 0.0)

    def law(self, d, rate, ops: Ops):
        return recoil_damper_force(rate, self.damper, ops)

    def dissipated_energy(self, quadrature, d_nodes, rate_nodes, times_nodes, stored):
        """``c(v) v^2`` integrated (J)."""
        return quadrature(recoil_damper_force(rate_nodes, self.damper, NUMPY_OPS) * rate_nodes)

    def force_bound(self, d_bound: float, rate_bound: float, energy: float) -> float:
        return max(self.damper.recoil, self.damper.counter_recoil) * rate_bound

    @property
    def linear_damping(self) -> float:
        """The larger coefficient (N s/m): what the linearised mechanism uses."""
        return max(self.damper.recoil, self.damper.counter_recoil)

    def always_acting_fields(self) -> tuple[str | None, str | None]:
        """No stiffness; the larger coefficient's field (:attr:`linear_damping`): one of the two acts in every state."""
        return None, ("recoil" if self.damper.recoil >= self.damper.counter_recoil else "counter_recoil")


def add_recoil_damper(mbs, marker_ground, marker_barrel, damper: RecoilDamper,
                      user_functions: str = "symbolic") -> RecoilDamperConnector:
    """Add the asymmetric recoil damper between two coordinate markers of your own Exudyn system.

    The force ``c(v) v`` with ``v`` the rate of ``x_barrel - x_ground`` (Eqs. 2-3); a symmetric damper is
    Exudyn's built-in linear damper, an asymmetric one a user function (``"symbolic"`` or ``"python"``).
    Returns the connector (``.index`` is the Exudyn item; keep it as long as ``mbs``).
    """
    connector = RecoilDamperConnector(damper)
    connector.add_items(mbs, marker_ground, marker_barrel, user_functions)
    return connector
