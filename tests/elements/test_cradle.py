"""Inclined cradle (mbs_models.elements.cradle, validation/reference/terms/cradle.py): gravity M g sin(theta)
along the recoil axis and Coulomb friction mu M g cos(theta) of the barrel on its slide.

Everything particular to the cradle: the table and its errors (API and command line), the Exudyn items, the
regularised friction law and its creep tolerance, the reference's exact Coulomb friction (equations, sticking),
closed forms of a block on the incline (sliding and sticking, both directions) against the engine and the
reference, a recoil that friction stops for good, the energy balance with the work of gravity, the early stop,
and the engine against the reference at every preset with the README's guarantee widened by the
regularisation's derived allowance (DESIGN.md, "Inclined cradle").
"""

from __future__ import annotations

import functools
import json
import math

import numpy as np
import pytest

from mbs_models import (Barrel, Cradle, RecoilSpring, Scene, SceneError, SolverSettings, load_scene,
                        model_ii, simplified_model, simulate)
from mbs_models.cli import main
from mbs_models.engine import final_metrics as fm
from mbs_models.engine.assembly import assemble
from mbs_models.elements import TABLES
from mbs_models.engine.stability import stable_step_limit
from mbs_models.scenes import scene_path
from validation.reference import solve_reference
from validation.reference.assembly import build_model
from validation.reference.model import Mode
from validation.studies.guarantee import TOLERANCES, energy_scale, errors_against_reference, reference_for

M, G = 5600.0, 9.81          # the paper's barrel (kg), gravity (m/s^2)
V0 = 6.86 * 564.0 / 5600.0   # the paper's v0 (m/s)
V_REG = 1e-4                 # the default friction_velocity (m/s), written out: DESIGN.md
PRESETS = ("draft", "standard", "reference")


def block(elevation: float, mu: float, v0: float, **cradle) -> Scene:
    """The barrel alone on the cradle (no spring, no damper): a block on an incline."""
    return Scene(barrel=Barrel(M, initial_velocity=v0), cradle=Cradle(elevation=elevation, friction_coefficient=mu,
                                                                      **cradle))


def friction(elevation: float, mu: float, g: float = G) -> float:
    """mu N = mu M g cos(theta) (N), written out."""
    return mu * M * g * math.cos(math.radians(elevation))


def weight_along(elevation: float, g: float = G) -> float:
    """M g sin(theta) (N), written out."""
    return M * g * math.sin(math.radians(elevation))


# ------------------------------------------------------------------ the table and its errors
CRADLE_TABLE = {"elevation": 30.0, "gravity": 9.81, "friction_coefficient": 0.05}
BAD_CRADLE = [
    ("missing-elevation", "cradle.elevation", "<delete>", "cradle.elevation", "missing"),
    ("elevation-above-90", "cradle.elevation", 90.5, "cradle.elevation", "in [-90, 90] degrees"),
    ("elevation-below-minus-90", "cradle.elevation", -91.0, "cradle.elevation", "in [-90, 90] degrees"),
    ("elevation-string", "cradle.elevation", "high", "cradle.elevation", "must be a number"),
    ("negative-gravity", "cradle.gravity", -9.81, "cradle.gravity", ">= 0 m/s^2"),
    ("gravity-bool", "cradle.gravity", True, "cradle.gravity", "must be a number"),
    ("negative-friction", "cradle.friction_coefficient", -0.05, "cradle.friction_coefficient", ">= 0"),
    ("friction-string", "cradle.friction_coefficient", "low", "cradle.friction_coefficient", "must be a number"),
    ("zero-friction-velocity", "cradle.friction_velocity", 0.0, "cradle.friction_velocity", "> 0 m/s"),
    ("negative-friction-velocity", "cradle.friction_velocity", -1e-4, "cradle.friction_velocity", "> 0 m/s"),
    ("unknown-key", "cradle.friction_coeficient", 0.05, "cradle.friction_coeficient",
     "did you mean 'friction_coefficient'"),
    ("not-a-table", "cradle", 30.0, "cradle", "must be a table"),
    # beyond double precision (DESIGN.md, "Bad input beyond the ranges"): M g sin = 5600 x 1e305 x 0.5 = 2.8e308 N
    ("weight-overflows", "cradle.gravity", 1e305, "cradle.gravity", "weight along the recoil axis"),
    # mu N / v_reg = 0.05 x 5600 x 9.81 x cos 30 / 5e-324 = inf
    ("slope-overflows", "cradle.friction_velocity", 5e-324, "cradle.friction_velocity", "slope mu N / friction_velocity"),
]


