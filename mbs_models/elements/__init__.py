"""Elements: every physical effect of a recoil mechanism is one module here.

An element module holds, for its effect: the scene table (a :class:`~.table.Table` dataclass and its
validation), the bodies and connectors it adds (:mod:`.connector`: the Exudyn items, the force law over
the backend ops of :mod:`.ops`, stored and dissipated energy, force bounds for the early stop, outputs).
Assembly, post-processing, the early stop and the stability checks iterate over them; none names an
effect.  This package finds the tables by itself: adding an effect is adding a module (and its reference
term in ``validation/reference/terms/`` and its test file).

The README lists the elements and their tables; ``TABLES`` below is the registry.

Importing this package loads neither Exudyn nor the engine.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil

from .connector import GROUND, Body, Connector, LinearSpringDamper
from .table import Rule, Table

_INFRASTRUCTURE = {"connector", "ops", "table"}


def _discover() -> dict[str, type]:
    """Every Table subclass defined in this package's element modules, by TOML table name, in ORDER."""
    found: dict[str, type] = {}
    for info in pkgutil.iter_modules(__path__):
        if info.name in _INFRASTRUCTURE or info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        for _, cls in inspect.getmembers(module, inspect.isclass):
            if issubclass(cls, Table) and cls.__module__ == module.__name__ and cls.TABLE:
                if cls.TABLE in found and found[cls.TABLE] is not cls:
                    raise RuntimeError(f"two tables named {cls.TABLE!r}: {found[cls.TABLE]} and {cls}")
                found[cls.TABLE] = cls
    return dict(sorted(found.items(), key=lambda item: (item[1].ORDER, item[0])))


#: Every scene table, by TOML name, in the scene's element order.  Nested tables (the absorber's
#: ``contact``) are listed too; the scene holds only the top-level ones (:data:`ELEMENT_TABLES`).
TABLES: dict[str, type] = _discover()
#: The tables that are elements of a scene (not nested in another table).
ELEMENT_TABLES: dict[str, type] = {name: cls for name, cls in TABLES.items()
                                   if not any(cls in other.NESTED.values() for other in TABLES.values())}

__all__ = ["Body", "Connector", "LinearSpringDamper", "GROUND", "Rule", "Table", "TABLES", "ELEMENT_TABLES"]
