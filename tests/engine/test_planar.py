"""The planar model in the engine (mbs_models/engine/planar.py): what is assembled, and closed forms it must meet.

Every expected value here comes from statics or DESIGN.md's quasi-static closed form (written out in the tests),
or from the 1-D engine on the same hardware -- never from the planar engine itself.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import mbs_models as m
from mbs_models.engine.assembly import assemble
from mbs_models.scene.io import load_scene, scene_from_dict, scene_to_dict
from mbs_models.scene.models import model_ii, simplified_model
from mbs_models.elements.carriage import Carriage

from carriage_scenes import BASE, SCENES_DIR, carriage_scene

G = 9.81
#: BASE's geometry (tests/carriage_scenes.py): carriage 2000 kg at x = 2.4, trunnion (2.5, 1.0), wheels at 2.8.
CARRIAGE_MASS, CARRIAGE_X, TRUNNION, FRONT_X = 2000.0, 2.4, (2.5, 1.0), 2.8


def _object_types(assembly) -> list[str]:
    mbs = assembly.mbs
    return [mbs.GetObject(i)["objectType"] for i in range(mbs.systemData.NumberOfObjects())]


# ================================================================================================ assembly
def test_a_scene_without_carriage_assembles_no_planar_item():
    with assemble(model_ii(1000.0, 0.0)) as assembly:
        types = _object_types(assembly)
        assert assembly.planar is None and not assembly.columns
        assert "KinematicTree" not in types and "ConnectorCartesianSpringDamper" not in types
        assert all(t in ("Mass1D", "ConnectorCoordinateSpringDamper") for t in types), types


def test_a_carriage_scene_is_one_tree_with_its_supports_in_the_tree():
    """One KinematicTree holds the carriage and every axis body; the supports act through its force user function
    (no connector of their own); the 1-D elements stay coordinate connectors on the tree's coordinates."""
    scene = carriage_scene(absorber=[{"name": "buffer", "mass": 200.0, "mount": "ground", "stiffness": 13500.0,
                                      "damping": 3675.0, "contact": {"law": "hertz", "gap": 0.01,
                                                                     "stiffness": 1e8, "exponent": 1.5}}])
    with assemble(scene) as assembly:
        types = _object_types(assembly)
        assert types.count("KinematicTree") == 1
        assert "Mass1D" not in types and "ConnectorCartesianSpringDamper" not in types
        assert assembly.mbs.GetObject(types.index("KinematicTree"))["forceUserFunction"] != 0
        data = assembly.mbs.systemData
        assert data.ODE2Size() == 3 + 2  # X, Y, pitch, barrel, absorber
        assert sorted(assembly.coordinates.values()) == [3, 4]


# ================================================================================================ statics
def _lever_rule_front_load(total_mass: float, moment: float) -> float:
    """The front support's load (N) of a gun on a spade at x = 0 and rigid wheels at FRONT_X: moments about the
    spade, ``N_f x_f = g sum m x``."""
    return G * moment / FRONT_X


def test_static_loads_are_the_lever_rule_and_the_gun_stays_at_rest():
    stiff = {"carriage.support.0.stiffness": 1e11, "carriage.support.0.damping": 1e8,
             "carriage.support.1.stiffness": 1e11, "carriage.support.1.damping": 1e8, "barrel.initial_velocity": 0.0}
    result = m.simulate(carriage_scene(stiff), end_time=0.5)
    total = CARRIAGE_MASS + 1000.0
    moment = CARRIAGE_MASS * CARRIAGE_X + 1000.0 * TRUNNION[0]
    front = _lever_rule_front_load(total, moment)
    loads = {s["name"]: s for s in result.supports}
    # rigid-support statics; the supports' compliance pitches the carriage by ~1e-7 rad: 1e-6 relative
    assert loads["wheels"]["static_normal_force"] == pytest.approx(front, rel=1e-6)
    assert loads["spade"]["static_normal_force"] == pytest.approx(G * total - front, rel=1e-6)
    for name, output in result.carriage.supports.items():  # no shot: it stays in its equilibrium
        assert np.max(np.abs(output.normal_force - loads[name]["static_normal_force"])) < 1e-6 * G * total
    assert result.stability_margin == pytest.approx(1.0, abs=1e-6)
    assert result.max_carriage_pitch < 1e-9 and result.max_lift == 0.0 and result.lift_off_time is None


