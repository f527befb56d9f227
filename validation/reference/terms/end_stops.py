"""Terms of ``[recoil_stop]`` and ``[battery_stop]``: the barrel against the ground, any contact law.

DESIGN.md: the recoil stop is a contact ground -> barrel with ``p = x_M - position`` (it pushes the
barrel back, the ground forward: support force ``+F``); the battery stop a contact barrel -> ground with
``p = position - x_M`` (``d = -x_M``, offset ``-position``: support force ``-F``).  Laws and their
fields as every contact (:mod:`.contact_laws`); the paper's readings do not apply to them.
"""

from __future__ import annotations

from ..model import BARREL, GROUND
from .contact_laws import ContactConnector, Law

TABLES = ("recoil_stop", "battery_stop")


def build(builder, key: str, table) -> None:
    """The stop's contact, named like its table."""
    position, law = float(table.position), Law.from_table(table)
    if key == "recoil_stop":
        builder.add_connector(ContactConnector(key, GROUND, BARREL, position, law))
    else:
        builder.add_connector(ContactConnector(key, BARREL, GROUND, -position, law))
    builder.add_stop(key)
