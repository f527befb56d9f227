"""Elements: every physical effect of a recoil mechanism is one module here.

An element module holds, for its effect: the scene table (a :class:`~.table.Table` dataclass and its
validation), the bodies and connectors it adds (:mod:`.connector`: the Exudyn items, the force law over
the backend ops of :mod:`.ops`, stored and dissipated energy, force bounds for the early stop, outputs).
Assembly, post-processing, the early stop and the stability checks iterate over them; none names an
effect.  This package finds the tables by itself: adding an effect is adding a module (and its reference
term in ``validation/reference/terms/`` and its test file); an element defined outside the package is
registered with :func:`register_element` (re-exported as ``mbs_models.register_element``).

The user guide (docs/guide/) and the key reference list the elements and their tables; ``TABLES`` below is the registry.

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
ELEMENT_TABLES: dict[str, type] = {}
#: Callbacks run after :func:`register_element` changed the registry (the scene modules keep views of it).
_LISTENERS: list = []


def _refresh() -> None:
    """Re-sort :data:`TABLES` in ORDER and rebuild :data:`ELEMENT_TABLES`, both in place (importers hold them)."""
    ordered = sorted(TABLES.items(), key=lambda item: (item[1].ORDER, item[0]))
    TABLES.clear()
    TABLES.update(ordered)
    nested = {cls for other in TABLES.values() for cls in (*other.NESTED.values(), *other.NESTED_MANY.values())}
    ELEMENT_TABLES.clear()
    ELEMENT_TABLES.update((name, cls) for name, cls in TABLES.items() if cls not in nested)


_refresh()


def on_register(callback) -> None:
    """Run ``callback()`` after every :func:`register_element` (for modules that keep views of the registry)."""
    _LISTENERS.append(callback)


def _same_definition(old: type, new: type) -> bool:
    """True when ``new`` is ``old`` defined again: the same class name in the same source file (a user module
    imported a second time, under another name or reloaded)."""
    try:
        return old.__qualname__ == new.__qualname__ and inspect.getsourcefile(old) == inspect.getsourcefile(new)
    except TypeError:  # a class without a source file (built in, or made at run time)
        return False


def register_element(table_class: type) -> type:
    """Register an element defined outside this package: its scene table ``table_class`` (a frozen dataclass
    subclass of :class:`Table` with ``TABLE``, ``ORDER``, ``RULES``, ``bodies`` and ``connectors``); returns it
    (usable as a class decorator).

    Afterwards ``[TABLE]`` is a scene table like the shipped ones: in scene files, :class:`~mbs_models.Scene`
    keywords, dotted override keys of sweeps and the optimiser, :func:`~mbs_models.simulate` and the CLI
    (``recoil --plugin MODULE run ...`` imports a module that calls this).  Registering the same class again
    does nothing, and the same definition imported again (its module reloaded, or imported under a second
    name) replaces the first; another class under a name already taken, or a class that is not a Table, is a
    TypeError.
    Its reference term is registered on the reference's side
    (:func:`validation.reference.terms.register_term`).  Processes forked afterwards (the sweep's local
    workers) inherit the registration; a Dask worker must import the module itself.
    """
    import dataclasses

    if not (isinstance(table_class, type) and issubclass(table_class, Table) and dataclasses.is_dataclass(table_class)):
        raise TypeError(f"register_element needs a dataclass subclass of mbs_models.elements.Table, got {table_class!r}")
    name = table_class.TABLE
    if not isinstance(name, str) or not name.isidentifier():
        raise TypeError(f"{table_class.__name__}.TABLE must name its TOML table (an identifier), got {name!r}")
    if TABLES.get(name) is table_class:
        return table_class
    if name in TABLES and _same_definition(TABLES[name], table_class):  # its module imported again (reloaded)
        del TABLES[name]
    if name in TABLES or name in ("conventions", "name", "version", "contact"):
        taken = TABLES.get(name, "a scene key")
        raise TypeError(f"the table name {name!r} of {table_class.__name__} is taken by {taken}")
    for nested in (*table_class.NESTED.values(), *table_class.NESTED_MANY.values()):
        if nested.TABLE and TABLES.get(nested.TABLE, nested) is not nested:
            raise TypeError(f"the nested table name {nested.TABLE!r} of {table_class.__name__} is taken")
    TABLES[name] = table_class
    for nested in (*table_class.NESTED.values(), *table_class.NESTED_MANY.values()):
        if nested.TABLE:
            TABLES[nested.TABLE] = nested
    _refresh()
    for callback in _LISTENERS:
        callback()
    return table_class


__all__ = ["Body", "Connector", "LinearSpringDamper", "GROUND", "Rule", "Table", "TABLES", "ELEMENT_TABLES",
           "register_element"]