# ================================================================================================ quasi-static
@pytest.mark.parametrize("elevation", [0.0, 20.0, 50.0])
@pytest.mark.parametrize("with_absorber", [False, True])
def test_front_load_follows_the_quasi_static_closed_form(elevation, with_absorber):
    """DESIGN.md's front load, with absorbers: moments about the spade of the whole gun, whose axis bodies
    accelerate along the axis (line through the trunnion: r x (-e) = h for every body) give

        N_f x_f = g (m_tot d - sum_j m_j x_j cos th) - (R - g sin th sum_j m_j) h(th)

    (R: the force the elements transmit to the cradle, ``support_force``; a breech force's moment cancels with its
    share of the bodies' accelerations).  It holds while the carriage rests: after the first 0.05 s (the carriage's
    response to the damper's step at the shot) to 5e-4 of the static load (the supports' compliance pitches the
    carriage by ~1e-4 rad; the closed form takes it rigid)."""
    tables = {}
    bodies = {"barrel": 1000.0}
    if with_absorber:
        tables["absorber"] = [{"name": "buffer", "mass": 200.0, "mount": "ground", "stiffness": 13500.0,
                               "damping": 3675.0, "contact": {"law": "kelvin-voigt", "gap": 0.0, "stiffness": 1e5,
                                                              "damping": 1e3}}]
        bodies["buffer"] = 200.0
    scene = carriage_scene({"cradle.elevation": elevation, "barrel.initial_velocity": 1.0}, **tables)
    result = m.simulate(scene, end_time=1.0)
    theta = math.radians(elevation)
    h = TRUNNION[1] * math.cos(theta) - TRUNNION[0] * math.sin(theta)
    axis_mass = sum(bodies.values())
    battery_moment = CARRIAGE_MASS * CARRIAGE_X + axis_mass * TRUNNION[0]
    shift = sum(mass * result.positions[name] for name, mass in bodies.items())
    expected = (G * (battery_moment - shift * math.cos(theta))
                - (result.support_force - G * math.sin(theta) * axis_mass) * h) / FRONT_X
    front = result.carriage.supports["wheels"]
    later = result.time > 0.05
    assert np.max(np.abs(front.normal_force - expected)[later]) < 5e-4 * front.static_normal_force
    assert np.ptp(front.normal_force[later]) > 10 * 5e-4 * front.static_normal_force  # the load does vary


@pytest.mark.parametrize("accuracy, tolerance", [("draft", 5e-4), ("standard", 2e-4), ("reference", 2e-4)])
@pytest.mark.parametrize("elevation", [0.0, 10.0])
def test_the_front_lifts_when_the_closed_form_says_and_not_before(elevation, accuracy, tolerance):
    """A slowly rising breech force F = r t on a barrel held by a stiff spring k: quasi-statically the spring
    carries R = F + M g sin th at x = R / k, and the front (an undamped linear support) unloads at F* where
    ``g (m_tot d - M x cos th) = F h`` (the closed form above):

        F* = g (m_tot d - M^2 g sin th cos th / k) / (h + g M cos th / k),    t* = F* / r.

    Lift-off within ``tolerance`` s of t* (the engine takes the first output sample with N = 0: its step; the
    closed form neglects the barrel's inertia M x'' = M r / k and the supports' compliance), and the front
    carries load at every sample before 0.99 t*."""
    k, duration, peak, mass = 1.0e7, 1.0, 1.5e5, 1000.0
    scene = carriage_scene({"cradle.elevation": elevation, "carriage.support.1.law": "hertz",
                            "carriage.support.1.exponent": 1.0, "carriage.support.1.damping": None},
                           barrel={"mass": mass}, recoil_spring={"stiffness": k},
                           recoil_damper={"recoil": 2.0e5, "counter_recoil": 2.0e5},
                           firing={"projectile_mass": 1.0, "muzzle_velocity": 30.0,
                                   "pulse": {"times": [0.0, duration], "forces": [0.0, peak]}})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", m.UnitWarning)  # a 1-s ramp is no breech pulse: on purpose
        result = m.simulate(scene, end_time=duration, accuracy=accuracy)
    theta = math.radians(elevation)
    h = TRUNNION[1] * math.cos(theta) - TRUNNION[0] * math.sin(theta)
    moment = CARRIAGE_MASS * CARRIAGE_X + mass * TRUNNION[0]
    force = G * (moment - mass ** 2 * G * math.sin(theta) * math.cos(theta) / k) / (h + G * mass * math.cos(theta) / k)
    lift_off = force / (peak / duration)
    assert result.lift_off_time == pytest.approx(lift_off, abs=tolerance)
    before = result.time < 0.99 * lift_off
    assert np.min(result.carriage.supports["wheels"].normal_force[before]) > 0.0
    assert result.stability_margin == 0.0 and result.max_lift > 0.0