@pytest.mark.parametrize("path, value, key, text", [c[1:] for c in BAD_CRADLE], ids=[c[0] for c in BAD_CRADLE])
def test_bad_cradle_tables_are_one_line_errors_naming_the_key(bad_input, v2_mapping, changed, path, value, key, text):
    bad_input(changed({**v2_mapping, "cradle": dict(CRADLE_TABLE)}, path, value), key, text)


def test_the_cradle_needs_a_version_2_scene(bad_input, v1_mapping):
    bad_input(dict(v1_mapping, cradle=dict(CRADLE_TABLE)), "cradle", "version-2 scene")


@pytest.mark.parametrize("fields, key", [(dict(elevation=91.0), "cradle.elevation"),
                                         (dict(elevation=math.nan), "cradle.elevation"),
                                         (dict(elevation=10.0, gravity=math.inf), "cradle.gravity"),
                                         (dict(elevation=10.0, gravity=-1.0), "cradle.gravity"),
                                         (dict(elevation=10.0, friction_coefficient=-0.1),
                                          "cradle.friction_coefficient"),
                                         (dict(elevation=10.0, friction_velocity=0.0), "cradle.friction_velocity")])
def test_a_cradle_built_in_python_is_checked_like_a_file(fields, key):
    with pytest.raises(SceneError) as info:
        Cradle(**fields)
    assert info.value.key == key
    with pytest.raises(SceneError) as info:  # and through with_changes, naming the dotted key
        simplified_model().with_changes(cradle=Cradle(elevation=10.0)).with_changes(**{key: -100.0})
    assert info.value.key == key


def test_the_extreme_elevations_are_accepted_and_give_no_friction_at_90_degrees():
    """[-90, 90] degrees: a vertical cradle has no normal force (no friction connector), gravity M g."""
    for elevation, sign in ((90.0, 1.0), (-90.0, -1.0)):
        scene = block(elevation, 0.3, V0)
        assert scene.cradle.friction_force(M) == 0.0 and scene.cradle.weight_along(M) == sign * M * G
        with assemble(scene) as assembly:
            assert "cradle" not in assembly.connectors and set(assembly.loads) == {"gravity"}


# ------------------------------------------------------------------ the Exudyn items
def test_an_absent_cradle_adds_no_exudyn_item_and_a_present_one_its_two():
    plain = simplified_model()
    with assemble(plain) as assembly:
        assert "cradle" not in assembly.connectors and not assembly.loads
        objects, loads = assembly.mbs.systemData.NumberOfObjects(), assembly.mbs.systemData.NumberOfLoads()
    idle = plain.with_changes(cradle=Cradle(elevation=0.0, friction_coefficient=0.0))
    with assemble(idle) as assembly:  # level and frictionless: nothing at all
        assert (assembly.mbs.systemData.NumberOfObjects(), assembly.mbs.systemData.NumberOfLoads()) == (objects, loads)
    with assemble(load_scene(scene_path("cradle"))) as assembly:
        assert "cradle" in assembly.connectors and set(assembly.loads) == {"gravity"}
        assert assembly.mbs.systemData.NumberOfObjects() == objects + 1
        assert assembly.mbs.systemData.NumberOfLoads() == loads + 1
        item = assembly.mbs.GetObject(assembly.connectors["cradle"])
        assert item["objectType"] == "ConnectorCoordinateSpringDamperExt"  # Exudyn's own friction, no user function
        assert "cradle" not in assembly.user_function_connectors


@pytest.mark.parametrize("velocity", [-0.3, -1e-4, -3e-5, 0.0, 2e-5, 1e-4, 1.5e-4, 0.7])
def test_the_exudyn_friction_item_is_the_linear_saturated_law(velocity):
    """Exudyn's regularised friction at the barrel velocity v: mu N v / v_reg inside |v| <= v_reg, mu N sign(v)
    outside (DESIGN.md), read from Exudyn's own force output; gravity is M g sin(theta) on the barrel."""
    import exudyn

    scene = simplified_model().with_changes(cradle=Cradle(elevation=20.0, friction_coefficient=0.1))
    expected = friction(20.0, 0.1) * max(-1.0, min(1.0, velocity / V_REG))
    with assemble(scene) as assembly:
        mbs = assembly.mbs
        velocities = np.array(mbs.systemData.GetODE2Coordinates_t())
        velocities[assembly.coordinates["barrel"]] = velocity
        mbs.systemData.SetODE2Coordinates_t(velocities, configuration=exudyn.ConfigurationType.Current)
        force = mbs.GetObjectOutput(assembly.connectors["cradle"], exudyn.OutputVariableType.Force)
        assert float(np.ravel(force)[0]) == pytest.approx(expected, rel=1e-12, abs=1e-9)
        assert mbs.GetLoadParameter(assembly.loads["gravity"], "load") == pytest.approx(weight_along(20.0), rel=1e-15)


