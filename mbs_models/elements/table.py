"""The base of every scene table: a frozen dataclass that validates itself on construction.

An element module defines its table as a subclass of :class:`Table`::

    @dataclass(frozen=True)
    class RecoilSpring(Table):
        stiffness: float
        TABLE: ClassVar[str] = "recoil_spring"          # the TOML table, and the Scene attribute
        ORDER: ClassVar[int] = 20                        # position in the assembly order
        RULES: ClassVar = {"stiffness": Rule(0.0, unit="N/m")}

and nothing else registers it: :mod:`mbs_models.elements` finds every Table subclass of its modules.
A table built in Python is checked exactly like one read from TOML; every error is a
:class:`~mbs_models.errors.SceneError` naming the key (``recoil_spring.stiffness``) and the allowed range.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, fields
from typing import Any, ClassVar, Iterable

from ..errors import SceneError
from .declaration import NO_OUTPUTS, Outputs


@dataclass(frozen=True)
class Rule:
    """Allowed values of a numeric field: ``value >= minimum`` (``> minimum`` if ``strict``), ``<= maximum``
    (``< maximum`` if ``strict_maximum``); ``unit`` is named in messages.  ``None`` bounds are open."""

    minimum: float | None = None
    strict: bool = False
    unit: str = ""
    maximum: float | None = None
    strict_maximum: bool = False

    def describe(self) -> str:
        """The allowed range in words, e.g. ``> 0 kg`` or ``in (0, 1]``."""
        suffix = f" {self.unit}" if self.unit else ""
        if self.minimum is not None and self.maximum is not None:
            left = "(" if self.strict else "["
            right = ")" if self.strict_maximum else "]"
            return f"in {left}{self.minimum:g}, {self.maximum:g}{right}{suffix}"
        if self.minimum is not None:
            return f"{'>' if self.strict else '>='} {self.minimum:g}{suffix}"
        if self.maximum is not None:
            return f"{'<' if self.strict_maximum else '<='} {self.maximum:g}{suffix}"
        return f"a finite number{suffix}"


def check_number(key: str, value, rule: Rule = Rule()) -> float:
    """Return ``value`` as float, or raise SceneError naming ``key`` and the allowed range."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SceneError(key, f"must be a number, got {type(value).__name__} {value!r}")
    if isinstance(value, int) and abs(value) > sys.float_info.max:  # float() would raise OverflowError
        raise SceneError(key, f"must be a finite number ({rule.describe()}), got an integer beyond the largest "
                              f"double ({sys.float_info.max:.4g})")
    value = float(value)
    if not math.isfinite(value):
        raise SceneError(key, f"must be a finite number, got {value}")
    too_small = rule.minimum is not None and (value <= rule.minimum if rule.strict else value < rule.minimum)
    too_large = rule.maximum is not None and (value >= rule.maximum if rule.strict_maximum else value > rule.maximum)
    if too_small or too_large:
        if rule.minimum is not None and rule.maximum is None:
            # the wording of version 1 ("must be > 0 kg, got -5")
            raise SceneError(key, f"must be {rule.describe()}, got {value:g}")
        raise SceneError(key, f"must be {rule.describe()}, got {value:g}")
    return value


def culprit(values: dict[str, float]) -> str:
    """The key (of ``{key: value}``, the keys a derived quantity depends on) whose value lies farthest from 1 in
    magnitude (``|log |value||`` largest; 0 counts as the farthest): the likeliest slip when the quantity is not
    representable."""
    def distance(item):
        value = abs(float(item[1]))
        return math.inf if value == 0.0 or not math.isfinite(value) else abs(math.log(value))
    return max(values.items(), key=distance)[0]