# ================================================================================================ the 1-D limit
HEAVY = {"mass": 1.0e8, "inertia": 1.0e10, "center_of_mass": [2.4, 0.8], "trunnion": [2.5, 1.0],
         "support": [{"name": "spade", "position": [0.0, 0.0], "law": "kelvin-voigt", "stiffness": 1e14,
                      "damping": 1e11, "horizontal_stiffness": 1e14, "horizontal_damping": 1e11},
                     {"name": "wheels", "position": [2.8, 0.0], "law": "kelvin-voigt", "stiffness": 1e14,
                      "damping": 1e11}]}


@pytest.mark.parametrize("name, base, elevation", [("model (ii) level", model_ii(1000.0, 0.0), 0.0),
                                                   ("simplified at 30 deg", simplified_model(), 30.0)])
def test_a_very_stiff_heavy_carriage_gives_the_1d_results(name, base, elevation):
    """A 1e8 kg carriage on 1e14 N/m supports does not move: the 1-D results, within the standard preset's
    metric guarantee (1e-4; measured ~1e-5).  (At 30 deg a scene without absorbers: the 1-D model pulls only
    the barrel along the axis, the planar one every body.)"""
    data = scene_to_dict(base)
    data["cradle"] = {"elevation": elevation}
    one = m.simulate(scene_from_dict(data), end_time=2.0)
    data["carriage"] = HEAVY
    two = m.simulate(scene_from_dict(data), end_time=2.0)
    for key in ("max_barrel_displacement", "peak_support_force", "peak_contact_force", "max_absorber_velocity"):
        if getattr(one, key) is not None:
            assert getattr(two, key) == pytest.approx(getattr(one, key), rel=1e-4), key
    assert two.max_carriage_pitch < 1e-8 and two.stability_margin > 0.999


# ================================================================================================ energy
@pytest.mark.parametrize("scene_name", ["towed_howitzer", "towed_howitzer_45"])
def test_the_planar_energy_balance_closes(scene_name):
    """kinetic (absolute velocities) + gravity's potential + stored (elements, supports) + dissipated - work of the
    breech force = its value at t = 0, within 1e-6 of the shot's energy at standard."""
    scene = load_scene(SCENES_DIR / f"{scene_name}.toml")
    result = m.simulate(scene, end_time=1.0)
    error = result.energy_error()
    shot = float(result.work_histories["breech_force"][-1])
    assert shot > 1000.0
    assert np.max(np.abs(error)) < 1e-6 * shot
    assert "gravity" in result.stored_energy_histories and "support.spade" in result.dissipated_energy_history


def test_carriage_scenes_are_never_stopped_early():
    """Gravity acts for ever on the planar model: no energy bound, no early stop, no stop at rest."""
    result = m.simulate(carriage_scene(), end_time=0.3, stop_when_final=["max_barrel_displacement"],
                        stop_at_rest=True)
    assert result.end_time == 0.3 and result.stop_reason == m.StopReason.NO_ENERGY_BOUND
    assert result.rest_time is None