def test_a_level_frictionless_cradle_changes_nothing():
    """elevation 0, mu 0: no item, so exactly the same run as without the table."""
    plain = simplified_model()
    idle = plain.with_changes(cradle=Cradle(elevation=0.0, friction_coefficient=0.0))
    a, b = simulate(plain, 10.0), simulate(idle, 10.0)
    np.testing.assert_array_equal(a.time, b.time)
    np.testing.assert_array_equal(a.barrel_position, b.barrel_position)
    ma, mb = a.metrics(), b.metrics()
    for key in ("wall_time", "scene"):
        ma.pop(key), mb.pop(key)
    assert ma == mb


def test_friction_is_a_damper_for_the_stability_checks_of_fixed_steps():
    """In its band the law is a damper mu N / v_reg: RK44's real-axis stability limit 2.785 / lambda with
    lambda = mu N / (M v_reg) bounds the fixed step; without friction the same step is stable."""
    scene = Scene(barrel=Barrel(M, initial_velocity=V0), recoil_spring=RecoilSpring(27500.0),
                  cradle=Cradle(elevation=0.0, friction_coefficient=0.05))
    rate = friction(0.0, 0.05) / (M * V_REG)
    limit = stable_step_limit(scene, "RK44", 1.0)
    assert 2.5 / rate < limit < 2.8 / rate  # 2.785 / rate, less what the spring and the 1 % growth allow
    with pytest.raises(SceneError) as info:
        simulate(scene, 1.0, SolverSettings(solver="RK44", step=2.0 * limit))
    assert info.value.key == "step"
    frictionless = scene.with_changes(cradle=None)
    assert stable_step_limit(frictionless, "RK44", 1.0) > 100 * limit


# ------------------------------------------------------------------ the reference: DESIGN.md's equations
@pytest.mark.parametrize("elevation", [0.0, 25.0, -15.0])
def test_reference_rhs_is_the_design_equations_of_the_cradle(elevation):
    """Every friction mode, on random states: slip+ F = mu N, slip- F = -mu N, stick F = the other forces (the
    barrel's acceleration is 0); gravity M g sin(theta) on the barrel; dissipated power F v; S = k x + c v + F."""
    scene = simplified_model().with_changes(cradle=Cradle(elevation=elevation, friction_coefficient=0.2))
    model = build_model(scene)
    assert model.names == tuple(key for key in TABLES if key in {"recoil_spring", "recoil_damper", "cradle"})  # (order)
    assert [(load.name, load.body, load.value) for load in model.loads] == (
        [] if elevation == 0.0 else [("gravity", "barrel", pytest.approx(weight_along(elevation), rel=1e-15))])
    mu_n, f_g = friction(elevation, 0.2), weight_along(elevation)
    rng = np.random.default_rng(11)
    for branch in (True, False):
        c = 6239.0 if branch else 14050.0
        for state, force in (("slip+", lambda other: mu_n), ("slip-", lambda other: -mu_n),
                             ("stick", lambda other: other)):
            mode = Mode(model.names, (None, branch, state))
            scales = np.array([0.3, 1.0] + [10.0] * (model.n_states - 2))  # x, v, dissipated and work states
            batch = rng.normal(size=(model.n_states, 20)) * scales[:, None]
            for y in batch.T:
                other = -27500.0 * y[0] - c * y[1] + f_g
                F = force(other)
                # x, v; the dissipated powers of the damper and the friction; gravity's work rate F_g v
                expected = [y[1], (other - F) / M, c * y[1] ** 2, F * y[1]] + ([f_g * y[1]] if f_g else [])
                np.testing.assert_allclose(model.rhs(mode)(0.0, y), expected, rtol=1e-12, atol=1e-9)
                evaluation = model.evaluate(mode, y, t=0.3)
                assert evaluation.support == pytest.approx(27500.0 * y[0] + c * y[1] + F, rel=1e-12, abs=1e-9)
            # the same on numpy rows (post-processing: forces, the support force and its peak)
            other = -27500.0 * batch[0] - c * batch[1] + f_g
            rows = model.evaluate(mode, batch, t=np.full(batch.shape[1], 0.3))
            np.testing.assert_allclose(rows.forces[2] + 0 * batch[0], force(other), rtol=1e-12, atol=1e-9)
            np.testing.assert_allclose(rows.support, 27500.0 * batch[0] + c * batch[1] + force(other), rtol=1e-12,
                                       atol=1e-9)
            if state == "stick":
                assert model.rhs(mode)(0.0, y)[1] == 0.0  # held exactly


