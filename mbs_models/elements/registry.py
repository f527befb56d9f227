"""The element registry: every scene table by its TOML name, loaded on first use.

A shipped element module is imported when one of its tables is first needed (a scene that has it, a file that
names it, a class looked up by name), not when the package is imported: a run of the paper's models never pays
for the carriage's or the brake's dataclasses.  To know the tables without importing their modules, the registry
reads :data:`~mbs_models.elements._manifest.SHIPPED` (each table's module, class name, ``ORDER``, ``MANY`` and
whether it is an element of a scene or nested in another table), which ``python scripts/element_manifest.py
--write`` generates from the modules themselves (:func:`discover`, :func:`manifest_source`).  The manifest is only a fast path, never a second truth:

* a module of the package that the manifest does not list is imported at once and its tables registered (a new
  element works before the manifest is regenerated; only its import is not deferred);
* when a listed module is imported, every table it defines is checked against its manifest entry, and a
  difference is a RuntimeError naming the table and the command that regenerates the manifest;
* ``tests/elements/test_registry.py`` checks that the manifest is what the modules define.

:data:`TABLES` and :data:`ELEMENT_TABLES` are read-only mappings (name -> class).  Iterating over their names,
``in``, :meth:`Tables.many` and :meth:`Tables.order` import nothing; ``tables[name]`` imports that table's module;
``.values()`` and ``.items()`` import every module.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import os
from collections.abc import Mapping
from typing import Iterator

from .table import Table

PACKAGE = __name__.rpartition(".")[0]
#: Modules of the package that define no element table (the infrastructure of every element).
INFRASTRUCTURE = frozenset({"connector", "declaration", "ops", "table", "registry"})
#: The names a table may not take: the scene's own keys.
SCENE_KEYS = ("conventions", "name", "version", "contact")
REGENERATE = "python scripts/element_manifest.py --write"


class _Entry:
    """One table: where it is defined (``module``, ``class_name``), what the scene needs to know of it without
    importing it (``order``, ``many``, ``element``), and the class once loaded (``cls``)."""

    __slots__ = ("name", "module", "class_name", "order", "many", "element", "cls")

    def __init__(self, name: str, module: str, class_name: str, order: int, many: bool, element: bool,
                 cls: type | None = None):
        self.name, self.module, self.class_name = name, module, class_name
        self.order, self.many, self.element, self.cls = order, many, element, cls

    @classmethod
    def of(cls, table_class: type, element: bool) -> "_Entry":
        return cls(table_class.TABLE, table_class.__module__, table_class.__name__, table_class.ORDER,
                   bool(table_class.MANY), element, table_class)

    def declared(self) -> tuple:
        """What the manifest records of this table."""
        return self.module.rpartition(".")[2], self.class_name, self.order, self.many, self.element


class Tables(Mapping):
    """Scene tables by TOML name, in the scene's element order (``ORDER``, then name); see the module docstring
    for what imports an element module."""

    def __init__(self, entries: dict[str, _Entry]):
        self._entries = entries

    def __getitem__(self, name: str) -> type:
        entry = self._entries[name]
        return entry.cls if entry.cls is not None else _load(entry)

    def __iter__(self) -> Iterator[str]:
        return iter(self._entries)

    def __len__(self) -> int:
        return len(self._entries)

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def many(self, name: str) -> bool:
        """True when ``name`` is an array of tables (the scene's attribute is ``name + "s"``, a tuple)."""
        return self._entries[name].many

    def order(self, name: str) -> int:
        """The table's position in the scene's element order (its ``ORDER``)."""
        return self._entries[name].order

    def class_name(self, name: str) -> str:
        """The name of the table's class (``Recuperator``), for messages about a table not yet imported."""
        return self._entries[name].class_name

    def by_class_name(self) -> "Mapping[str, type]":
        """The tables now registered, by class name (``Barrel``, ``Contact``): a read-only mapping that imports
        a module when one of its classes is looked up."""
        return _ByClassName({entry.class_name: name for name, entry in self._entries.items()}, self)

    def __repr__(self) -> str:
        return f"Tables({list(self._entries)})"


class _ByClassName(Mapping):
    def __init__(self, names: dict[str, str], tables: Tables):
        self._names, self._tables = names, tables

    def __getitem__(self, class_name: str) -> type:
        return self._tables[self._names[class_name]]

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)

    def __contains__(self, class_name: object) -> bool:
        return class_name in self._names


