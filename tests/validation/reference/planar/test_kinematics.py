"""The hand-derived mass matrix, velocity terms and generalised forces against Lagrange's equations evaluated
numerically from the positions alone (central differences of the bodies' CG positions, nothing of the module's
formulas)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from validation.reference.planar.kinematics import Geometry

GEOMETRY = Geometry(carriage_mass=2000.0, carriage_inertia=1500.0, center_of_mass=(2.4, 0.8), trunnion=(2.5, 1.0),
                    barrel_offset=0.3, barrel_inertia=400.0, elevation=math.radians(25.0), gravity=9.81,
                    masses=(1000.0, 150.0))
#: a state away from every symmetry: q = (X, Y, phi, x_barrel, x_absorber), q'
Q = np.array([0.01, -0.002, 0.07, 0.4, 0.35])
QD = np.array([0.3, -0.2, 0.9, 4.0, -1.5])


def positions(q):
    """CG positions (m) of carriage, barrel, absorber written from DESIGN.md's words: P = (X, Y) + R(phi) r."""
    X, Y, phi = q[:3]
    c, s = math.cos(phi), math.sin(phi)
    e = (math.cos(GEOMETRY.elevation), math.sin(GEOMETRY.elevation))

    def place(r):
        return np.array([X + c * r[0] - s * r[1], Y + s * r[0] + c * r[1]])
    points = [place(GEOMETRY.center_of_mass)]
    for x in q[3:]:
        along = GEOMETRY.barrel_offset - x
        points.append(place((GEOMETRY.trunnion[0] + along * e[0], GEOMETRY.trunnion[1] + along * e[1])))
    return points


def jacobians(q, h=1e-6):
    """dP_k/dq (2 x n) by central differences."""
    cols = []
    for j in range(len(q)):
        dq = np.zeros(len(q))
        dq[j] = h
        cols.append([(a - b) / (2 * h) for a, b in zip(positions(q + dq), positions(q - dq))])
    return [np.array([cols[j][k] for j in range(len(q))]).T for k in range(len(cols[0]))]


def numeric_mass_matrix(q):
    masses = (GEOMETRY.carriage_mass,) + GEOMETRY.masses
    M = sum(m * J.T @ J for m, J in zip(masses, jacobians(q)))
    M[2, 2] += GEOMETRY.carriage_inertia + GEOMETRY.barrel_inertia  # both turn with phi
    return M


def test_mass_matrix_is_the_kinetic_energys_hessian():
    phi, xs = np.array([Q[2]]), [np.array([x]) for x in Q[3:]]
    M = GEOMETRY.mass_matrix(phi, xs)[..., 0]
    expected = numeric_mass_matrix(Q)
    assert np.allclose(M, M.T)
    assert np.allclose(M, expected, rtol=0, atol=1e-5 * np.abs(expected).max())
    # the coupling of the pitch with an axis body is m_i h, whatever x_i and phi (DESIGN.md's arm)
    h = GEOMETRY.trunnion[1] * math.cos(GEOMETRY.elevation) - GEOMETRY.trunnion[0] * math.sin(GEOMETRY.elevation)
    assert M[2, 3] == pytest.approx(1000.0 * h, rel=1e-12) and M[2, 4] == pytest.approx(150.0 * h, rel=1e-12)


def test_velocity_terms_are_lagranges():
    """c = (dM/dt) q' - dT/dq with T = q'^T M q' / 2, M from the positions (central differences in q)."""
    h = 1e-5
    dM = []
    for j in range(len(Q)):
        dq = np.zeros(len(Q))
        dq[j] = h
        dM.append((numeric_mass_matrix(Q + dq) - numeric_mass_matrix(Q - dq)) / (2 * h))
    Mdot = sum(dM[j] * QD[j] for j in range(len(Q)))
    dT = np.array([0.5 * QD @ dM[j] @ QD for j in range(len(Q))])
    expected = Mdot @ QD - dT
    c = GEOMETRY.velocity_terms(np.array([Q[2]]), [np.array([x]) for x in Q[3:]], np.array([QD[2]]),
                                [np.array([v]) for v in QD[3:]])[:, 0]
    assert np.allclose(c, expected, rtol=0, atol=1e-4 * np.abs(expected).max())
    assert np.abs(expected).max() > 100.0  # the case exercises the terms


def test_gravity_is_minus_the_potentials_gradient():
    h = 1e-6
    masses = (GEOMETRY.carriage_mass,) + GEOMETRY.masses

    def potential(q):
        return GEOMETRY.gravity * sum(m * p[1] for m, p in zip(masses, positions(q)))
    expected = []
    for j in range(len(Q)):
        dq = np.zeros(len(Q))
        dq[j] = h
        expected.append(-(potential(Q + dq) - potential(Q - dq)) / (2 * h))
    Qg = GEOMETRY.gravity_forces(np.array([Q[2]]), [np.array([x]) for x in Q[3:]])[:, 0]
    assert np.allclose(Qg, expected, rtol=1e-8, atol=1e-6)
    V = GEOMETRY.gravity_potential(np.array([Q[1]]), np.array([Q[2]]), [np.array([x]) for x in Q[3:]])[0]
    assert V == pytest.approx(potential(Q), rel=1e-12)


def test_breech_force_is_a_force_along_minus_e_on_the_barrel():
    """J_b^T F with F = -L R(phi) e at the barrel's CG; a shot (an impulse of it) jumps x_b' alone."""
    L = 1.0e5
    c, s = math.cos(Q[2] + GEOMETRY.elevation), math.sin(Q[2] + GEOMETRY.elevation)
    J = jacobians(Q)[1]
    expected = J.T @ np.array([-L * c, -L * s])
    Qb = GEOMETRY.axis_load(np.array([Q[2]]), [np.array([x]) for x in Q[3:]], L, 0)[:, 0]
    assert np.allclose(Qb, expected, rtol=0, atol=1e-5 * L)
    M = GEOMETRY.mass_matrix(np.array([Q[2]]), [np.array([x]) for x in Q[3:]])[..., 0]
    jump = np.linalg.solve(M, Qb)
    assert np.allclose(jump, [0, 0, 0, L / 1000.0, 0], atol=1e-9 * L / 1000.0)


def test_point_velocity_and_force_of_a_carriage_point():
    r = (2.8, 0.1)
    h = 1e-6
    X, Y, phi = Q[:3]
    p = GEOMETRY.place(X - h * QD[0], Y - h * QD[1], phi - h * QD[2], r)
    p2 = GEOMETRY.place(X + h * QD[0], Y + h * QD[1], phi + h * QD[2], r)
    v = GEOMETRY.point_velocity(phi, QD[0], QD[1], QD[2], r)
    assert np.allclose(v, [(b - a) / (2 * h) for a, b in zip(p, p2)], rtol=1e-7)
    # virtual work of a force F at the point in a rotation dphi: F . dP/dphi
    F = (300.0, 5000.0)
    dP = [(b - a) / h for a, b in zip(GEOMETRY.place(X, Y, phi, r), GEOMETRY.place(X, Y, phi + h, r))]
    assert GEOMETRY.point_force(phi, r, *F) == pytest.approx(F[0] * dP[0] + F[1] * dP[1], rel=1e-5)