# ------------------------------------------------------------------ closed forms: a block on the incline
def _sliding_then_stuck(v0: float, elevation: float, mu: float):
    """x(t) of the block sliding down (v0 > 0) with tan(theta) < mu: it decelerates at b = g (mu cos - sin),
    stops at t_s = v0 / b, x_s = v0^2 / (2 b), and sticks (|M g sin| <= mu M g cos)."""
    theta = math.radians(elevation)
    b = G * (mu * math.cos(theta) - math.sin(theta))
    t_s, x_s = v0 / b, v0 ** 2 / (2 * b)
    return (lambda t: np.where(t < t_s, v0 * t - 0.5 * b * t ** 2, x_s)), t_s, x_s


def test_reference_block_slides_and_sticks_exactly():
    x_of, t_s, x_s = _sliding_then_stuck(V0, 10.0, 0.3)
    r = solve_reference(block(10.0, 0.3, V0), 3.0)
    t = np.linspace(0.0, 3.0, 3001)
    np.testing.assert_allclose(r.barrel_position(t), x_of(t), rtol=0, atol=1e-12)
    assert [s.mode["cradle"] for s in r.segments] == ["slip+", "stick"]
    assert r.segments[1].t0 == pytest.approx(t_s, rel=1e-10)
    assert np.all(r.barrel_velocity(t[t > t_s]) == pytest.approx(0.0, abs=1e-15))
    assert r.max_barrel_displacement == pytest.approx(x_s, rel=1e-12)
    # the friction dissipates the kinetic energy and the work of gravity: mu N x_s = M v0^2 / 2 + M g sin x_s
    assert r.dissipated_energy["cradle"] == pytest.approx(friction(10.0, 0.3) * x_s, rel=1e-10)
    assert r.work["gravity"] == pytest.approx(weight_along(10.0) * x_s, rel=1e-12)


@pytest.mark.parametrize("accuracy", PRESETS)
def test_engine_block_slides_like_coulomb_then_creeps_at_the_stated_rate(accuracy):
    """Sliding (|v| > v_reg) the regularised law is Coulomb: x(t) as the closed form; stuck, the block creeps
    down at v = v_reg F_g / (mu N) = v_reg tan(theta) / mu (the law's band balances gravity), at most v_reg:
    |x(t) - x_s| <= v_reg (t - t_s), the stated creep tolerance."""
    x_of, t_s, x_s = _sliding_then_stuck(V0, 10.0, 0.3)
    r = simulate(block(10.0, 0.3, V0), 3.0, accuracy)
    sliding = r.time < t_s - 0.01
    tolerance = {"draft": 1e-6, "standard": 1e-8, "reference": 1e-9}[accuracy]
    np.testing.assert_allclose(r.barrel_position[sliding], x_of(r.time[sliding]), rtol=0, atol=tolerance)
    assert r.max_barrel_displacement <= x_s + V_REG * (3.0 - t_s) + tolerance
    stuck = r.time > t_s
    creep = r.barrel_position[stuck] - x_s
    assert np.all(np.abs(creep) <= V_REG * (r.time[stuck] - t_s) + 1e-7)  # the stated tolerance
    late = r.time > t_s + 0.5  # after the band's transient: the creep rate of the closed form
    rate = np.polyfit(r.time[late], r.barrel_position[late], 1)[0]
    assert rate == pytest.approx(V_REG * math.tan(math.radians(10.0)) / 0.3, rel=1e-3)


