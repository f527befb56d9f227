"""Whether two connectors have the same law, by value: :func:`same_laws` (a sweep's kept item keeps its user function).

A connector's law is its class's code over its attributes (the element contract: the law is the element).  Two
connectors of one class whose attributes are equal *by value* therefore have the same law, and a kept Exudyn item
(:func:`~mbs_models.engine.assembly.refill`) whose symbolic user function was recorded from one of them need not
record it again for the other (recording costs as much as tens of steps of a sweep point).

Only values immutable all the way down are compared, so that the held connector's attributes are still what its
law was recorded from: numbers (a float by its bits: ``-0.0`` is not ``0.0``, NaN equals NaN), strings, None,
tuples and frozen dataclasses of those (by class and fields), enum members.  A connector holding anything else (a
list, an array, a Scene, an onset capture with its state, a function) never shares a recording.  Being
conservative is the point: only a proven-equal law shares one; any doubt records the law anew, as for a
connector seen for the first time.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from typing import Any

#: Attributes the engine sets on a connector (its Exudyn item and the recorded user function): not its law.
ENGINE_ATTRIBUTES = frozenset({"index", "_user_function"})


def same_value(a: Any, b: Any) -> bool:
    """True if ``a`` and ``b`` are equal by value, exactly, and immutable all the way down (module docstring);
    False whenever unsure."""
    kind = type(a)
    if kind is not type(b):
        return False
    if kind is float:
        if a != a:
            return b != b  # NaN
        return a == b and (a != 0.0 or math.copysign(1.0, a) == math.copysign(1.0, b))
    if a is None or kind in (bool, int, str):
        return a == b
    if kind is tuple:
        return len(a) == len(b) and all(same_value(x, y) for x, y in zip(a, b))
    if isinstance(a, enum.Enum):
        return a is b
    params = getattr(kind, "__dataclass_params__", None)
    if params is not None and params.frozen:
        return all(same_value(getattr(a, field.name), getattr(b, field.name)) for field in dataclasses.fields(a))
    return False  # mutable (a list, an array, a Scene, an onset capture) or unknown: never shared


def same_law(old, new) -> bool:
    """True if connector ``new`` has the law of connector ``old``: the same class, and every attribute but the
    engine's (:data:`ENGINE_ATTRIBUTES`) and those the class says its law does not read (``law_state_ignores``)
    equal by value; ``offset`` left out too for a class whose item holds it
    (:attr:`~mbs_models.elements.connector.Connector.offset_in_item`: the item's offset is written anew)."""
    if type(old) is not type(new) or not hasattr(new, "__dict__") or not hasattr(old, "__dict__"):
        return False  # (another class, or attributes in slots: not compared)
    mine, theirs = vars(new), vars(old)
    kind = type(new)
    ignored = (ENGINE_ATTRIBUTES | getattr(kind, "law_state_ignores", frozenset())
               | ({"offset"} if getattr(kind, "offset_in_item", False) else set()))
    names = mine.keys() - ignored
    if names != theirs.keys() - ignored:
        return False
    return all(same_value(theirs[name], mine[name]) for name in names)


def same_laws(recorded, members) -> bool:
    """True if the connectors ``members`` have, one by one, the laws of ``recorded`` (the connectors an item's user
    function was recorded from)."""
    return len(recorded) == len(members) and all(same_law(old, new) for old, new in zip(recorded, members))


__all__ = ["ENGINE_ATTRIBUTES", "same_value", "same_law", "same_laws"]
