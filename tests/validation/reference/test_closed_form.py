"""Closed-form oracles of validation.reference.closed_form, checked against their own defining equations."""

import math

import numpy as np
import pytest

from scipy.integrate import solve_ivp

from validation.reference.closed_form import (_g, achieved_restitution, exact_restitution_factor,
                                              hunt_crossley_restitution, kelvin_voigt_restitution, restitution_factor,
                                              simplified_max_displacement)

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


# ------------------------------------------------------------------ restitution laws
RESTITUTIONS = [0.05, 0.3, 0.5, 0.8, 0.99]


def test_restitution_factors_are_designs_formulas():
    assert restitution_factor("lankarani-nikravesh", 0.5) == 0.75 * 0.75
    assert restitution_factor("flores", 0.5) == pytest.approx(8 * 0.5 / 2.5, rel=1e-15)
    assert restitution_factor("gonthier", 0.5) == pytest.approx(0.75 / 0.5, rel=1e-15)
    for law in ("lankarani-nikravesh", "flores", "gonthier", "exact-restitution"):
        assert restitution_factor(law, 1.0) == 0.0
    with pytest.raises(ValueError, match="not a restitution law"):
        restitution_factor("hertz", 0.5)
    for bad in (0.0, 1.5, math.nan):
        with pytest.raises(ValueError, match="restitution"):
            restitution_factor("flores", bad)


@pytest.mark.parametrize("e", RESTITUTIONS + [1e-3, 0.999999])
def test_exact_restitution_factor_solves_its_relation(e):
    chi = exact_restitution_factor(e)
    assert 0 < chi <= 1 / e  # = 1/e to round-off when 1 - chi e underflows (e = 1e-3: 1 - chi e ~ e^-1000)
    if chi * e < 1 - 1e-6:
        # chi - ln(1 + chi) = -chi e - ln(1 - chi e), written without the helper g
        lhs, rhs = chi - math.log1p(chi), -chi * e - math.log1p(-chi * e)
        assert lhs == pytest.approx(rhs, rel=1e-9)
    else:  # 1 - chi e is below what the relation resolves in floating point: chi is 1/e to round-off
        assert chi * e == pytest.approx(1.0, abs=1e-6)
    assert hunt_crossley_restitution(1.0, chi, 1.5) == pytest.approx(e, rel=1e-12)
    assert restitution_factor("exact-restitution", e) == chi


@pytest.mark.parametrize("e", RESTITUTIONS)
def test_achieved_restitution_of_the_restitution_laws(e):
    for law in ("lankarani-nikravesh", "flores", "gonthier", "exact-restitution"):
        chi = restitution_factor(law, e)
        achieved = achieved_restitution(law, e)
        assert 0 < achieved < min(1.0, 1 / chi)  # a free impact never clips
        margin = 1 - achieved * chi  # g(-e chi) amplifies round-off by 1/margin
        if margin > 1e-9:
            assert _g(-achieved * chi) == pytest.approx(_g(chi), rel=max(1e-12, 1e-14 / margin))  # the docstring's
        else:  # 1 - e chi below round-off of the relation (flores at 0.05: chi = 30.4): e is 1/chi
            assert achieved == pytest.approx(1 / chi, rel=1e-9)
        # the law is Hunt-Crossley with lambda = chi / v-: any v- gives the same e
        assert achieved == pytest.approx(hunt_crossley_restitution(0.37, chi / 0.37, 1.3), rel=1e-13)
    assert achieved_restitution("exact-restitution", e) == pytest.approx(e, rel=1e-13)


def test_lankarani_nikravesh_gives_about_073_for_05():
    assert achieved_restitution("lankarani-nikravesh", 0.5) == pytest.approx(0.73, abs=0.01)


def test_achieved_restitution_of_the_other_laws():
    assert achieved_restitution("hertz") == 1.0
    assert achieved_restitution("hunt-crossley", lambda_v=0.6 * 0.69) == hunt_crossley_restitution(0.69, 0.6, 1.3)
    assert achieved_restitution("kelvin-voigt", damping_ratio=0.2) == kelvin_voigt_restitution(0.2, clipped=True)
    with pytest.raises(ValueError, match="lambda_v"):
        achieved_restitution("hunt-crossley")
    with pytest.raises(ValueError, match="damping_ratio"):
        achieved_restitution("kelvin-voigt", 0.5)
    with pytest.raises(ValueError, match="asked for"):
        achieved_restitution("flores")
    with pytest.raises(ValueError, match="unknown"):
        achieved_restitution("coulomb", 0.5)


def _kelvin_voigt_impact(zeta, clipped):
    """-p'_out / v- of m p'' = -k p - c p' from p = 0, p' = 1, integrated with solve_ivp (m = k = 1): until
    the force k p + c p' reaches 0 (clipped; afterwards nothing acts) or p returns to 0 (unclipped)."""
    c = 2 * zeta

    def force(t, y):
        return y[0] + c * y[1]

    def apart(t, y):
        return y[0]
    force.terminal = apart.terminal = True
    force.direction = apart.direction = -1
    sol = solve_ivp(lambda t, y: [y[1], -y[0] - c * y[1]], (0, 200), [0.0, 1.0], rtol=1e-12, atol=1e-14,
                    events=[force] if clipped else [apart])
    if not clipped and sol.status == 0:
        return 0.0
    return -sol.y[1, -1]


@pytest.mark.parametrize("zeta", [0.01, 0.2, 0.6, 0.95, 1.0, 1.3, 4.0])
def test_kelvin_voigt_restitution_matches_the_oscillator(zeta):
    assert kelvin_voigt_restitution(zeta) == pytest.approx(_kelvin_voigt_impact(zeta, True), rel=1e-8)
    if zeta < 1:
        assert kelvin_voigt_restitution(zeta, clipped=False) == pytest.approx(_kelvin_voigt_impact(zeta, False),
                                                                              rel=1e-8)
        assert kelvin_voigt_restitution(zeta, clipped=False) == pytest.approx(
            math.exp(-zeta * math.pi / math.sqrt(1 - zeta * zeta)), rel=1e-14)
        assert kelvin_voigt_restitution(zeta) > kelvin_voigt_restitution(zeta, clipped=False)


def test_kelvin_voigt_restitution_limits():
    assert kelvin_voigt_restitution(0.0) == 1.0 and kelvin_voigt_restitution(0.0, clipped=False) == 1.0
    assert kelvin_voigt_restitution(2.0, clipped=False) == 0.0
    for z in (1 - 1e-9, 1 + 1e-9):
        assert kelvin_voigt_restitution(z) == pytest.approx(math.exp(-2), rel=1e-8)
    es = [kelvin_voigt_restitution(z) for z in (0.1, 0.5, 1.0, 2.0, 10.0, 100.0)]
    assert all(a > b for a, b in zip(es, es[1:]))
    with pytest.raises(ValueError):
        kelvin_voigt_restitution(-0.1)
