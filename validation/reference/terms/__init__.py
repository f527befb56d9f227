"""Reference terms: one module per physical effect, found by this package.

A term module names the scene tables it models in ``TABLES`` and adds, in ``build(builder, key, table)``,
the bodies, connectors and roles of one such table to a
:class:`~validation.reference.assembly.ModelBuilder` (``key`` is the table's place in the scene:
``"recoil_spring"``, ``"absorber"``, ``"absorber.1"``).  The connectors carry the rest of the effect:
their force law (mandatory, :class:`~validation.reference.model.Connector`) and what is derived from it unless
given in closed form -- the stored energy and dissipated power, the
switching surfaces and how the mode is classified at a restart, and the contribution to the energy
bounds of the early stop (:mod:`validation.reference.model`).  Adding an effect to the reference is
adding one module here; a user's element defined outside the package registers its term with
:func:`register_term`.

Modules without ``TABLES`` are building blocks of the terms (:mod:`.contact_laws`, :mod:`.spring_damper`).
The terms are found by the table names they declare (:data:`TERMS`, below), never listed here: the user guide
lists the effects and their tables, and ``tests/validation/reference/test_terms.py`` checks that every scene
table has a term.
"""

from __future__ import annotations

import importlib
import pkgutil
from types import ModuleType


def _discover() -> dict[str, ModuleType]:
    """Every term module of this package, by the table names it declares in ``TABLES``."""
    found: dict[str, ModuleType] = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda i: i.name):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        for table in getattr(module, "TABLES", ()):
            if table in found:
                raise RuntimeError(f"two reference terms for [{table}]: {found[table].__name__} and {module.__name__}")
            found[table] = module
    return found


#: table name -> term module
TERMS: dict[str, ModuleType] = _discover()


def _redefined(old, new) -> bool:
    """Is ``new`` the term ``old`` once more: the same name from the same file (its module imported again)?"""
    import inspect

    def origin(term):
        try:
            return getattr(term, "__qualname__", getattr(term, "__name__", None)), inspect.getfile(term)
        except TypeError:
            return None, id(term)

    return origin(old) == origin(new)


def register_term(term) -> object:
    """Register the reference term of an element defined outside the package; returns ``term``.

    ``term`` is a module (or any object) with ``TABLES`` (the scene table names it models) and
    ``build(builder, key, table)`` (adds its bodies and connectors, subclasses of
    :class:`validation.reference.model.Connector` with their ``law``, to the builder), exactly like the term modules of this
    package.  Registering the same term again does nothing, and the same definition imported again (its module
    reloaded) replaces the first; a table that already has another term, or a term without ``TABLES`` or
    ``build``, is a TypeError.  The engine's side is
    :func:`mbs_models.register_element`.
    """
    tables = getattr(term, "TABLES", None)
    if isinstance(tables, str) or not tables or not callable(getattr(term, "build", None)):
        raise TypeError(f"a reference term needs TABLES (a tuple of table names) and build(builder, key, table): "
                        f"{term!r}")
    for table in tables:
        if TERMS.get(table, term) is not term and not _redefined(TERMS[table], term):
            raise TypeError(f"[{table}] already has a reference term: {TERMS[table].__name__}")
    for table in tables:
        TERMS[table] = term
    return term


__all__ = ["TERMS", "register_term"]