@pytest.mark.parametrize("accuracy", PRESETS)
def test_a_block_on_a_steep_cradle_accelerates_at_g_sin_minus_mu_cos(accuracy):
    """tan(theta) > mu: x = v0 t + g (sin - mu cos) t^2 / 2, engine and reference."""
    a = G * (math.sin(math.radians(30.0)) - 0.05 * math.cos(math.radians(30.0)))
    scene = block(30.0, 0.05, V0)
    r = simulate(scene, 2.0, accuracy)
    tolerance = {"draft": 1e-5, "standard": 1e-8, "reference": 1e-9}[accuracy]
    np.testing.assert_allclose(r.barrel_position, V0 * r.time + 0.5 * a * r.time ** 2, rtol=0, atol=tolerance)
    ref = solve_reference(scene, 2.0)
    t = np.linspace(0.0, 2.0, 101)
    np.testing.assert_allclose(ref.barrel_position(t), V0 * t + 0.5 * a * t ** 2, rtol=1e-12, atol=1e-13)


def _thrown_up(v0: float, elevation: float, mu: float):
    """x(t) of the block thrown up the cradle (v0 < 0): it decelerates at g (sin + mu cos) and stops at
    t_1 = |v0| / (g (sin + mu cos)), x_1 = -v0^2 / (2 g (sin + mu cos)); then, if tan(theta) > mu, slides back
    down at g (sin - mu cos), else sticks."""
    theta = math.radians(elevation)
    up = G * (math.sin(theta) + mu * math.cos(theta))
    down = G * (math.sin(theta) - mu * math.cos(theta))
    t_1, x_1 = -v0 / up, -v0 ** 2 / (2 * up)

    def x_of(t):
        back = x_1 + 0.5 * max(down, 0.0) * (t - t_1) ** 2
        return np.where(t < t_1, v0 * t + 0.5 * up * t ** 2, back)
    return x_of, t_1, x_1


@pytest.mark.parametrize("elevation, mu", [(30.0, 0.2), (10.0, 0.3)], ids=["slides-back", "sticks"])
def test_a_block_thrown_up_the_cradle_stops_then_slides_back_or_sticks(elevation, mu):
    x_of, t_1, x_1 = _thrown_up(-1.0, elevation, mu)
    scene = block(elevation, mu, -1.0)
    ref = solve_reference(scene, 1.0)
    t = np.linspace(0.0, 1.0, 2001)
    np.testing.assert_allclose(ref.barrel_position(t), x_of(t), rtol=0, atol=1e-12)
    assert [s.mode["cradle"] for s in ref.segments] == ["slip-", "slip+" if elevation == 30.0 else "stick"]
    assert ref.segments[1].t0 == pytest.approx(t_1, rel=1e-10)
    r = simulate(scene, 1.0, "standard")
    # after the reversal the motion is late by tau h(r) (barrel_offset_bound below): a velocity offset
    # v_reg (r - 1) h(r) < v_reg; a stuck block creeps at most v_reg: both stay within v_reg (t - t_1)
    allowed = 1e-8 + np.where(r.time > t_1, V_REG * (r.time - t_1), 0.0)
    assert np.all(np.abs(r.barrel_position - x_of(r.time)) <= allowed)
    assert r.max_barrel_displacement == pytest.approx(float(np.max(x_of(t))), abs=1e-8 + V_REG * (1.0 - t_1))


# ------------------------------------------------------------------ a recoil that friction stops for good
STOPPED = simplified_model().with_changes(cradle=Cradle(elevation=30.0, friction_coefficient=0.8))


@functools.lru_cache(maxsize=None)
def engine(scene, accuracy: str = "standard"):
    """The engine's 10 s run (cached: a stiff stuck barrel costs ~2 s; two tests read the same run)."""
    return simulate(scene, 10.0, accuracy)


def test_friction_stops_the_recoil_and_the_barrel_stays_stuck():
    """mu = 0.8 at 30 deg: the barrel stops at its maximum displacement and stays there, exactly in the
    reference; in the engine within the creep tolerance v_reg (t - t_stop) over the remaining 9.8 s."""
    ref = solve_reference(STOPPED, 10.0)
    assert [s.mode["cradle"] for s in ref.segments] == ["slip+", "stick"]
    t_stop, x_stop = ref.segments[1].t0, ref.max_barrel_displacement
    # the stop is where spring, gravity and friction balance within mu N: |M g sin - k x| <= mu N
    assert abs(weight_along(30.0) - 27500.0 * x_stop) <= friction(30.0, 0.8)
    t = np.linspace(t_stop, 10.0, 1001)
    assert np.all(ref.barrel_position(t) == x_stop) and np.all(np.abs(ref.barrel_velocity(t)) <= 1e-15)
    # held by the friction: F = M g sin(theta) - k x (the other forces; the damper's is 0 at rest), on the mount
    np.testing.assert_allclose(ref.connector_force("cradle", t), weight_along(30.0) - 27500.0 * x_stop, rtol=1e-12)
    np.testing.assert_allclose(ref.support_force(t), weight_along(30.0), rtol=1e-12)  # spring + friction
    r = engine(STOPPED)
    assert r.max_barrel_displacement == pytest.approx(x_stop, abs=1e-9 + V_REG * (10.0 - t_stop))
    after = r.time >= t_stop
    drift = np.abs(r.barrel_position[after] - x_stop)
    assert np.all(drift <= V_REG * (r.time[after] - t_stop) + 1e-8)
    assert np.max(np.abs(r.barrel_velocity[r.time > t_stop + 0.05])) <= V_REG  # creeping, never sliding again
    assert np.max(np.abs(r.energy_error())) <= 5e-6 * (r.kinetic_energy_history[0] + np.max(np.abs(r.work_history)))