_ENTRIES: dict[str, _Entry] = {}
_ELEMENT_ENTRIES: dict[str, _Entry] = {}
#: Every scene table, by TOML name, in the scene's element order.  Nested tables (the absorber's ``contact``) are
#: listed too; the scene holds only the top-level ones (:data:`ELEMENT_TABLES`).
TABLES = Tables(_ENTRIES)
#: The tables that are elements of a scene (not nested in another table).
ELEMENT_TABLES = Tables(_ELEMENT_ENTRIES)
#: Callbacks run after :func:`register_element` changed the registry (the scene modules keep views of it).
_LISTENERS: list = []


def _module_tables(module) -> list[type]:
    """The Table subclasses ``module`` defines with a TOML name."""
    return [cls for _, cls in inspect.getmembers(module, inspect.isclass)
            if issubclass(cls, Table) and cls.__module__ == module.__name__ and cls.TABLE]


def _nested_of(classes) -> set[type]:
    return {nested for cls in classes for nested in (*cls.NESTED.values(), *cls.NESTED_MANY.values())}


def _load(entry: _Entry) -> type:
    """Import ``entry``'s module and check each table it defines against its manifest entry."""
    module = importlib.import_module(entry.module)
    defined = _module_tables(module)
    nested = _nested_of(defined)
    for cls in defined:
        listed = _ENTRIES.get(cls.TABLE)
        if listed is None or listed.cls is not None and listed.cls is not cls:
            raise RuntimeError(f"{module.__name__} defines the table {cls.TABLE!r}, which the element manifest "
                               f"(mbs_models/elements/_manifest.py) does not list: regenerate it with {REGENERATE}")
        found = _Entry.of(cls, listed.element).declared()
        if found != listed.declared() or (cls in nested and listed.element):
            raise RuntimeError(f"the element manifest is out of date for the table {cls.TABLE!r}: it records "
                               f"{listed.declared()}, {module.__name__} defines {found}: regenerate it with "
                               f"{REGENERATE}")
        listed.cls = cls
    if entry.cls is None:
        raise RuntimeError(f"{module.__name__} no longer defines the table {entry.name!r} (class "
                           f"{entry.class_name}) that the element manifest lists: regenerate it with {REGENERATE}")
    return entry.cls


def _package_modules() -> list[str]:
    """The element modules of the package (every ``.py`` file but the infrastructure and private ones)."""
    directory = os.path.dirname(__file__)
    names = [name[:-3] for name in os.listdir(directory) if name.endswith(".py")]
    return sorted(name for name in names if name not in INFRASTRUCTURE and not name.startswith("_"))


def discover() -> dict[str, tuple]:
    """Import every element module of the package and return what the manifest should record: table name ->
    ``(module, class name, ORDER, MANY, element)``, in the scene's element order (the modules are
    :func:`_package_modules`)."""
    classes: dict[str, type] = {}
    for name in _package_modules():
        for cls in _module_tables(importlib.import_module(f"{PACKAGE}.{name}")):
            if cls.TABLE in classes and classes[cls.TABLE] is not cls:
                raise RuntimeError(f"two tables named {cls.TABLE!r}: {classes[cls.TABLE]} and {cls}")
            classes[cls.TABLE] = cls
    nested = _nested_of(classes.values())
    ordered = sorted(classes.values(), key=lambda cls: (cls.ORDER, cls.TABLE))
    return {cls.TABLE: _Entry.of(cls, cls not in nested).declared() for cls in ordered}