def check_derived(values: dict[str, float], what: str, value: float, unit: str = "", *,
                  positive: bool = False) -> float:
    """``value`` -- a quantity the model derives from the keys ``values`` (``{key: value}``; ``what`` names it and
    gives its formula) -- if double precision represents it: finite, and > 0 if ``positive`` (a product of
    positive numbers that underflows to 0).  Otherwise a SceneError naming the key of :func:`culprit` and every
    key with its value: a magnitude the model cannot represent is bad input, never clamped."""
    if math.isfinite(value) and (value > 0.0 or not positive):
        return value
    allowed = f"finite and > 0 (in [{5e-324:g}, {sys.float_info.max:.4g}]{' ' + unit if unit else ''})" if positive \
        else f"finite (|x| <= {sys.float_info.max:.4g}{' ' + unit if unit else ''})"
    given = ", ".join(f"{key} = {number:g}" for key, number in values.items())
    raise SceneError(culprit(values), f"{what} = {value:g}{' ' + unit if unit else ''} is beyond double precision: "
                                      f"it must be {allowed}; from {given}")


def ieee_power(base: float, exponent: float) -> float:
    """``base ** exponent`` (floats, ``base >= 0``) as IEEE arithmetic gives it -- inf where it overflows -- for
    quantities that :func:`check_derived` then judges (Python's float power raises OverflowError instead);
    otherwise exactly Python's power."""
    try:
        return float(base) ** float(exponent)
    except OverflowError:
        return math.inf


def check_choice(key: str, value, allowed: Iterable[str], what: str = "value") -> str:
    """Return ``value`` if it is one of ``allowed`` strings, else a SceneError with a "did you mean"."""
    allowed = tuple(allowed)
    if not isinstance(value, str):
        raise SceneError(key, f"must be a string, one of {', '.join(allowed)}")
    if value not in allowed:
        raise SceneError(key, f"unknown {what} {value!r}{suggestion(value, allowed)}")
    return value


def suggestion(word: str, allowed: Iterable[str]) -> str:
    """``"; did you mean 'x'?"`` for the closest allowed word, else ``"; allowed: a, b, c"``."""
    allowed = sorted(allowed)
    import difflib  # (here: a misspelt key is rare, the import is not free)

    close = difflib.get_close_matches(word, allowed, n=1, cutoff=0.6)
    if close:
        return f"; did you mean {close[0]!r}?"
    return f"; allowed: {', '.join(allowed)}"


def rekey(error: SceneError, old_prefix: str, new_prefix: str) -> SceneError:
    """The same error with its key's ``old_prefix`` replaced (a nested or indexed table names its place)."""
    key = error.key
    if key == old_prefix or key.startswith(old_prefix + "."):
        key = new_prefix + key[len(old_prefix):]
    elif not key:
        key = new_prefix
    return SceneError(key, error.message)