# ------------------------------------------------------------------ energy: element by element, with gravity's work
def test_the_energy_balance_closes_element_by_element_with_the_work_of_gravity():
    scene = load_scene(scene_path("cradle"))
    r = simulate(scene, 10.0, "standard")
    energy = r.energy()
    cradle = energy["cradle"]
    e0 = 0.5 * M * V0 ** 2
    work = weight_along(30.0) * r.barrel_position[-1]  # W = M g sin(theta) x_M(T), written out
    assert cradle["work"] == pytest.approx(work, rel=1e-12)
    assert cradle["kinetic"] == 0.0 and cradle["stored"] == 0.0 and cradle["dissipated"] > 0
    total = sum(e["kinetic"] + e["stored"] + e["dissipated"] - e.get("work", 0.0) for e in energy.values())
    assert total == pytest.approx(e0, abs=5e-6 * (e0 + abs(work)))
    history = r.dissipated_energy_history["cradle"]
    assert np.all(np.diff(history) >= -1e-9 * history[-1])  # F v >= 0: never decreasing
    # the friction's dissipated energy is mu N times the path length while sliding
    path = np.sum(np.abs(np.diff(r.barrel_position)))
    assert cradle["dissipated"] == pytest.approx(friction(30.0, 0.05) * path, rel=1e-3)
    assert np.max(np.abs(r.energy_error())) <= 5e-6 * (e0 + np.max(np.abs(r.work_history)))


