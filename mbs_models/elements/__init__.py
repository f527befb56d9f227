"""Elements: every physical effect of a recoil mechanism is one module here.

An element module holds, for its effect: the scene table (a :class:`~.table.Table` dataclass and its
validation), the bodies and connectors it adds (:mod:`.connector`: the Exudyn items, the force law over
the backend ops of :mod:`.ops`, stored and dissipated energy, force bounds for the early stop, outputs).
Assembly, post-processing, the early stop and the stability checks iterate over them; none names an
effect.  This package finds the tables by itself: adding an effect is adding a module (and its reference
term in ``validation/reference/terms/`` and its test file); an element defined outside the package is
registered with :func:`register_element` (re-exported as ``mbs_models.register_element``).

The user guide (docs/guide/) and the key reference list the elements and their tables; ``TABLES`` is the registry
(:mod:`.registry`): an element module is imported when one of its tables is first used, not with the package.

Importing this package loads neither Exudyn nor the engine, nor any element module but the ones the scene
module needs (the barrel, the absorber and its contact, the firing).
"""

from __future__ import annotations

from .connector import GROUND, Body, Connector, LinearSpringDamper
from .table import Rule, Table
from .registry import ELEMENT_TABLES, TABLES, on_register, register_element
from .registry import _start

_start()

__all__ = ["Body", "Connector", "LinearSpringDamper", "GROUND", "Rule", "Table", "TABLES", "ELEMENT_TABLES",
           "register_element", "on_register"]
