#!/usr/bin/env python
"""A check against a real design: the M109's recoil brake from its published figures (``python scripts/m109_check.py``).

Inputs (DTIC ADA089005, "furnished by ARRADCOM for design purposes", ../shared/references/recoil-data.md 1.2):
recoiling weight 9,600 lb (4,354.5 kg), projectile 98 lb (44.45 kg) at 3,250 ft/s (990.6 m/s), propellant 40 lb
(18.14 kg), a constant-resistance recoil of 21 in (0.5334 m), recoil-cylinder pressure "over 6,000 psi"
(41.4 MPa); and the M109A1's variable recoil, 36 in (0.9144 m) below 45 degrees and 24 in (0.6096 m) above
(recoil-data.md 1.1).  The vehicle is not modelled (a self-propelled gun: the cradle on a 1-D mount).

The gas after-effect's convention is the one number the sources do not give; three common readings are run,
each an explicit input (the free-recoil momentum ``I = m_p v_p + m_c v_gas``):

* ``in-bore only``: the charge moves with half the projectile's speed on average: ``v_gas = v_p / 2``;
* ``1.5 v_p``: the gas leaves the muzzle at 1.5 times the projectile's speed (a textbook value);
* ``4,700 ft/s``: the US Army's customary gas velocity for the after-effect (1,432.6 m/s).

For each: the free-recoil velocity ``v0 = I / M``, energy ``E = M v0^2 / 2``, the constant resistance the energy
implies over 21 in, ``R = E / L``, and ``recoil design-brake``'s simulated brake for 21 in (its resistance and the
brake force's share of it); the brake pressure ``p = F_brake / A`` needs the piston area, which the source does not
give: the piston area at which the designed resistance R is 6,000 psi is printed instead (two cylinders share it; the
recuperator's share of R, ~34 kN, is not deducted).
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

INCH, POUND, FOOT = 0.0254, 0.45359237, 0.3048
RECOILING_MASS = 9600 * POUND
PROJECTILE_MASS, MUZZLE_VELOCITY, CHARGE_MASS = 98 * POUND, 3250 * FOOT, 40 * POUND
RECOIL = 21 * INCH
PRESSURE = 6000 * 6894.757  # Pa
CONVENTIONS = {"in-bore only (v_gas = v_p / 2)": MUZZLE_VELOCITY / 2, "1.5 v_p": 1.5 * MUZZLE_VELOCITY,
               "4,700 ft/s": 4700 * FOOT}


def m109_scene(gas_velocity: float):
    """The M109 on a 1-D mount: its barrel, the shot, a brake (its piston area a placeholder: the design's forces do
    not depend on it, only its pressure does), a recuperator (700 psi) and a battery buffer."""
    from mbs_models.scene.io import scene_from_dict

    return scene_from_dict({"version": 2, "name": f"M109, gas at {gas_velocity:.1f} m/s",
                            "barrel": {"mass": RECOILING_MASS},
                            "firing": {"projectile_mass": PROJECTILE_MASS, "muzzle_velocity": MUZZLE_VELOCITY,
                                       "charge_mass": CHARGE_MASS, "gas_velocity": gas_velocity},
                            "recoil_brake": {"piston_area": 0.03, "orifice_area": 1e-3,
                                             "discharge_coefficient": 0.7, "fluid_density": 870.0},
                            # the M109's 700 psi nitrogen charge (recoil-data.md 1.1) on an assumed 0.01 m^2 piston
                            # and 0.05 m^3 of gas: what returns the barrel (its share of R is in the design)
                            "recuperator": {"initial_pressure": 700 * 6894.757, "piston_area": 0.01,
                                            "gas_volume": 0.05, "polytropic_exponent": 1.3},
                            "battery_stop": {"position": 0.0, "law": "kelvin-voigt", "stiffness": 5e7,
                                             "damping": 2e5}})


def check(gas_velocity: float, recoil: float = RECOIL) -> dict:
    from mbs_models.studies.brake_length import hit_recoil_length

    scene = m109_scene(gas_velocity)
    momentum = PROJECTILE_MASS * MUZZLE_VELOCITY + CHARGE_MASS * gas_velocity
    v0 = momentum / RECOILING_MASS
    energy = 0.5 * RECOILING_MASS * v0 ** 2
    length = hit_recoil_length(scene, recoil, end_time=3.0)
    return {"gas_velocity": gas_velocity, "momentum": momentum, "v0": v0, "energy": energy,
            "implied_resistance": energy / recoil, "designed_resistance": length.design.resistance,
            "recoil": length.recoil_length, "area_at_6000_psi": length.design.resistance / PRESSURE}


def main() -> int:
    print(f"M109: M = {RECOILING_MASS:.1f} kg, projectile {PROJECTILE_MASS:.2f} kg at {MUZZLE_VELOCITY:.1f} m/s, charge "
          f"{CHARGE_MASS:.2f} kg, recoil {RECOIL:.4f} m (21 in)")
    for name, gas in CONVENTIONS.items():
        r = check(gas)
        print(f"  gas after-effect {name:32s} I = {r['momentum']:8.0f} N s, v0 = {r['v0']:5.2f} m/s, E = "
              f"{r['energy'] / 1e3:6.1f} kJ; R = E/L = {r['implied_resistance'] / 1e3:7.1f} kN; designed "
              f"{r['designed_resistance'] / 1e3:7.1f} kN over a simulated {r['recoil'] * 1e3:.1f} mm; R at 6,000 psi "
              f"needs {r['area_at_6000_psi'] * 1e4:.0f} cm^2 of piston")
    gas = CONVENTIONS["4,700 ft/s"]
    for inches in (36, 24):
        r = check(gas, inches * INCH)
        print(f"  M109A1, {inches} in ({'below' if inches == 36 else 'above'} 45 deg), 4,700 ft/s: designed R = "
              f"{r['designed_resistance'] / 1e3:.1f} kN; R at 6,000 psi needs {r['area_at_6000_psi'] * 1e4:.0f} cm^2")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