def test_recoil_run_json_reports_the_cradle(capsys):
    assert main(["run", "cradle", "--end-time", "4", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["energy"]["cradle"]["dissipated"] > 0 and data["energy"]["cradle"]["work"] > 0
    assert data["dissipated_energy"]["cradle"] == data["energy"]["cradle"]["dissipated"]
    assert data["max_barrel_displacement"] > 1.0  # gravity pulls the unpreloaded barrel past 1 m


# ------------------------------------------------------------------ the early stop
@pytest.mark.parametrize("base, requested",
                         [(simplified_model(), fm.FINAL_METRICS),
                          (model_ii(1000.0, 0.0), ("max_barrel_displacement", "peak_support_force"))],
                         ids=["simplified-all", "ii-x-S"])
def test_early_stop_of_a_friction_only_scene_gives_the_full_runs_metrics(base, requested):
    """Friction alone dissipates: the energy bounds hold (the friction's force bound is mu N) and the early-stopped
    metrics are the full run's.  (A stuck barrel keeps the energy of its springs: with model (ii)'s absorber
    pressed on it for good, the contact's bounds never fall below the impact threshold, so x and S are asked.)"""
    scene = base.with_changes(cradle=Cradle(elevation=0.0, friction_coefficient=0.05))
    full = simulate(scene, 10.0)
    early = simulate(scene, 10.0, stop_when_final=requested)
    assert early.stop_reason == fm.STOP_METRICS_FINAL and early.end_time < 2.0
    assert set(requested) <= set(early.final_metrics)
    np.testing.assert_array_equal(early.barrel_position, full.barrel_position[:len(early.time)])
    for name in early.final_metrics:
        assert getattr(early, name) == getattr(full, name), name
    # friction bounds the force on the mount by mu N: it is part of the support force's bound
    bounds = fm.EnergyBounds(scene)
    without = fm.EnergyBounds(scene.with_changes(cradle=None))
    assert bounds.support_force_bound(100.0) == pytest.approx(without.support_force_bound(100.0)
                                                              + friction(0.0, 0.05), rel=1e-12)


def test_a_scene_with_gravity_never_stops_early():
    """Gravity may raise kinetic + stored energy: no bound, so the run goes to its end time, in the engine
    and in the reference."""
    scene = load_scene(scene_path("cradle"))
    early = simulate(scene, 3.0, stop_when_final=fm.FINAL_METRICS)
    assert early.stop_reason == fm.STOP_NO_BOUND and early.end_time == 3.0
    full = simulate(scene, 3.0)
    assert early.max_barrel_displacement == full.max_barrel_displacement
    mechanical = full.kinetic_energy_history + full.stored_energy_history
    assert fm.largest_energy_rise(mechanical) > 1.0  # it really rises: tenfold and more
    ref = solve_reference(scene, 3.0, stop_when_final=("max_barrel_displacement",))
    assert ref.stop_reason == "end_time_no_energy_bound" and ref.end_time == 3.0


# ------------------------------------------------------------------ the engine against the reference
def stuck_time(ref) -> float:
    """Time (s) the reference's barrel is stuck (exact Coulomb), over its window."""
    return sum(s.t1 - s.t0 for s in ref.segments if s.mode["cradle"] == "stick")


def friction_allowance(scene, ref) -> dict:
    """What the engine's regularisation may add to the README's errors (DESIGN.md, "Inclined cradle"): a stuck
    barrel creeps by at most dx = v_reg T_stuck, which shifts displacements by dx and energies by at most
    mu N dx (the friction's dissipation) plus what the creep lets the spring and gravity exchange,
    (k x_max + |F_g|) dx."""
    table = scene.cradle
    creep = table.friction_velocity * stuck_time(ref)
    k = scene.recoil_spring.stiffness if scene.recoil_spring is not None else 0.0
    mu_n = table.friction_force(scene.barrel.mass)
    energy = (mu_n + k * abs(ref.max_barrel_displacement) + abs(table.weight_along(scene.barrel.mass))) * creep
    return {"x": creep, "energy": energy}


SCENES = {
    "shipped-30deg": lambda: load_scene(scene_path("cradle")),
    "level-friction": lambda: simplified_model().with_changes(cradle=Cradle(elevation=0.0, friction_coefficient=0.05)),
    "stopped": lambda: STOPPED,
    "depressed": lambda: simplified_model().with_changes(
        cradle=Cradle(elevation=-10.0, friction_coefficient=0.1, friction_velocity=3e-4)),
}


@pytest.mark.parametrize("accuracy", PRESETS)
@pytest.mark.parametrize("key", list(SCENES))
def test_engine_agrees_with_the_exact_coulomb_reference(key, accuracy):
    """The README's guarantee, with the displacement and the dissipated energies widened by the allowance the
    regularisation is allowed (friction_allowance, derived above from the reference's stuck time); every other
    error within the README's tolerances.  Energies are relative to the guarantee's energy scale: the initial
    energy plus the largest work of gravity (the energy that flows through the mechanism)."""
    scene = SCENES[key]()
    tol = TOLERANCES[accuracy]
    result = engine(scene, accuracy)
    ref = reference_for(scene, 10.0, (), accuracy)
    errors = errors_against_reference(result, ref, tol["time"])
    allowance = friction_allowance(scene, ref)
    scale = energy_scale(result, ref.initial_energy)  # what errors_against_reference divides energies by
    assert errors["x"] <= tol["metric"] + allowance["x"] / abs(ref.max_barrel_displacement), (errors, allowance)
    assert errors["dissipated"] <= tol["metric"] + allowance["energy"] / scale, (errors, allowance)
    assert errors["energy"] <= tol["energy"], errors
    for name, bound in (("v", "metric"), ("F", "force"), ("S", "force"), ("peaks", "impact_peak"), ("time", "time")):
        assert errors[name] <= tol[bound], (name, errors)
    assert errors["impact_mismatch"] == 0, errors
    # and the allowance is not idle talk: the engine does creep where the reference sticks
    if stuck_time(ref) > 1.0:
        end = float(ref.barrel_position(np.array([10.0]))[0])
        assert 0.0 < abs(result.barrel_position[-1] - end) <= allowance["x"] + 1e-6


def barrel_offset_bound(scene, ref, t: float) -> float:
    """Bound (m) on how far the engine's barrel may be from the exact one at time ``t`` because of the
    regularisation, from the reference's modes (DESIGN.md, "Inclined cradle"), derived for a force f that is
    constant across the band |v| < v_reg:

    * a reversal (slip to slip through v = 0, r = |f| / (mu N) > 1) crosses the band slower than exact Coulomb
      switches: the regularised law's band takes tau ln((r+1)/(r-1)) (tau = M v_reg / (mu N), the band's time
      constant; v' = (f - mu N v / v_reg) / M), exact Coulomb 2 tau r / (r^2 - 1); the motion after it is late
      by tau h(r), h(r) = |ln((r+1)/(r-1)) - 2 r / (r^2 - 1)|, i.e. off by v_reg (r - 1) h(r) in velocity
      (tau mu N / M = v_reg), which grows into the position linearly;
    * while the reference is stuck the engine creeps at most v_reg.
    """
    table = scene.cradle
    v_reg, mu_n, mass = table.friction_velocity, table.friction_force(scene.barrel.mass), scene.barrel.mass
    tau = mass * v_reg / mu_n
    offset = v_reg * sum(max(0.0, min(s.t1, t) - s.t0) for s in ref.segments if s.mode["cradle"] == "stick")
    for before, after in zip(ref.segments, ref.segments[1:]):
        if {before.mode["cradle"], after.mode["cradle"]} != {"slip+", "slip-"} or after.t0 >= t:
            continue
        friction_now = mu_n if after.mode["cradle"] == "slip+" else -mu_n
        f = mass * float(ref.acceleration("barrel", np.array([after.t0 + 1e-12]))[0]) + friction_now
        r = abs(f) / mu_n
        h = abs(math.log((r + 1) / (r - 1)) - 2 * r / (r * r - 1))
        offset += v_reg * tau * h + v_reg * (r - 1) * h * (t - after.t0)
    return offset


def test_impacts_on_a_stuck_barrel_converge_to_exact_coulomb_as_the_friction_velocity_shrinks():
    """Model (ii), level, mu = 0.05: the barrel reverses once, then sticks between the absorber's late bounces,
    which hit a barrel that the reference holds exactly and the engine lets creep.  Each impact starts within
    offset / v- of the reference's (barrel_offset_bound, v-: the impact's approach rate), and every difference
    the regularisation makes is O(v_reg): a friction_velocity 4 times smaller makes the impact times and peaks
    and the dissipated energies 4 times closer (measured: 0.25)."""
    errors = {}
    exact = model_ii(1000.0, 0.0).with_changes(cradle=Cradle(elevation=0.0, friction_coefficient=0.05))
    ref = reference_for(exact, 10.0, (), "standard")  # exact Coulomb: friction_velocity plays no part in it
    for v_reg in (1e-4, 2.5e-5):
        scene = exact.with_changes(**{"cradle.friction_velocity": v_reg})
        result = simulate(scene, 10.0, "standard")
        e = errors_against_reference(result, ref, TOLERANCES["standard"]["time"])
        for name, bound in (("x", "metric"), ("v", "metric"), ("F", "force"), ("S", "force"), ("energy", "energy")):
            assert e[name] <= TOLERANCES["standard"][bound], (name, e)
        assert e["impact_mismatch"] == 0
        onsets = dict(ref.contacts["contact"].onsets)
        for ours, theirs in zip(result.contacts["contact"].impacts, ref.contacts["contact"].impacts):
            allowed = barrel_offset_bound(scene, ref, theirs.start) / onsets[theirs.start]
            assert abs(ours.start - theirs.start) <= allowed + TOLERANCES["standard"]["time"], (theirs.start, allowed)
        errors[v_reg] = e
    for name in ("time", "peaks", "dissipated"):
        assert errors[2.5e-5][name] <= 0.35 * errors[1e-4][name], (name, errors)


# ------------------------------------------------------------------ the generic tests' scenes have the cradle
def test_the_scene_of_every_element_has_the_shipped_cradle(every_element):
    """The generic tests run on scenes composed by ``every_element``: with the shipped cradle (gravity and
    friction)."""
    shipped = load_scene(scene_path("cradle")).cradle
    for base in (None, model_ii(100.0, 0.0)):
        # the shipped recuperator's 2 kN preload cannot hold the barrel at the shipped cradle's 30 degrees: the
        # composed scene leaves the cradle out, unless it is composed without the recuperator
        assert every_element(base).cradle is None
        assert every_element(base, without=("recuperator",)).cradle == shipped
    with pytest.raises(SceneError, match="cannot return the barrel to battery"):
        every_element().with_changes(cradle=shipped)
