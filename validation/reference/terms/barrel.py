"""Term of ``[barrel]``: the recoiling barrel, body ``barrel`` of mass M (kg), starting at x = 0 with v0.

v0 (m/s), DESIGN.md: ``barrel.initial_velocity``, or from ``[firing]`` the shot's momentum
``I = m_p v_p + m_c v_g`` (with the powder gas's after-effect) over the recoiling mass
(:func:`validation.reference.terms.firing.recoil_velocity`): ``I / M``, or
``I / (M + sum of the masses of the absorbers mounted on the barrel)`` with the ``v0_includes_absorber``
reading; 0 with a breech-force pulse (the barrel starts at rest); ``rounded_initial_velocity`` rounds v0
to 0.1 m/s (the paper's 0.7).
"""

from __future__ import annotations

from ..model import BARREL, Body
from .firing import recoil_velocity

TABLES = ("barrel",)


def initial_velocity(scene) -> float:
    """v0 (m/s) of ``scene`` (module docstring), read from its tables as data."""
    conventions = scene.conventions
    if scene.firing is None:
        v0 = float(scene.barrel.initial_velocity)
    else:
        moving_mass = scene.barrel.mass
        if conventions.v0_includes_absorber:
            for absorber in scene.absorbers:
                if absorber.mount == "barrel":
                    moving_mass += absorber.mass
        v0 = recoil_velocity(scene.firing, moving_mass)
    if conventions.rounded_initial_velocity:
        v0 = round(v0, 1)
    return v0


def build(builder, key: str, table) -> None:
    """The barrel body (mass ``table.mass``, kg) at v0."""
    builder.add_body(Body(BARREL, float(table.mass), initial_velocity(builder.scene)))
