"""The validated description of one recoil mechanism: :class:`Scene` and the paper's readings (:class:`Conventions`).

A scene is pure data: the tables of its elements (frozen dataclasses defined in
:mod:`mbs_models.elements`, SI units), its conventions and a name.  It knows no effect by name: every
table registered in :data:`mbs_models.elements.ELEMENT_TABLES` is an attribute (``scene.recoil_spring``,
``None`` when absent), arrays of tables hold tuples (``scene.absorbers``), and :meth:`Scene.elements`
iterates over what the scene has, in assembly order.  A scene built in Python is checked exactly like one
read from TOML (:mod:`mbs_models.scene.io`); errors are :class:`~mbs_models.errors.SceneError` naming
the key, e.g. ``contact.gap`` or ``absorber.1.mass``.

Sign convention: positions are positive in the recoil direction; every body starts at x = 0 (unless a
preload holds the barrel in battery: :mod:`mbs_models.elements.recuperator`), the absorbers at rest, the
barrel at ``v0`` (:attr:`Scene.initial_velocity`).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, is_dataclass, replace
from typing import Any, Iterator

from ..elements import ELEMENT_TABLES, Table, on_register
from ..elements.absorber import Absorber
from ..elements.contact_laws import Contact
from ..elements.table import rekey, suggestion
from ..errors import SceneError

#: The paper's printed, rounded initial barrel velocity (Section 2.1), in m/s.
PAPER_ROUNDED_INITIAL_VELOCITY = 0.7


@dataclass(frozen=True)
class Conventions:
    """Alternative readings of the paper's text; all off by default (see the user guide and the report).

    Each flag reproduces one literal reading that the validation report studies.  They concern the
    paper's contact at wall A (the absorbers' contacts):

    Attributes
    ----------
    literal_lambda_sign: Eq. (6) taken literally with delta_dot = x_m' - x_M': the damping term
        becomes ``(1 - lambda p_dot)``, i.e. it *adds* energy during compression (hunt-crossley only).
    compression_only: "the contact force will only act ... when delta and delta_dot are
        negative": force only while the penetration grows (p_dot > 0), none during restitution
        (hunt-crossley, one absorber).
    v0_includes_absorber: model (i): the absorber rides on the barrel, so the projectile
        momentum accelerates ``M + m`` (Section 2.1, "this will affect the initial velocity").
    rounded_initial_velocity: use the paper's printed v0 = 0.7 m/s instead of the exact
        momentum balance (0.6909 m/s for Table 1).
    literal_gap_sign: delta = x_m - (x_M + gap) taken literally: the gap then acts as an
        initial interference, ``p = (x_M - x_m) + gap``.
    """

    literal_lambda_sign: bool = False
    compression_only: bool = False
    v0_includes_absorber: bool = False
    rounded_initial_velocity: bool = False
    literal_gap_sign: bool = False

    TABLE = "conventions"
    #: every flag is a boolean (the key reference, :mod:`mbs_models.scene.keys`)
    KEY_UNITS = {name: "true/false" for name in ("literal_lambda_sign", "compression_only", "v0_includes_absorber",
                                                 "rounded_initial_velocity", "literal_gap_sign")}

    def __post_init__(self):
        for f in fields(self):
            if not isinstance(getattr(self, f.name), bool):
                raise SceneError(f"conventions.{f.name}", "must be true or false")

    @property
    def active(self) -> tuple[str, ...]:
        """Names of the flags that are switched on."""
        return tuple(f.name for f in fields(self) if getattr(self, f.name))


def _many_attribute(table: str) -> str:
    return table + "s"


#: The single tables' names, and the arrays' scene attributes (``absorbers``) -> table name, in element order.
_SINGLE: dict[str, str] = {}
_MANY: dict[str, str] = {}


def _refresh_views() -> None:
    """The single and array tables of :data:`ELEMENT_TABLES` (again after :func:`~mbs_models.register_element`);
    by name, importing no element module."""
    _SINGLE.clear()
    _SINGLE.update((name, name) for name in ELEMENT_TABLES if not ELEMENT_TABLES.many(name))
    _MANY.clear()
    _MANY.update((_many_attribute(name), name) for name in ELEMENT_TABLES if ELEMENT_TABLES.many(name))


_refresh_views()
on_register(_refresh_views)


class Scene:
    """One recoil mechanism: the paper's simplified model, its models (i) and (ii), or a richer one.

    ``Scene(barrel, recoil_spring, recoil_damper, firing=None, absorber=None, contact=None,
    conventions=None, name="unnamed scene", **tables)``: the first eight are version 1's (one absorber,
    with its ``contact`` given beside it); ``**tables`` are any element tables by their scene attribute
    (``absorbers=(...)``, and any other table by its name).  A barrel and an initial velocity
    (``barrel.initial_velocity`` or a ``firing`` table) are required; every other table is optional and
    an absent one adds nothing to the simulated system.

    Attributes: ``name``, ``conventions``, and one per element table (``None`` when absent;
    ``absorbers`` is a tuple).  ``absorber`` and ``contact`` are the one absorber and its contact (None
    without absorber; an error with several: use ``absorbers``).
    """

    __slots__ = ("name", "conventions", "_parts")

    def __init__(self, barrel=None, recoil_spring=None, recoil_damper=None, firing=None, absorber=None,
                 contact=None, conventions=None, name: str = "unnamed scene", **tables):
        parts: dict[str, Any] = {"barrel": barrel, "recoil_spring": recoil_spring, "recoil_damper": recoil_damper,
                                 "firing": firing}
        for key, value in tables.items():
            if key not in _SINGLE and key not in _MANY:
                raise SceneError(key, f"not a scene table{suggestion(key, list(_SINGLE) + list(_MANY))}")
            parts[key] = value
        absorbers = tables.get("absorbers")
        if absorber is not None or contact is not None:
            if absorbers is not None:
                raise SceneError("absorber", "give either absorber (with contact) or absorbers, not both")
            if not isinstance(absorber, Absorber) and absorber is not None:
                raise SceneError("absorber", f"must be a Absorber or absent, got {type(absorber).__name__}")
            if contact is not None and not isinstance(contact, Contact):
                raise SceneError("contact", f"must be a Contact or absent, got {type(contact).__name__}")
            if absorber is None:
                raise SceneError("absorber", "missing: a [contact] table needs an [absorber] to touch")
            if contact is None and absorber.contact is None:
                raise SceneError("contact", "missing: an [absorber] needs a [contact] table (wall A drives it)")
            if contact is not None and absorber.contact is not None and contact != absorber.contact:
                raise SceneError("contact", "given twice: as the scene's contact and as the absorber's")
            parts["absorbers"] = (absorber if contact is None else replace(absorber, contact=contact),)
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "conventions", Conventions() if conventions is None else conventions)
        object.__setattr__(self, "_parts", self._normalise(parts))
        self._check()

    # ------------------------------------------------------------------ construction
    @staticmethod
    def _normalise(parts: dict[str, Any]) -> tuple:
        out = []
        for table in ELEMENT_TABLES:  # an absent table's class is not needed (nor its module imported)
            if ELEMENT_TABLES.many(table):
                attribute = _many_attribute(table)
                value = parts.get(attribute)
                value = () if value is None else value
                if isinstance(value, Table) or not isinstance(value, (list, tuple)):
                    raise SceneError(attribute, f"must be a sequence of {ELEMENT_TABLES.class_name(table)} tables, "
                                                f"got {type(value).__name__}")
                if value:
                    cls = ELEMENT_TABLES[table]
                    for i, item in enumerate(value):
                        if not isinstance(item, cls):
                            raise SceneError(f"{table}.{i}", f"must be a {cls.__name__}, got {type(item).__name__}")
                out.append((attribute, tuple(value)))
            else:
                value = parts.get(table)
                if value is not None and not isinstance(value, ELEMENT_TABLES[table]):
                    raise SceneError(table, f"must be a {ELEMENT_TABLES.class_name(table)} or absent, got "
                                            f"{type(value).__name__}")
                out.append((table, value))
        return tuple(out)

    def _check(self) -> None:
        if not isinstance(self.name, str):
            raise SceneError("name", "must be a string")
        if not isinstance(self.conventions, Conventions):
            raise SceneError("conventions", f"must be a Conventions or absent, got {type(self.conventions).__name__}")
        if self.barrel is None:
            raise SceneError("barrel", "missing required table [barrel]")
        if self.firing is None and self.barrel.initial_velocity is None:
            raise SceneError("barrel.initial_velocity",
                             "missing: give barrel.initial_velocity (m/s) or a [firing] table")
        if self.firing is not None and self.barrel.initial_velocity is not None:
            raise SceneError("barrel.initial_velocity",
                             "give either barrel.initial_velocity or a [firing] table, not both")
        names = self.absorber_names()
        keys = [key for key, _ in self._absorber_keys()]
        for i, name in enumerate(names):
            if name in names[:i]:
                raise SceneError(f"{keys[i]}.name", f"{name!r} names two absorbers: names must be unique")
        for key, table in self.tables():
            try:
                table.check_in_scene(self, key)
            except SceneError as exc:
                raise exc from None
        self._check_item_names()
        conventions = self.conventions
        if conventions.v0_includes_absorber and self.firing is None:
            raise SceneError("conventions.v0_includes_absorber",
                             "needs a [firing] table (v0 is computed from the projectile momentum)")
        for flag in ("literal_lambda_sign", "compression_only"):
            if getattr(conventions, flag):
                for key, absorber in self._absorber_keys():
                    if absorber.contact.law != "hunt-crossley":
                        raise SceneError(f"conventions.{flag}", f"is a reading of the paper's Hunt-Crossley law: "
                                                                f"{key}.contact.law is {absorber.contact.law!r}")
        if conventions.compression_only and len(self.absorbers) > 1:
            raise SceneError("conventions.compression_only", "needs a scene with one absorber")

    def _check_item_names(self) -> None:
        """Every body, connector and load of the assembled mechanism has its own name, and no element is named
        like another element's item: outputs are keyed by these names and ``Result.energy()`` groups them by
        element, so a shared name would merge or misattribute entries.  Only an absorber's name is the user's
        (the other elements' names are fixed and distinct) or that of an element named by the user (a
        ``[[tabulated_spring]]``'s ``name``), so this runs when one is named; the error names that element's key
        (``absorber.N.name``, ``tabulated_spring.1.name``)."""
        keys = {id(table): key for key, table in self.tables()
                if isinstance(table, Absorber) or isinstance(getattr(table, "name", None), str)}
        if not any(table.name for _, table in self.tables() if id(table) in keys):
            return
        elements = [(name, table, keys.get(id(table))) for name, table in self.elements()]

        def described(index: int) -> str:
            name, table, key = elements[index]
            if key is None:
                return f"the [{name}] element"
            return f"absorber {name!r}" if isinstance(table, Absorber) else f"the [[{table.TABLE}]] {name!r}"

        owner: dict[str, int] = {}  # a name -> the index of the element that uses it
        for index, (element, table, key) in enumerate(elements):
            items = [b.name for b in table.bodies(self, element)] + [c.name for c in table.connectors(self, element)]
            if hasattr(table, "loads"):
                items += [load.name for load in table.loads(self, element)]
            for name in [element] + items:
                other = owner.setdefault(name, index)
                if other == index and items.count(name) <= 1:
                    continue
                by = f"by {described(other)} and by {described(index)}" if other != index else \
                    f"by {described(index)} (its body and one of its connectors)"
                named = key or elements[other][2]  # the absorber's key (two fixed names never collide)
                raise SceneError(f"{named}.name" if named else element,
                                 f"the name {name!r} is taken twice, {by}: every body, connector, load and element "
                                 f"must have its own name (an absorber A adds the body A and the connectors A_damper "
                                 f"and A_contact; absorber_damper and contact if it is the only one)")

    # ------------------------------------------------------------------ tables
    def __getattr__(self, name: str):
        if name.startswith("__"):
            raise AttributeError(name)
        parts = object.__getattribute__(self, "_parts")
        for key, value in parts:
            if key == name:
                return value
        raise AttributeError(f"'Scene' object has no attribute {name!r}")

    def __setattr__(self, name, value):
        raise AttributeError("a Scene is immutable: use scene.with_changes(...)")

    def _absorber_keys(self) -> list[tuple[str, Absorber]]:
        absorbers = self.absorbers
        if len(absorbers) == 1:
            return [("absorber", absorbers[0])]
        return [(f"absorber.{i}", a) for i, a in enumerate(absorbers)]

    def tables(self) -> list[tuple[str, Table]]:
        """Every table the scene has, with its key (``"recoil_spring"``, ``"absorber"``, ``"absorber.1"``)."""
        out = []
        for key, value in self._parts:
            if isinstance(value, tuple):
                table = _MANY[key]
                out += [(table if len(value) == 1 else f"{table}.{i}", item) for i, item in enumerate(value)]
            elif value is not None:
                out.append((key, value))
        return out

    def absorber_names(self) -> list[str]:
        """The absorbers' names: their own, or ``absorber`` (one) / ``absorber_1``, ``absorber_2``, ..."""
        absorbers = self.absorbers
        if len(absorbers) == 1:
            return [absorbers[0].name or "absorber"]
        return [a.name or f"absorber_{i + 1}" for i, a in enumerate(absorbers)]

    def elements(self) -> list[tuple[str, Table]]:
        """``(element name, table)`` of every element, in assembly order (absorbers by their names)."""
        out = []
        names = iter(self.absorber_names())
        for key, value in self._parts:
            if isinstance(value, tuple):
                out += [(next(names), item) for item in value] if key == "absorbers" else \
                    [(getattr(item, "name", None) or f"{key[:-1]}_{i + 1}", item) for i, item in enumerate(value)]
            elif value is not None:
                out.append((key, value))
        return out

    @property
    def absorber(self) -> Absorber | None:
        """The scene's one absorber (None without; SceneError with several: use :attr:`absorbers`)."""
        absorbers = self.absorbers
        if len(absorbers) > 1:
            raise SceneError("absorber", f"the scene has {len(absorbers)} absorbers: use scene.absorbers")
        return absorbers[0] if absorbers else None

    @property
    def contact(self) -> Contact | None:
        """The contact of the scene's one absorber (None without absorber)."""
        absorber = self.absorber
        return None if absorber is None else absorber.contact

    # ------------------------------------------------------------------ derived quantities
    @property
    def has_absorber(self) -> bool:
        """True for models (i) and (ii) and every scene with an absorber."""
        return bool(self.absorbers)

    @property
    def model_label(self) -> str:
        """``"simplified"``, ``"model (i)"``, ``"model (ii)"`` (one absorber) or ``"N absorbers"``."""
        absorbers = self.absorbers
        if not absorbers:
            return "simplified"
        if len(absorbers) == 1:
            return "model (i)" if absorbers[0].mount == "barrel" else "model (ii)"
        return f"{len(absorbers)} absorbers"

    @property
    def initial_velocity(self) -> float:
        """Initial barrel velocity v0 in m/s (Section 2.1), honouring the active conventions.

        From a [firing] table: ``v0 = projectile momentum / M`` (``/(M + m)`` with
        ``v0_includes_absorber``, m the mass of every absorber on the barrel); with
        ``rounded_initial_velocity`` the value is rounded to 0.1 m/s as the paper prints it (0.7 m/s).
        """
        if self.firing is None:
            v0 = float(self.barrel.initial_velocity)
        else:
            moving_mass = self.barrel.mass
            if self.conventions.v0_includes_absorber:
                for absorber in self.absorbers:
                    if absorber.mount == "barrel":
                        moving_mass += absorber.mass
            v0 = self.firing.initial_velocity(moving_mass)
        if self.conventions.rounded_initial_velocity:
            v0 = round(v0, 1)
        return v0

    @property
    def initial_kinetic_energy(self) -> float:
        """Kinetic energy at t = 0 in J (the barrel alone moves)."""
        return 0.5 * self.barrel.mass * self.initial_velocity ** 2

    # ------------------------------------------------------------------ changes
    def with_changes(self, **changes) -> "Scene":
        """A copy with tables or fields changed.

        Keys: a table (``recoil_spring=RecoilSpring(...)``, ``recoil_damper=None``, ``absorbers=(...)``,
        ``absorber=...`` and ``contact=...`` for the one absorber), ``name``, ``conventions``, or a dotted
        key to one field: ``"contact.gap"``, ``"absorber.mass"`` (the one absorber), ``"absorber.0.mass"``,
        ``"absorber.1.contact.gap"``, ``"recoil_damper.recoil"``, ``"conventions.literal_gap_sign"``.
        """
        state = {key: value for key, value in self._parts}
        name, conventions = self.name, self.conventions
        for key, value in changes.items():
            if key == "name":
                name = value
            elif key == "conventions" or key.startswith("conventions."):
                conventions = value if key == "conventions" else _replace_path(conventions, key, key.split(".")[1:], value)
            elif key in ("absorber", "contact") or key.startswith(("absorber.", "contact.")):
                state["absorbers"] = _change_absorbers(state["absorbers"], key, value)
            elif key in state:
                state[key] = tuple(value) if isinstance(value, list) else value
            elif "." in key:
                table, *path = key.split(".")
                if table not in state:
                    raise SceneError(key, f"not a scene table{suggestion(table, list(state))}")
                current = state[table]
                if current is None:
                    raise SceneError(key, f"the scene has no [{table}] table to change")
                state[table] = _replace_path(current, key, path, value)
            else:
                raise SceneError(key, f"not a scene table or key{suggestion(key, list(state) + ['name'])}")
        return Scene(name=name, conventions=conventions, **{k: v for k, v in state.items()})

    # ------------------------------------------------------------------ value semantics
    def _key(self) -> tuple:
        return (self.name, self.conventions, self._parts)

    def __eq__(self, other) -> bool:
        return isinstance(other, Scene) and self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __reduce__(self):
        return (_restore, (self.name, self.conventions, self._parts))

    def __repr__(self) -> str:
        parts = ", ".join(f"{key}={value!r}" for key, value in self._parts if value not in (None, ()))
        return f"Scene(name={self.name!r}, {parts}, conventions={self.conventions!r})"

    def __iter__(self) -> Iterator:
        raise TypeError("a Scene is not iterable: use scene.elements() or scene.tables()")


def _restore(name, conventions, parts) -> Scene:
    return Scene(name=name, conventions=conventions, **{key: value for key, value in parts})


def _replace_path(obj, key: str, path: list[str], value):
    """``obj`` with the field at ``path`` (a list of field names) set to ``value``; errors name ``key``."""
    if not path:
        raise SceneError(key, "names a table, not a field")
    head, *rest = path
    if not is_dataclass(obj):
        raise SceneError(key, "has no fields to change")
    valid = [f.name for f in fields(obj)]
    if head not in valid:
        raise SceneError(key, f"unknown field{suggestion(head, valid)}")
    if rest:
        inner = getattr(obj, head)
        if inner is None:
            raise SceneError(key, f"the scene has no {head} to change")
        value = _replace_path(inner, key, rest, value)
    table = getattr(obj, "TABLE", "")
    try:
        return replace(obj, **{head: value})
    except SceneError as exc:
        raise rekey(exc, table, key.rsplit(".", len(path))[0]) from None


def _change_absorbers(absorbers: tuple, key: str, value) -> tuple:
    """The absorbers with ``key`` (``absorber``, ``contact``, ``absorber.N...``, ``absorber.field``,
    ``contact.field``) set to ``value``."""
    parts = key.split(".")
    if parts[0] == "absorber" and len(parts) > 1 and parts[1].isdigit():
        index = int(parts[1])
        if index >= len(absorbers):
            raise SceneError(key, f"the scene has {len(absorbers)} absorber(s): index {index} does not exist")
        rest = parts[2:]
        target = ["absorber"] + rest
    else:
        if len(absorbers) != 1:
            if parts[0] == "absorber" and len(parts) == 1 and not absorbers:
                return (value,) if value is not None else ()
            raise SceneError(key, f"the scene has {len(absorbers)} absorbers: name one as absorber.N.{'.'.join(parts[1:]) or '...'}"
                             if absorbers else "the scene has no [absorber] table to change")
        index = 0
        target = parts
    absorber = absorbers[index]
    if target == ["absorber"]:
        new = value
    elif target == ["contact"] or target[:2] == ["absorber", "contact"] and len(target) == 2:
        new = replace(absorber, contact=value)
    elif target[0] == "contact":
        new = _replace_path(absorber, key, ["contact"] + target[1:], value)
    else:
        new = _replace_path(absorber, key, target[1:], value)
    items = list(absorbers)
    if new is None:
        del items[index]
    else:
        items[index] = new
    return tuple(items)