class Table:
    """Mixin of every scene table (a frozen dataclass): class attributes describe it, ``RULES`` check it.

    Class attributes
    ----------------
    TABLE: the TOML table name and the :class:`~mbs_models.scene.Scene` attribute (``"recoil_spring"``).
    MANY: True for an array of tables (``[[absorber]]``): the scene holds a tuple, attribute ``TABLE + "s"``.
    ORDER: position in the scene's element order (assembly, energy sums, outputs); smaller first.
    SINCE_VERSION: the first scene-format version that has this table (2 for the new effects).
    RULES: field name -> :class:`Rule` for numeric fields (``None`` values are skipped: optional fields).
    REQUIRED: keys a file must give (default: the fields without a default value).
    NESTED: field name -> Table class of a sub-table (``[absorber.contact]``).
    NESTED_MANY: field name -> Table class of an array of sub-tables (``[[carriage.support]]``): the field holds
        a tuple of them; dotted keys address one by its 0-based index (``carriage.support.1.stiffness``).
    ROLES: what the element is to the results (:data:`~mbs_models.elements.declaration.ABSORBER`,
        :data:`~mbs_models.elements.declaration.END_STOP`); none by default.
    OUTPUTS: the element's declared histories and metrics (:mod:`~mbs_models.elements.declaration`); none by
        default.
    KEY_UNITS: field name -> unit of a key whose ``RULES`` entry names none (``"1"`` dimensionless, ``"text"``,
        ``"true/false"``, the form of a table of pairs); with the ``Attributes`` section of the class docstring
        (one entry per key) it makes the key reference (:mod:`mbs_models.scene.keys`).
    CHOICES: field name -> the allowed strings of a key that is a choice (the tuple its check uses).
    """

    TABLE: ClassVar[str] = ""
    MANY: ClassVar[bool] = False
    ORDER: ClassVar[int] = 100
    SINCE_VERSION: ClassVar[int] = 1
    RULES: ClassVar[dict[str, Rule]] = {}
    NESTED: ClassVar[dict[str, type]] = {}
    NESTED_MANY: ClassVar[dict[str, type]] = {}
    ROLES: ClassVar[tuple[str, ...]] = ()
    OUTPUTS: ClassVar[Outputs] = NO_OUTPUTS
    KEY_UNITS: ClassVar[dict[str, str]] = {}
    CHOICES: ClassVar[dict[str, tuple[str, ...]]] = {}

    def __post_init__(self):
        for name, rule in self.RULES.items():
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, check_number(f"{self.TABLE}.{name}", value, rule))
        for name, cls in self.NESTED.items():
            value = getattr(self, name)
            if value is not None and not isinstance(value, cls):
                raise SceneError(f"{self.TABLE}.{name}", f"must be a {cls.__name__} table, got {type(value).__name__}")
        for name, cls in self.NESTED_MANY.items():
            value = getattr(self, name)
            if isinstance(value, list):
                value = tuple(value)
                object.__setattr__(self, name, value)
            if not isinstance(value, tuple) or not all(isinstance(item, cls) for item in value):
                raise SceneError(f"{self.TABLE}.{name}", f"must be an array of [[{self.TABLE}.{name}]] tables "
                                                         f"({cls.__name__}), got {type(value).__name__}")

    # ------------------------------------------------------------------ description
    @classmethod
    def field_names(cls) -> list[str]:
        """The table's keys (dataclass fields), in order."""
        return [f.name for f in fields(cls)]

    @classmethod
    def required_keys(cls) -> tuple[str, ...]:
        """Keys a file must give: the fields without a default."""
        from dataclasses import MISSING
        return tuple(f.name for f in fields(cls) if f.default is MISSING and f.default_factory is MISSING)

    @classmethod
    def from_mapping(cls, data: dict[str, Any], key: str, version: int) -> "Table":
        """Build the table from a parsed TOML mapping; errors name ``key`` (the table's place in the file)."""
        if not isinstance(data, dict):
            raise SceneError(key, f"must be a table [{key}], got {type(data).__name__}")
        names = cls.field_names()
        for name in data:
            if name not in names:
                raise SceneError(f"{key}.{name}", f"unknown key{suggestion(name, names)}")
        for name in cls.required_keys():
            if name not in data:
                raise SceneError(f"{key}.{name}", "missing required key")
        values = dict(data)
        for name, nested in cls.NESTED.items():
            if name in values:
                if nested.SINCE_VERSION > version:
                    raise SceneError(f"{key}.{name}", f"[{key}.{name}] needs a version-{nested.SINCE_VERSION} scene "
                                                      f"(put version = {nested.SINCE_VERSION} at the top)")
                values[name] = nested.from_mapping(values[name], f"{key}.{name}", version)
        for name, nested in cls.NESTED_MANY.items():
            if name in values:
                entries = values[name] if isinstance(values[name], list) else [values[name]]
                values[name] = tuple(nested.from_mapping(entry, f"{key}.{name}.{i}", version)
                                     for i, entry in enumerate(entries))
        try:
            return cls(**values)
        except SceneError as exc:
            raise rekey(exc, cls.TABLE, key) from None

    def to_mapping(self) -> dict[str, Any]:
        """The TOML mapping of this table (inverse of :meth:`from_mapping`); omits fields that are None."""
        out: dict[str, Any] = {}
        for name in self.field_names():
            value = getattr(self, name)
            if value is None:
                continue
            if isinstance(value, Table):
                value = value.to_mapping()
            elif name in self.NESTED_MANY:
                value = [item.to_mapping() for item in value]
            out[name] = value
        return out

    def check_in_scene(self, scene, key: str) -> None:
        """Checks that need the whole scene (e.g. a stop's position against the other stop); ``key`` is
        this table's place in the scene (``"absorber.1"``).  Default: none."""

    def initial_positions(self, scene, name: str, bodies, connectors) -> dict[str, float]:
        """Positions (m) at t = 0 that this element imposes, by body name, given every body and connector of
        the scene (a preload holding the barrel against its battery stop).  Default: none -- every body starts
        at x = 0."""
        return {}
