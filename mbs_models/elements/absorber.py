"""The impact absorber: a mass on its actuator spring-damper, driven by wall A through a contact.

Table ``[absorber]`` (version 1, with a ``[contact]`` table) or ``[[absorber]]`` with
``[absorber.contact]`` (version 2, zero or more absorbers)::

    [[absorber]]
    name = "front"          # optional: default "absorber" (one absorber), "absorber_1", ... (several)
    mass = 1000.0           # m, kg (> 0)
    mount = "ground"        # "ground" = model (ii) of the paper, "barrel" = model (i)
    stiffness = 13500.0     # k_r, N/m (>= 0)
    damping = 3675.0        # c_r, N s/m (>= 0)
    [absorber.contact]      # wall A against this absorber: gap and a contact law
    gap = 0.0
    law = "hunt-crossley"
    stiffness = 2.1e8
    exponent = 1.3
    damping_factor = 0.6

Each absorber adds a body (its name, starting at rest at x = 0), the actuator spring-damper between its
mount and the body (left out if k_r = c_r = 0), and the contact ``p = (x_M - x_m) - gap`` between the body
and the barrel (:mod:`mbs_models.elements.contact_laws`).  Force on the ground: the actuator's force of a
ground-mounted absorber; a barrel-mounted one passes everything through the barrel.

Names of outputs and energies: with one absorber those of version 1 (``absorber_damper``, ``contact``);
with several, prefixed by the absorber's name (``front_damper``, ``front_contact``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import ClassVar

from ..errors import SceneError
from .barrel import BARREL
from .connector import GROUND, Body, Connector, LinearSpringDamper
from .contact_laws import Contact, ContactConnector
from .declaration import ABSORBER
from .table import Rule, Table, check_choice, check_derived, ieee_power

#: Allowed absorber mounts: ``"barrel"`` is the paper's model (i), ``"ground"`` its model (ii).
MOUNTS = ("barrel", "ground")
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_RESERVED = ("barrel", "ground")


@dataclass(frozen=True)
class Absorber(Table):
    """The impact absorber of mass ``m`` on its actuator spring-damper ``(k_r, c_r)``.

    Attributes
    ----------
    mass: absorber mass m in kg (> 0).
    mount: ``"barrel"`` (model (i), Eqs. 4-5) or ``"ground"`` (model (ii), Eqs. 7-8).
    stiffness: actuator stiffness k_r in N/m (>= 0), 13500 N/m in Table 1.
    damping: actuator damping c_r in N s/m (>= 0), 3675 N s/m in Table 1.
    contact: its contact with wall A (:class:`~mbs_models.elements.contact_laws.Contact`); a
        version-1 scene gives it as the scene's ``contact``.
    name: identifier (letters, digits, ``_``); default ``absorber`` / ``absorber_1``, ``absorber_2``, ...
    """

    mass: float
    mount: str
    stiffness: float
    damping: float
    contact: Contact | None = None
    name: str | None = None
    TABLE: ClassVar[str] = "absorber"
    MANY: ClassVar[bool] = True
    ORDER: ClassVar[int] = 40
    RULES: ClassVar = {"mass": Rule(0.0, strict=True, unit="kg"), "stiffness": Rule(0.0, unit="N/m"),
                       "damping": Rule(0.0, unit="N s/m")}
    NESTED: ClassVar = {"contact": Contact}
    KEY_UNITS: ClassVar = {"mount": "text", "name": "text"}
    CHOICES: ClassVar = {"mount": MOUNTS}
    ROLES: ClassVar = (ABSORBER,)  # its body is an absorber, its contact an absorber's contact

    def __post_init__(self):
        super().__post_init__()
        check_choice("absorber.mount", self.mount, MOUNTS, "mount")
        if self.name is not None:
            if not isinstance(self.name, str) or not _NAME.match(self.name) or self.name in _RESERVED:
                raise SceneError("absorber.name", f"must be an identifier (a letter, then letters, digits or _), "
                                                  f"not {', '.join(_RESERVED)}; got {self.name!r}")

    @classmethod
    def from_mapping(cls, data, key, version):
        if version < 2 and isinstance(data, dict):
            for name in ("contact", "name"):
                if name in data:
                    raise SceneError(f"{key}.{name}", "needs a version-2 scene (put version = 2 at the top); "
                                                      "version 1 has the contact as a [contact] table")
        return super().from_mapping(data, key, version)

    def check_in_scene(self, scene, key: str) -> None:
        if self.contact is None:
            raise SceneError(f"{key}.contact", "missing: every absorber needs a contact with wall A "
                                               "([absorber.contact])")
        if scene.conventions.literal_gap_sign and self.contact.gap > 0.0:  # an initial interference p(0) = gap
            contact = self.contact
            n = 1.0 if contact.exponent is None else contact.exponent
            keys = {f"{key}.contact.gap": contact.gap, f"{key}.contact.stiffness": contact.stiffness}
            check_derived(keys, "the initial interference's force k gap^n (conventions.literal_gap_sign)",
                          contact.stiffness * ieee_power(contact.gap, n), "N")
            check_derived(keys, "the initial interference's elastic energy k gap^(n+1) / (n+1)",
                          contact.stiffness * ieee_power(contact.gap, n + 1.0) / (n + 1.0), "J")

    # ------------------------------------------------------------------ the element
    @staticmethod
    def connector_names(scene, name: str) -> tuple[str, str]:
        """(actuator, contact) connector names: ``absorber_damper``/``contact`` with one absorber."""
        if len(scene.absorbers) == 1:
            return "absorber_damper", "contact"
        return f"{name}_damper", f"{name}_contact"

    def bodies(self, scene, name: str) -> list[Body]:
        return [Body(name, self.mass, 0.0, element=name)]

    def connectors(self, scene, name: str) -> list[Connector]:
        actuator, contact = self.connector_names(scene, name)
        out: list[Connector] = []
        if self.stiffness > 0 or self.damping > 0:
            mount = BARREL if self.mount == "barrel" else GROUND
            out.append(LinearSpringDamper(actuator, name, mount, name, stiffness=self.stiffness, damping=self.damping))
        gap = self.contact.gap
        offset = -gap if scene.conventions.literal_gap_sign else gap
        out.append(ContactConnector(contact, name, name, BARREL, self.contact, offset, conventions=scene.conventions))
        return out
