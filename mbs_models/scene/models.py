"""Ready-made scenes: the paper's three models with Table 1 parameters.

All three start from the same barrel: M = 5600 kg, recoil spring k = 27500 N/m, asymmetric damper
c = 6239 / 14050 N s/m (Eqs. 2-3), fired by a 6.86 kg projectile at 564 m/s (v0 = 0.6909 m/s).
The shipped TOML files in ``mbs_models/scenes/`` hold the same values for m = 1000 kg, gap 0.
"""

from __future__ import annotations

from ..elements.absorber import Absorber
from ..elements.barrel import Barrel
from ..elements.contact_laws import Contact
from ..elements.firing import Firing
from ..elements.recoil_damper import RecoilDamper
from ..elements.recoil_spring import RecoilSpring
from .container import Conventions, Scene

#: Barrel mass M, kg (Section 2.1).
PAPER_BARREL_MASS = 5600.0
#: Projectile mass, kg, and muzzle velocity, m/s (Section 2.1).
PAPER_PROJECTILE_MASS = 6.86
PAPER_MUZZLE_VELOCITY = 564.0
#: Recoil spring stiffness k, N/m (Section 2.1).
PAPER_RECOIL_STIFFNESS = 27500.0
#: Recoil damper c, N s/m, Eqs. (2) and (3).
PAPER_RECOIL_DAMPING = 6239.0
PAPER_COUNTER_RECOIL_DAMPING = 14050.0
#: Table 1: actuator k_r (N/m), c_r (N s/m), contact k_c (N/m^1.3), n_c, lambda_c (s/m).
PAPER_ABSORBER_STIFFNESS = 13500.0
PAPER_ABSORBER_DAMPING = 3675.0
PAPER_CONTACT_STIFFNESS = 2.1e8
PAPER_CONTACT_EXPONENT = 1.3
PAPER_CONTACT_DAMPING_FACTOR = 0.6
#: Absorber masses of Table 2, kg.
PAPER_ABSORBER_MASSES = (100.0, 500.0, 1000.0)


def _barrel_parts(conventions: Conventions | None) -> dict:
    return dict(
        barrel=Barrel(mass=PAPER_BARREL_MASS),
        firing=Firing(projectile_mass=PAPER_PROJECTILE_MASS, muzzle_velocity=PAPER_MUZZLE_VELOCITY),
        recoil_spring=RecoilSpring(stiffness=PAPER_RECOIL_STIFFNESS),
        recoil_damper=RecoilDamper(recoil=PAPER_RECOIL_DAMPING, counter_recoil=PAPER_COUNTER_RECOIL_DAMPING),
        conventions=conventions or Conventions(),
    )


def simplified_model(conventions: Conventions | None = None) -> Scene:
    """The simplified recoil mechanism of Fig. 1, Eq. (1)::

            k (recoil spring)
        |--/\\/\\/\\--+------+
        |           |  M   |---> x_M   (v0 from the shot)
        |---[ c ]---+------+
        ground   c = 6239 (x_M' > 0) / 14050 (x_M' < 0) N s/m

    with Table 1's barrel, recoil spring and recoil damper.
    """
    return Scene(name="simplified model", **_barrel_parts(conventions))


def _contact(gap: float) -> Contact:
    return Contact(gap=gap, stiffness=PAPER_CONTACT_STIFFNESS, exponent=PAPER_CONTACT_EXPONENT,
                   damping_factor=PAPER_CONTACT_DAMPING_FACTOR)


def _absorber(mass: float, mount: str) -> Absorber:
    return Absorber(mass=mass, mount=mount, stiffness=PAPER_ABSORBER_STIFFNESS, damping=PAPER_ABSORBER_DAMPING)


def model_i(absorber_mass: float = 1000.0, gap: float = 0.0, conventions: Conventions | None = None) -> Scene:
    """Model (i), Fig. 2, Eqs. (4)-(5): the absorber rides on the barrel::

            k, c                  barrel M (moves with x_M)
        |--/\\/\\--+=====================================+
        |         |  wall A   gap     k_r, c_r          |
        |--[ c ]--+   |<---->[ m ]--/\\/\\--[ c_r ]------| (fixed to the barrel)
        ground    +=====================================+
                      Hunt-Crossley contact k_c, n_c, lambda

    Parameters
    ----------
    absorber_mass: m in kg (Table 2 uses 100, 500, 1000).
    gap: clearance between wall A and the absorber in m (Fig. 4 sweeps 0-0.12).
    """
    return Scene(name=f"model (i), m = {absorber_mass:g} kg, gap {gap * 1000:g} mm",
                 absorber=_absorber(absorber_mass, "barrel"), contact=_contact(gap), **_barrel_parts(conventions))


def model_ii(absorber_mass: float = 1000.0, gap: float = 0.0, conventions: Conventions | None = None) -> Scene:
    """Model (ii), Fig. 3, Eqs. (7)-(8): the absorber is tied to the ground::

            k, c            barrel M
        |--/\\/\\--+--------------+ wall A  gap          k_r, c_r
        |         |      M       |<---->[ m ]--/\\/\\--[ c_r ]--|
        |--[ c ]--+--------------+                             | ground
        ground                     Hunt-Crossley contact k_c, n_c, lambda

    Parameters
    ----------
    absorber_mass: m in kg (Table 2 uses 100, 500, 1000).
    gap: clearance between wall A and the absorber in m (Fig. 5 sweeps 0-0.12).
    """
    return Scene(name=f"model (ii), m = {absorber_mass:g} kg, gap {gap * 1000:g} mm",
                 absorber=_absorber(absorber_mass, "ground"), contact=_contact(gap), **_barrel_parts(conventions))


def paper_model(model: str, absorber_mass: float = 1000.0, gap: float = 0.0,
                conventions: Conventions | None = None) -> Scene:
    """One of the paper's models by label: ``"simplified"``, ``"i"`` or ``"ii"``."""
    key = model.strip().lower().replace("model", "").strip(" ()")
    if key == "simplified":
        return simplified_model(conventions)
    if key == "i":
        return model_i(absorber_mass, gap, conventions)
    if key == "ii":
        return model_ii(absorber_mass, gap, conventions)
    from ..errors import SceneError
    raise SceneError("model", f"unknown model {model!r}; allowed: 'simplified', 'i', 'ii'")
