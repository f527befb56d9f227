"""Closed-form oracles of validation.reference.closed_form, checked against their own defining equations."""

import math

import numpy as np
import pytest

from validation.reference.closed_form import _g, hunt_crossley_restitution, simplified_max_displacement

M, K, C_REC = 5600.0, 27500.0, 6239.0
V0 = 6.86 * 564.0 / 5600.0


def _trajectory(mass, k, c, v0, t):
    """x(t) of M x'' + c x' + k x = 0, x(0) = 0, x'(0) = v0 (all damping regimes), for brute-force checks."""
    w, sigma = math.sqrt(k / mass), c / (2 * mass)
    if sigma < w:
        wd = math.sqrt(w * w - sigma * sigma)
        return v0 * np.exp(-sigma * t) * np.sin(wd * t) / wd
    if sigma == w:
        return v0 * t * np.exp(-w * t)
    g = math.sqrt(sigma * sigma - w * w)
    return v0 * np.exp(-sigma * t) * np.sinh(g * t) / g


def test_paper_simplified_value_rounds_to_table2():
    x_max, t_max = simplified_max_displacement(M, K, C_REC, V0)
    assert round(x_max, 4) == 0.2215
    assert 0.6 < t_max < 0.63


@pytest.mark.parametrize("c", [C_REC, 1000.0, 2 * math.sqrt(K * M), 3e4, 2e5])
def test_maximum_matches_brute_force(c):
    x_max, t_max = simplified_max_displacement(M, K, c, V0)
    t = np.linspace(0.0, 3 * t_max, 300001)
    x = _trajectory(M, K, c, V0, t)
    i = int(np.argmax(x))
    assert x_max == pytest.approx(x[i], rel=1e-9)
    assert t_max == pytest.approx(t[i], abs=2e-5 * t_max)
    assert x_max == pytest.approx(float(_trajectory(M, K, c, V0, np.array(t_max))), rel=1e-12)


def test_critical_and_near_critical_are_continuous():
    c_crit = 2 * math.sqrt(K * M)
    x_c, t_c = simplified_max_displacement(M, K, c_crit, V0)
    w = math.sqrt(K / M)
    assert x_c == pytest.approx(V0 / (math.e * w), rel=1e-14)
    assert t_c == pytest.approx(1 / w, rel=1e-14)
    for c in (c_crit * (1 - 1e-9), c_crit * (1 + 1e-9)):
        x, t = simplified_max_displacement(M, K, c, V0)
        assert x == pytest.approx(x_c, rel=1e-7)
        assert t == pytest.approx(t_c, rel=1e-4)


def test_edge_cases():
    assert simplified_max_displacement(M, K, C_REC, 0.0) == (0.0, 0.0)
    assert simplified_max_displacement(M, K, C_REC, -0.5) == (0.0, 0.0)
    assert simplified_max_displacement(M, 0.0, C_REC, V0) == (pytest.approx(M * V0 / C_REC), math.inf)
    x, t = simplified_max_displacement(M, K, 0.0, V0)  # undamped: quarter period, v0 / w
    assert x == pytest.approx(V0 / math.sqrt(K / M), rel=1e-15)
    assert t == pytest.approx(math.pi / 2 / math.sqrt(K / M), rel=1e-15)
    with pytest.raises(ValueError):
        simplified_max_displacement(0.0, K, C_REC, V0)
    with pytest.raises(ValueError):
        simplified_max_displacement(M, -1.0, C_REC, V0)


# ------------------------------------------------------------------ Hunt-Crossley restitution
def test_no_damping_is_elastic():
    assert hunt_crossley_restitution(0.69, 0.0, 1.3) == 1.0


@pytest.mark.parametrize("lam", [1e-9, 1e-4, 0.1, 0.6, 2.0, 10.0, 1e3])
@pytest.mark.parametrize("v_in", [1e-3, 0.69, 5.0])
def test_root_solves_the_energy_integral(lam, v_in):
    e = hunt_crossley_restitution(v_in, lam, 1.3)
    u = lam * v_in
    assert 0 < e < 1
    assert e * u <= 1  # restitution ends before the force could clip: lambda v_out < 1
    if e * u < 1 - 1e-9:  # otherwise 1 - lambda v_out is below round-off (u >~ 20)
        # G(-v_out) = G(v_in) with G(v) = v/lam - ln(1 + lam v)/lam^2, i.e. g(-e u) = g(u)
        assert _g(-e * u) == pytest.approx(_g(u), rel=1e-12)
    else:
        assert e == pytest.approx(1 / u, rel=1e-12)


def test_classic_small_damping_limit():
    # Hunt & Crossley: lambda = 3 (1 - e) / (2 v_in) for small damping, i.e. e ~ 1 - 2u/3
    for u in (1e-6, 1e-4, 1e-3):
        e = hunt_crossley_restitution(1.0, u, 1.5)
        assert (1 - e) == pytest.approx(2 * u / 3, rel=2 * u)


def test_depends_on_lambda_v_only_and_decreases():
    e1 = hunt_crossley_restitution(0.5, 0.6, 1.3)
    assert hunt_crossley_restitution(0.3, 1.0, 2.0) == pytest.approx(e1, rel=1e-14)
    assert hunt_crossley_restitution(1.5, 0.2, 1.0) == pytest.approx(e1, rel=1e-14)
    es = [hunt_crossley_restitution(1.0, lam, 1.3) for lam in (0.1, 0.5, 1.0, 3.0, 30.0)]
    assert all(a > b for a, b in zip(es, es[1:]))


def test_series_branch_is_continuous():
    for z in (-1e-3, 1e-3):
        assert _g(z * (1 - 1e-12)) == pytest.approx(z - math.log1p(z), rel=1e-9)


def test_negative_lambda_literal_sign_injects_energy():
    e = hunt_crossley_restitution(0.69, -0.6, 1.3)
    u = -0.6 * 0.69
    assert e > 1
    assert _g(-e * u) == pytest.approx(_g(u), rel=1e-12)
    with pytest.raises(ValueError):
        hunt_crossley_restitution(2.0, -0.6, 1.3)  # 1 + lambda v_in <= 0: no force at all


def test_bad_inputs():
    with pytest.raises(ValueError):
        hunt_crossley_restitution(0.0, 0.6, 1.3)
    with pytest.raises(ValueError):
        hunt_crossley_restitution(1.0, 0.6, 0.0)
    with pytest.raises(ValueError):
        hunt_crossley_restitution(1.0, math.nan, 1.3)