def manifest_source(declared: dict[str, tuple], modules: list[str]) -> str:
    """The text of ``_manifest.py`` recording ``declared`` (from :func:`discover`) and the element ``modules``
    (:func:`_package_modules`: those defining no table too, so that the registry does not import them)."""
    lines = ['"""The shipped element tables, for the registry to defer importing their modules (mbs_models/elements/',
             'registry.py).  Generated from the modules: do not edit; regenerate with', f"``{REGENERATE}``.", '"""',
             "", "#: table name -> (module, class name, ORDER, MANY, element: False for a table nested in another)",
             "SHIPPED = {"]
    lines += [f"    {name!r}: {declared[name]!r}," for name in declared]
    lines += ["}", "#: every element module of the package when the manifest was written", "MODULES = ("]
    lines += [f"    {name!r}," for name in modules]
    return "\n".join(lines + [")", ""])


def _refresh() -> None:
    """Re-sort the tables in the scene's element order and rebuild :data:`ELEMENT_TABLES`, in place."""
    ordered = sorted(_ENTRIES.values(), key=lambda entry: (entry.order, entry.name))
    _ENTRIES.clear()
    _ENTRIES.update((entry.name, entry) for entry in ordered)
    _ELEMENT_ENTRIES.clear()
    _ELEMENT_ENTRIES.update((entry.name, entry) for entry in ordered if entry.element)


def _start() -> None:
    """Fill the registry from the manifest, then import at once every element module it does not list."""
    try:
        from ._manifest import MODULES, SHIPPED
    except ImportError:  # no manifest yet: every module is imported below (as before the manifest)
        MODULES, SHIPPED = (), {}
    for name, (module, class_name, order, many, element) in SHIPPED.items():
        _ENTRIES[name] = _Entry(name, f"{PACKAGE}.{module}", class_name, order, many, element)
    listed = set(MODULES)
    for module_name in _package_modules():
        if module_name in listed:
            continue
        defined = _module_tables(importlib.import_module(f"{PACKAGE}.{module_name}"))
        for cls in defined:
            if cls.TABLE in _ENTRIES:
                raise RuntimeError(f"two tables named {cls.TABLE!r}: {_ENTRIES[cls.TABLE].module}."
                                   f"{_ENTRIES[cls.TABLE].class_name} and {cls}")
            _ENTRIES[cls.TABLE] = _Entry.of(cls, cls not in _nested_of(defined))
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
    if not (isinstance(table_class, type) and issubclass(table_class, Table)
            and dataclasses.is_dataclass(table_class)):
        raise TypeError(f"register_element needs a dataclass subclass of mbs_models.elements.Table, got {table_class!r}")
    name = table_class.TABLE
    if not isinstance(name, str) or not name.isidentifier():
        raise TypeError(f"{table_class.__name__}.TABLE must name its TOML table (an identifier), got {name!r}")
    if name in TABLES and TABLES[name] is table_class:
        return table_class
    if name in TABLES and _same_definition(TABLES[name], table_class):  # its module imported again (reloaded)
        del _ENTRIES[name]
    if name in TABLES or name in SCENE_KEYS:
        taken = TABLES[name] if name in TABLES else "a scene key"
        raise TypeError(f"the table name {name!r} of {table_class.__name__} is taken by {taken}")
    nested = (*table_class.NESTED.values(), *table_class.NESTED_MANY.values())
    for table in nested:
        if table.TABLE and table.TABLE in TABLES and TABLES[table.TABLE] is not table:
            raise TypeError(f"the nested table name {table.TABLE!r} of {table_class.__name__} is taken")
    _ENTRIES[name] = _Entry.of(table_class, True)
    for table in nested:
        if table.TABLE:
            _ENTRIES[table.TABLE] = _Entry.of(table, False)
    _refresh()
    for callback in _LISTENERS:
        callback()
    return table_class
