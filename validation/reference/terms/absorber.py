"""Term of ``[[absorber]]``: an absorber body, its actuator and its contact with wall A of the barrel.

DESIGN.md: body ``A`` (mass m, kg, at rest at x = 0); actuator ``A_damper`` mount -> ``A``,
``F = k_r d + c_r d'`` (:mod:`.spring_damper`; none if k_r = c_r = 0), the mount being the barrel (the
paper's model (i)) or the ground (model (ii)); contact ``A_contact`` ``A`` -> barrel with
``p = (x_M - x_m) - gap`` and the table's law (:mod:`.contact_laws`).  With one absorber the
version-1 names are kept: body ``absorber`` (unless named), connectors ``absorber_damper``, ``contact``.

The paper's readings (``scene.conventions``) concern these contacts: ``literal_gap_sign`` (offset
``-gap``: an initial interference), ``literal_lambda_sign`` (hunt-crossley ``1 - lambda p'``),
``compression_only`` (hunt-crossley, one absorber: force only while ``p' > 0``).
"""

from __future__ import annotations

from ..model import BARREL, GROUND, AbsorberRole, Body, ReferenceModelError
from .contact_laws import ContactConnector, Law
from .spring_damper import LinearSpringDamper

TABLES = ("absorber",)
MOUNTS = {"barrel": BARREL, "ground": GROUND}


def connector_names(name: str, several: bool) -> tuple[str, str]:
    """(actuator, contact) names of absorber ``name``: ``absorber_damper``, ``contact`` for a lone one."""
    return (f"{name}_damper", f"{name}_contact") if several else ("absorber_damper", "contact")


def build(builder, key: str, table) -> None:
    """Body, actuator and contact of the absorber at ``key`` (``absorber`` or ``absorber.<i>``)."""
    scene = builder.scene
    names = scene.absorber_names()
    index = 0 if key == "absorber" else int(key.split(".")[1])
    name = names[index]
    if table.mount not in MOUNTS:
        raise ReferenceModelError(f"{key}.mount: unknown mount {table.mount!r}; known: {', '.join(MOUNTS)}")
    actuator, contact = connector_names(name, len(names) > 1)
    builder.add_body(Body(name, float(table.mass)))
    if table.stiffness > 0 or table.damping > 0:
        builder.add_connector(LinearSpringDamper(actuator, MOUNTS[table.mount], name, table.stiffness, table.damping))
    else:
        actuator = None
    conventions = scene.conventions
    gap = float(table.contact.gap)
    law = Law.from_table(table.contact, literal_lambda_sign=conventions.literal_lambda_sign)
    builder.add_connector(ContactConnector(contact, name, BARREL, -gap if conventions.literal_gap_sign else gap, law,
                                           compression_only=conventions.compression_only))
    builder.add_absorber(AbsorberRole(name, name, actuator, contact))
