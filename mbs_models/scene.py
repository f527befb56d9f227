"""The validated description of one recoil mechanism: :class:`Scene` and its parts.

A scene is pure data (frozen dataclasses, SI units).  Every part validates itself on construction,
so a scene built in Python is checked exactly like one read from TOML (see :mod:`mbs_models.scene_io`).
Errors are :class:`~mbs_models.errors.SceneError` and name the offending key, e.g. ``contact.gap``.

Sign convention (DESIGN.md): positions are positive in the recoil direction; barrel position ``x_M``
and absorber position ``x_m`` both start at 0, the absorber at rest, the barrel at ``v0``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import ClassVar, Literal

from .errors import SceneError

#: Allowed absorber mounts: ``"barrel"`` is the paper's model (i), ``"ground"`` its model (ii).
MOUNTS = ("barrel", "ground")
#: Allowed contact laws.
CONTACT_LAWS = ("hunt-crossley",)
#: The paper's printed, rounded initial barrel velocity (Section 2.1), in m/s.
PAPER_ROUNDED_INITIAL_VELOCITY = 0.7


def _check_number(key: str, value, *, minimum: float | None = None, strict: bool = False,
                  unit: str = "") -> float:
    """Return ``value`` as float, or raise SceneError naming ``key``.

    ``minimum`` with ``strict=True`` demands ``value > minimum``; otherwise ``value >= minimum``.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SceneError(key, f"must be a number, got {type(value).__name__} {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise SceneError(key, f"must be a finite number, got {value}")
    if minimum is not None:
        bad = value <= minimum if strict else value < minimum
        if bad:
            relation = ">" if strict else ">="
            suffix = f" {unit}" if unit else ""
            raise SceneError(key, f"must be {relation} {minimum:g}{suffix}, got {value:g}")
    return value


class _Part:
    """Mixin: validate numeric fields after construction using the ``_rules`` table."""

    _table: ClassVar[str] = ""
    # field name -> (minimum, strict, unit)
    _rules: ClassVar[dict[str, tuple[float, bool, str]]] = {}

    def __post_init__(self):
        for name, (minimum, strict, unit) in self._rules.items():
            value = getattr(self, name)
            if value is None:
                continue
            object.__setattr__(self, name, _check_number(f"{self._table}.{name}", value,
                                                         minimum=minimum, strict=strict, unit=unit))


@dataclass(frozen=True)
class Barrel(_Part):
    """The recoiling barrel, mass ``M`` of the paper (Eq. 1).

    Attributes
    ----------
    mass: barrel mass M in kg (> 0).
    initial_velocity: v0 in m/s; give either this or a :class:`Firing`.
    """

    mass: float
    initial_velocity: float | None = None
    _table: ClassVar[str] = "barrel"
    _rules: ClassVar = {"mass": (0.0, True, "kg"), "initial_velocity": (None, False, "m/s")}


@dataclass(frozen=True)
class Firing(_Part):
    """The shot that starts the motion: v0 follows from conservation of momentum (Section 2.1).

    Attributes
    ----------
    projectile_mass: kg (> 0), 6.86 kg in the paper.
    muzzle_velocity: m/s (> 0), 564 m/s in the paper.
    """

    projectile_mass: float
    muzzle_velocity: float
    _table: ClassVar[str] = "firing"
    _rules: ClassVar = {"projectile_mass": (0.0, True, "kg"), "muzzle_velocity": (0.0, True, "m/s")}

    @property
    def momentum(self) -> float:
        """Projectile momentum in kg m/s."""
        return self.projectile_mass * self.muzzle_velocity


@dataclass(frozen=True)
class RecoilSpring(_Part):
    """Recoil spring between ground and barrel, stiffness ``k`` in N/m (Eq. 1)."""

    stiffness: float
    _table: ClassVar[str] = "recoil_spring"
    _rules: ClassVar = {"stiffness": (0.0, False, "N/m")}


@dataclass(frozen=True)
class RecoilDamper(_Part):
    """Asymmetric recoil damper ``c`` of Eqs. (2)-(3), in N s/m.

    Attributes
    ----------
    recoil: c while the barrel moves in recoil (barrel velocity > 0), 6239 N s/m in the paper.
    counter_recoil: c while the barrel returns (velocity < 0), 14050 N s/m in the paper.
    """

    recoil: float
    counter_recoil: float
    _table: ClassVar[str] = "recoil_damper"
    _rules: ClassVar = {"recoil": (0.0, False, "N s/m"), "counter_recoil": (0.0, False, "N s/m")}

    @property
    def symmetric(self) -> bool:
        """True when both coefficients are equal: a plain linear damper suffices."""
        return self.recoil == self.counter_recoil


@dataclass(frozen=True)
class Absorber(_Part):
    """The impact absorber of mass ``m`` on its actuator spring-damper ``(k_r, c_r)``.

    Attributes
    ----------
    mass: absorber mass m in kg (> 0).
    mount: ``"barrel"`` (model (i), Eqs. 4-5) or ``"ground"`` (model (ii), Eqs. 7-8).
    stiffness: actuator stiffness k_r in N/m (>= 0), 13500 N/m in Table 1.
    damping: actuator damping c_r in N s/m (>= 0), 3675 N s/m in Table 1.
    """

    mass: float
    mount: Literal["barrel", "ground"]
    stiffness: float
    damping: float
    _table: ClassVar[str] = "absorber"
    _rules: ClassVar = {"mass": (0.0, True, "kg"), "stiffness": (0.0, False, "N/m"),
                        "damping": (0.0, False, "N s/m")}

    def __post_init__(self):
        super().__post_init__()
        if not isinstance(self.mount, str):
            raise SceneError("absorber.mount", f"must be a string, one of {', '.join(MOUNTS)}")
        if self.mount not in MOUNTS:
            raise SceneError("absorber.mount",
                             f"unknown mount {self.mount!r}; allowed: {', '.join(repr(m) for m in MOUNTS)}")


@dataclass(frozen=True)
class Contact(_Part):
    """Gap contact between wall A of the barrel and the absorber: Hunt-Crossley law, Eq. (6).

    With penetration ``p = (x_M - x_m) - gap`` (m) the force is
    ``F = k_c p^n_c (1 + lambda p_dot)`` for ``p > 0`` and never negative (no pulling).

    Attributes
    ----------
    gap: initial clearance in m (>= 0).
    stiffness: k_c in N/m^n_c (> 0), 2.1e8 in Table 1.
    exponent: n_c (> 0), 1.3 in Table 1.
    damping_factor: lambda_c = c_c / k_c in s/m (>= 0), 0.6 in Table 1.
    law: contact law name; only ``"hunt-crossley"``.
    """

    gap: float
    stiffness: float
    exponent: float
    damping_factor: float
    law: str = "hunt-crossley"
    _table: ClassVar[str] = "contact"
    _rules: ClassVar = {"gap": (0.0, False, "m"), "stiffness": (0.0, True, "N/m^exponent"),
                        "exponent": (0.0, True, ""), "damping_factor": (0.0, False, "s/m")}

    def __post_init__(self):
        super().__post_init__()
        if not isinstance(self.law, str):
            raise SceneError("contact.law", "must be a string")
        if self.law not in CONTACT_LAWS:
            raise SceneError("contact.law",
                             f"unknown law {self.law!r}; allowed: {', '.join(repr(x) for x in CONTACT_LAWS)}")


@dataclass(frozen=True)
class Conventions:
    """Alternative readings of the paper's text; all off by default (DESIGN.md, Physics).

    Each flag reproduces one literal reading that the validation report studies:

    * ``literal_lambda_sign`` -- Eq. (6) taken literally with delta_dot = x_m' - x_M': the damping term
      becomes ``(1 - lambda p_dot)``, i.e. it *adds* energy during compression.
    * ``compression_only`` -- "the contact force will only act ... when delta and delta_dot are
      negative": force only while the penetration grows (p_dot > 0), none during restitution.
    * ``v0_includes_absorber`` -- model (i): the absorber rides on the barrel, so the projectile
      momentum accelerates ``M + m`` (Section 2.1, "this will affect the initial velocity").
    * ``rounded_initial_velocity`` -- use the paper's printed v0 = 0.7 m/s instead of the exact
      momentum balance (0.6909 m/s for Table 1).
    * ``literal_gap_sign`` -- delta = x_m - (x_M + gap) taken literally: the gap then acts as an
      initial interference, ``p = (x_M - x_m) + gap``.
    """

    literal_lambda_sign: bool = False
    compression_only: bool = False
    v0_includes_absorber: bool = False
    rounded_initial_velocity: bool = False
    literal_gap_sign: bool = False

    def __post_init__(self):
        for f in fields(self):
            if not isinstance(getattr(self, f.name), bool):
                raise SceneError(f"conventions.{f.name}", "must be true or false")

    @property
    def active(self) -> tuple[str, ...]:
        """Names of the flags that are switched on."""
        return tuple(f.name for f in fields(self) if getattr(self, f.name))


@dataclass(frozen=True)
class Scene:
    """One recoil mechanism: the simplified model, model (i) or model (ii) of the paper.

    The simplified model has no absorber and no contact.  An absorber always needs a contact
    (wall A is what drives it); a contact without an absorber has nothing to touch.
    """

    barrel: Barrel
    recoil_spring: RecoilSpring
    recoil_damper: RecoilDamper
    firing: Firing | None = None
    absorber: Absorber | None = None
    contact: Contact | None = None
    conventions: Conventions = field(default_factory=Conventions)
    name: str = "unnamed scene"

    def __post_init__(self):
        if not isinstance(self.name, str):
            raise SceneError("name", "must be a string")
        for key, value, cls in (("barrel", self.barrel, Barrel), ("recoil_spring", self.recoil_spring, RecoilSpring),
                                ("recoil_damper", self.recoil_damper, RecoilDamper)):
            if not isinstance(value, cls):
                raise SceneError(key, f"must be a {cls.__name__}, got {type(value).__name__}")
        for key, value, cls in (("firing", self.firing, Firing), ("absorber", self.absorber, Absorber),
                                ("contact", self.contact, Contact), ("conventions", self.conventions, Conventions)):
            if value is not None and not isinstance(value, cls):
                raise SceneError(key, f"must be a {cls.__name__} or absent, got {type(value).__name__}")
        if self.firing is None and self.barrel.initial_velocity is None:
            raise SceneError("barrel.initial_velocity",
                             "missing: give barrel.initial_velocity (m/s) or a [firing] table")
        if self.firing is not None and self.barrel.initial_velocity is not None:
            raise SceneError("barrel.initial_velocity",
                             "give either barrel.initial_velocity or a [firing] table, not both")
        if self.absorber is not None and self.contact is None:
            raise SceneError("contact", "missing: an [absorber] needs a [contact] table (wall A drives it)")
        if self.contact is not None and self.absorber is None:
            raise SceneError("absorber", "missing: a [contact] table needs an [absorber] to touch")
        if self.conventions.v0_includes_absorber and self.firing is None:
            raise SceneError("conventions.v0_includes_absorber",
                             "needs a [firing] table (v0 is computed from the projectile momentum)")

    # ----------------------------------------------------------------------------------------
    @property
    def has_absorber(self) -> bool:
        """True for models (i) and (ii)."""
        return self.absorber is not None

    @property
    def model_label(self) -> str:
        """``"simplified"``, ``"model (i)"`` or ``"model (ii)"``."""
        if self.absorber is None:
            return "simplified"
        return "model (i)" if self.absorber.mount == "barrel" else "model (ii)"

    @property
    def initial_velocity(self) -> float:
        """Initial barrel velocity v0 in m/s (Section 2.1), honouring the active conventions.

        From a [firing] table: ``v0 = projectile momentum / M`` (``/(M + m)`` with
        ``v0_includes_absorber`` and an absorber on the barrel); with ``rounded_initial_velocity``
        the value is rounded to 0.1 m/s as the paper prints it (0.7 m/s).
        """
        if self.firing is None:
            v0 = float(self.barrel.initial_velocity)
        else:
            moving_mass = self.barrel.mass
            if (self.conventions.v0_includes_absorber and self.absorber is not None
                    and self.absorber.mount == "barrel"):
                moving_mass += self.absorber.mass
            v0 = self.firing.momentum / moving_mass
        if self.conventions.rounded_initial_velocity:
            v0 = round(v0, 1)
        return v0

    @property
    def initial_kinetic_energy(self) -> float:
        """Kinetic energy at t = 0 in J (the barrel alone moves)."""
        return 0.5 * self.barrel.mass * self.initial_velocity ** 2

    def with_changes(self, **changes) -> "Scene":
        """Return a copy with parts replaced, e.g. ``scene.with_changes(name="x")``.

        Dotted keys change one field of a part: ``scene.with_changes(**{"contact.gap": 0.04})``.
        """
        parts: dict = {}
        for key, value in changes.items():
            if "." in key:
                table, name = key.split(".", 1)
                current = parts.get(table, getattr(self, table, None))
                if current is None:
                    raise SceneError(key, f"the scene has no [{table}] table to change")
                valid = {f.name for f in fields(current)}
                if name not in valid:
                    raise SceneError(key, f"unknown field; allowed: {', '.join(sorted(valid))}")
                parts[table] = replace(current, **{name: value})
            else:
                parts[key] = value
        return replace(self, **parts)
