"""Term of ``[carriage]``: nothing on the recoil axis -- the carriage and its supports are the planar model's.

DESIGN.md, "The recoil axis on a carriage".  The axis model (the bodies and connectors of every other term) is
the same with or without a carriage (but for the cradle's gravity along the axis, which the planar model
replaces by gravity on every body); :mod:`validation.reference.planar` reads ``scene.carriage`` itself and
moves that axis with the carriage.
"""

from __future__ import annotations

TABLES = ("carriage",)


def build(builder, key: str, table) -> None:
    """Nothing: the planar model (:mod:`validation.reference.planar`) reads the table."""