# ================================================================================================ backends, reuse
def test_python_and_symbolic_user_functions_give_the_same_run():
    """The tree's force user function is one function over the backend ops: Python and symbolic agree (the same
    steps; positions to 1e-12 m, support loads to 1e-6 N)."""
    scene = load_scene(SCENES_DIR / "towed_howitzer_45.toml")
    symbolic = m.simulate(scene, end_time=0.3)
    python = m.simulate(scene, end_time=0.3, user_functions="python")
    assert python.steps == symbolic.steps
    assert np.max(np.abs(python.barrel_position - symbolic.barrel_position)) < 1e-12
    assert np.max(np.abs(python.carriage_position - symbolic.carriage_position)) < 1e-12
    for name, support in symbolic.carriage.supports.items():
        assert np.max(np.abs(python.carriage.supports[name].normal_force - support.normal_force)) < 1e-6


def test_a_reused_simulator_assembles_a_carriage_scene_anew_with_the_same_result():
    """A carriage scene is never refilled into a kept system (its tree is built for its numbers): a Simulator
    gives what simulate gives, bit for bit, point after point."""
    from mbs_models import Simulator

    first, second = carriage_scene(), carriage_scene({"carriage.mass": 2500.0})
    with Simulator() as simulator:
        runs = [simulator.simulate(s, 0.2) for s in (first, second, first)]
        assert simulator.reuses == 0
    for scene, run in zip((first, second, first), runs):
        fresh = m.simulate(scene, 0.2)
        assert np.array_equal(run.barrel_position, fresh.barrel_position)
        assert np.array_equal(run.carriage_position, fresh.carriage_position)


def test_restitution_law_supports_capture_each_touch_down():
    """Wheels of a restitution law (Lankarani-Nikravesh) that leave the ground and land again: the law's v- is
    captured at each touch-down (at the step starts, as the absorbers' contacts), Python and symbolic agree, and
    the energy balance closes."""
    changes = {"carriage.support.1.law": "lankarani-nikravesh", "carriage.support.1.exponent": 1.5,
               "carriage.support.1.restitution": 0.6, "carriage.support.1.stiffness": 1e10,
               "carriage.support.1.damping": None, "barrel.initial_velocity": 4.0}
    scene = carriage_scene(changes, recoil_damper={"recoil": 6.0e4, "counter_recoil": 6.0e4})
    symbolic = m.simulate(scene, end_time=1.0)
    python = m.simulate(scene, end_time=1.0, user_functions="python")
    assert symbolic.lift_off_time is not None and symbolic.max_lift > 1e-4  # the wheels jump and land
    assert python.steps == symbolic.steps
    assert np.max(np.abs(python.carriage_position - symbolic.carriage_position)) < 1e-12
    wheels = symbolic.carriage.supports["wheels"]
    assert wheels.max_normal_force > 2 * wheels.static_normal_force  # the landing
    assert np.max(np.abs(symbolic.energy_error())) < 1e-6 * float(symbolic.kinetic_energy_history[0])


def test_a_support_that_carries_nothing_at_rest_does_not_lift_off():
    """A third support held 0.1 m above the ground: it carries nothing, so it neither lifts off at t = 0 nor counts
    in the stability margin (the reference: the same, tests/validation)."""
    from mbs_models.scene.io import scene_to_dict

    data = scene_to_dict(carriage_scene({"barrel.initial_velocity": 0.5}))
    data["carriage"]["support"].append({"name": "skid", "position": [1.4, 0.1], "law": "hertz", "stiffness": 1e8,
                                        "exponent": 1.5})
    result = m.simulate(scene_from_dict(data), end_time=0.3)
    assert result.carriage.supports["skid"].static_normal_force == 0.0
    assert result.lift_off_time is None and 0.0 < result.stability_margin < 1.0
