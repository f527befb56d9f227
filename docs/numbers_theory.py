"""Numbers the theory pages quote (the numbers contract of issue #25): closed forms and the restitution relation,
each computed here from its formula (the restitution relation solved independently of the engine's solver, with
scipy's brentq), or read from the code where the page states what the code does."""

from __future__ import annotations

import math


def _v0() -> float:
    """v0 = I / M of the paper's scene (6.86 kg at 564 m/s on 5600 kg), as the scene computes it."""
    from mbs_models import model_ii

    return model_ii().initial_velocity


def _g(z: float) -> float:
    return z - math.log1p(z)


def restitution_of(chi: float) -> float:
    """The restitution e a free impact gets from the factor chi: the root in (0, min(1, 1/chi)) of
    ``g(chi) = g(-chi e)``, ``g(z) = z - ln(1 + z)`` (the relation on the theory page)."""
    from scipy.optimize import brentq

    upper = min(1.0, 1.0 / chi) * (1.0 - 1e-15)
    return brentq(lambda e: _g(-chi * e) - _g(chi), 1e-12, upper, xtol=1e-15)


def _exact_chi(e: float) -> float:
    """chi of exact-restitution for e, solved here: the root in (0, 1/e) of ``g(chi) = g(-chi e)``."""
    from scipy.optimize import brentq

    return brentq(lambda chi: _g(-chi * e) - _g(chi), 1e-9, (1.0 - 1e-12) / e, xtol=1e-15)


NUMBERS = {
    "v0_exact": {"compute": _v0, "format": "{:.4f} m/s", "rel_tol": 1e-12,
                 "why": "the paper's v0 from the exact momentum balance, m/s"},
    "ln_restitution_at_half": {"compute": lambda: restitution_of(3.0 * (1.0 - 0.25) / 4.0), "format": "{:.2f}",
                               "rel_tol": 1e-9,
                               "why": "the restitution Lankarani-Nikravesh's factor for e = 0.5 really gives"},
    "flores_restitution_at_half": {"compute": lambda: restitution_of(8.0 * (1.0 - 0.5) / (5.0 * 0.5)),
                                   "format": "{:.2f}", "rel_tol": 1e-9,
                                   "why": "the restitution Flores's factor for e = 0.5 really gives"},
    "gonthier_restitution_at_half": {"compute": lambda: restitution_of((1.0 - 0.25) / 0.5), "format": "{:.2f}",
                                     "rel_tol": 1e-9,
                                     "why": "the restitution Gonthier's factor for e = 0.5 really gives"},
    "exact_chi_at_half": {"compute": lambda: _exact_chi(0.5), "format": "{:.4f}", "rel_tol": 1e-9,
                          "why": "exact-restitution's factor chi for e = 0.5"},
}
