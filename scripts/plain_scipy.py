"""The paper's model (ii) as an engineer would write it with scipy: the yardstick of ``scripts/bench_scipy.py``.

Written from the equations (DESIGN.md, "Bodies and connectors" and "Contact laws"), numpy and scipy only, no
project code::

    M x_M'' = -k x_M - c(v_M) v_M - F_c          c = c_recoil if v_M > 0 else c_counter
    m x_m'' = -k_r x_m - c_r v_m + F_c           (the absorber's actuator is tied to the ground)
    p = x_M - x_m - gap;   F_c = max(k_c p^n (1 + lambda p'), 0) while p > 0, else 0   (Hunt-Crossley)
    x_M(0) = x_m(0) = 0,   v_M(0) = m_p v_p / M,   v_m(0) = 0

with the numbers of the paper (Section 2.1, Table 1): M = 5600 kg, k = 27500 N/m, c = 6239 / 14050 N s/m,
a 6.86 kg projectile at 564 m/s, k_r = 13500 N/m, c_r = 3675 N s/m, k_c = 2.1e8 N/m^1.3, n = 1.3,
lambda = 0.6 s/m.

One run is ``solve_ivp`` with dense output, then the three metrics: the largest sample of the solver's own steps
(the barrel position, the absorber velocity, the contact force computed from the states), refined by a bounded
scalar search on the dense output between the neighbouring steps (or the same on a uniform grid of the dense
output, ``grid_spacing``: the same values, at the cost of evaluating the dense output on every step).
``max_step`` is solve_ivp's default (none) unless given: the plain script finds the same impacts as the reference
(``scripts/bench_scipy.py`` checks it).

    python scripts/plain_scipy.py [METHOD] [RTOL]
"""

from __future__ import annotations

import sys

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

BARREL_MASS = 5600.0                     # M, kg
RECOIL_STIFFNESS = 27500.0               # k, N/m
RECOIL_DAMPING = 6239.0                  # c while v_M > 0, N s/m
COUNTER_RECOIL_DAMPING = 14050.0         # c while v_M <= 0, N s/m
INITIAL_VELOCITY = 6.86 * 564.0 / 5600.0  # v0 = m_p v_p / M, m/s
ABSORBER_STIFFNESS = 13500.0             # k_r, N/m
ABSORBER_DAMPING = 3675.0                # c_r, N s/m
CONTACT_STIFFNESS = 2.1e8                # k_c, N/m^n
CONTACT_EXPONENT = 1.3                   # n
CONTACT_DAMPING_FACTOR = 0.6             # lambda, s/m


def model_ii(absorber_mass: float = 1000.0, gap: float = 0.0):
    """Right-hand side ``f(t, y)`` of y = [x_M, v_M, x_m, v_m] (m, m/s) and the contact force F_c(y) (N) of
    states of shape (4, N), for an absorber of ``absorber_mass`` kg at ``gap`` m."""
    M, k, c_rec, c_cnt = BARREL_MASS, RECOIL_STIFFNESS, RECOIL_DAMPING, COUNTER_RECOIL_DAMPING
    m, kr, cr = absorber_mass, ABSORBER_STIFFNESS, ABSORBER_DAMPING
    kc, n, lam = CONTACT_STIFFNESS, CONTACT_EXPONENT, CONTACT_DAMPING_FACTOR

    def rhs(t, y):
        x, v, xa, va = y
        p = x - xa - gap
        force = 0.0
        if p > 0:
            force = max(kc * p ** n * (1.0 + lam * (v - va)), 0.0)
        c = c_rec if v > 0 else c_cnt
        return [v, (-k * x - c * v - force) / M, va, (-kr * xa - cr * va + force) / m]

    def contact_force(y):
        p = np.maximum(y[0] - y[2] - gap, 0.0)
        return np.where(p > 0, np.maximum(kc * p ** n * (1.0 + lam * (y[1] - y[3])), 0.0), 0.0)

    return rhs, contact_force


def refined_max(f, t, values):
    """The largest of ``values`` (samples of ``f`` at times ``t``), refined by a bounded search of ``f``
    between the neighbouring samples: (value, time)."""
    i = int(np.argmax(values))
    lo, hi = t[max(i - 1, 0)], t[min(i + 1, len(t) - 1)]
    best = minimize_scalar(lambda s: -f(s), bounds=(lo, hi), method="bounded", options={"xatol": 1e-12})
    if -best.fun > values[i]:
        return -best.fun, best.x
    return values[i], t[i]


def run(method: str = "RK45", rtol: float = 1e-6, atol: float | None = None, max_step: float = np.inf,
        absorber_mass: float = 1000.0, gap: float = 0.0, end_time: float = 10.0,
        grid_spacing: float | None = None) -> dict:
    """One complete run: integrate, then the metrics (m, N, m/s); also ``steps``, ``evaluations`` (of ``f``, as
    ``sol.nfev`` counts them), the dense output ``dense``
    (a callable of t) and the contact-force function ``contact_force``, for checks.  The maxima are searched on
    the solver's steps, or with ``grid_spacing`` (s) on a uniform grid of the dense output."""
    rhs, contact_force = model_ii(absorber_mass, gap)
    atol = rtol * 1e-2 if atol is None else atol
    sol = solve_ivp(rhs, (0.0, end_time), [0.0, INITIAL_VELOCITY, 0.0, 0.0], method=method, rtol=rtol, atol=atol,
                    max_step=max_step, dense_output=True)
    if not sol.success:
        raise RuntimeError(f"solve_ivp {method} failed: {sol.message}")
    t, y, dense = sol.t, sol.y, sol.sol
    if grid_spacing is not None:
        t = np.linspace(0.0, end_time, int(round(end_time / grid_spacing)) + 1)
        y = dense(t)
    force = contact_force(y)
    x_max, _ = refined_max(lambda s: dense(s)[0], t, y[0])
    v_max, _ = refined_max(lambda s: dense(s)[3], t, y[3])
    f_max, _ = refined_max(lambda s: contact_force(dense(s)[:, None])[0], t, force)
    return {"max_barrel_displacement": float(x_max), "peak_contact_force": float(f_max),
            "max_absorber_velocity": float(v_max), "steps": len(sol.t) - 1, "evaluations": int(sol.nfev),
            "dense": dense, "contact_force": contact_force}


if __name__ == "__main__":
    result = run(*(sys.argv[1:2] or ["RK45"]), *[float(a) for a in sys.argv[2:3]])
    print({k: v for k, v in result.items() if k not in ("dense", "contact_force")})
