"""Term of ``[firing]``: the shot's momentum sets the barrel moving (Section 2.1 of the paper).

Conservation of momentum: ``v0 = projectile_mass * muzzle_velocity / moving_mass`` (kg, m/s, kg), e.g.
6.86 x 564 / 5600 = 0.6909 m/s.  The table adds no body and no force; the barrel term uses
:func:`recoil_velocity` for its initial velocity.
"""

from __future__ import annotations

TABLES = ("firing",)


def recoil_velocity(firing, moving_mass: float) -> float:
    """``m_p v_p / moving_mass`` (m/s) of a ``[firing]`` table and a recoiling mass (kg)."""
    return firing.projectile_mass * firing.muzzle_velocity / moving_mass


def build(builder, key: str, table) -> None:
    """Nothing to add: the effect is the barrel's initial velocity (:mod:`.barrel`)."""
