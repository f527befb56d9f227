"""The recuperator (mbs_models.elements.recuperator, validation/reference/terms/recuperator.py): a gas spring
ground -> barrel, ``F = p0 A (V0 / (V0 - A x))^n``, whose preload holds the barrel in battery.

Everything particular to it: its law and energy against DESIGN.md's formulas written out here, the scene
errors (API and command line), holding in battery (the initial state is a static equilibrium, for every stop
law and with absorbers on the barrel and on the ground), a conservative case against its closed form, the
energy balance element by element, the early stop (metrics equal to the full run's, bounds that bound the
future) and the engine against the independent reference at every preset with the README's guarantee.
"""

from __future__ import annotations

import json
import math
import re
from types import SimpleNamespace

import numpy as np
import pytest
import tomllib
from scipy.integrate import quad

from mbs_models import (Barrel, BatteryStop, Firing, RecoilDamper, RecoilSpring, RecoilStop,
                        Recuperator, Scene, SceneError, load_scene, model_i, model_ii, simulate)
from mbs_models.cli import main
from mbs_models.elements import ELEMENT_TABLES
from mbs_models.elements.recuperator import held_position
from mbs_models.engine import final_metrics as fm
from mbs_models.engine.assembly import add_body, assemble
from mbs_models.engine.mechanism import Mechanism
from mbs_models.scenes import scene_path
from validation.reference import solve_reference
from validation.reference.assembly import ModelBuilder, build_model
from validation.reference.finality import METRICS
from validation.reference.model import BARREL, GROUND, Body
from validation.reference.terms.contact_laws import ContactConnector, Law
from validation.reference.terms.recuperator import GasSpring, hold_in_battery
from validation.studies.guarantee import TOLERANCES

G = 9.81


# ------------------------------------------------------------------ DESIGN.md's formulas, written out here
def gas_force(rec, x):
    """F = p0 A (V0 / (V0 - A x))^n (N)."""
    return rec.initial_pressure * rec.piston_area * (rec.gas_volume / (rec.gas_volume - rec.piston_area * x)) \
        ** rec.polytropic_exponent


def gas_energy(rec, x):
    """U(x) = p0 V0 / (n - 1) ((V0 / (V0 - A x))^(n-1) - 1), or -p0 V0 ln(1 - A x / V0) for n = 1 (J)."""
    p0, A, V0, n = rec.initial_pressure, rec.piston_area, rec.gas_volume, rec.polytropic_exponent
    if n == 1.0:
        return -p0 * V0 * math.log(1.0 - A * x / V0)
    return p0 * V0 / (n - 1.0) * ((V0 / (V0 - A * x)) ** (n - 1.0) - 1.0)


def stop_force_at_rest(stop, p):
    """The battery stop at rest: k p^n (k p for Kelvin-Voigt), 0 for p <= 0."""
    if p <= 0:
        return 0.0
    return stop.stiffness * p ** (1.0 if stop.law == "kelvin-voigt" else stop.exponent)


def stop_energy(stop, p):
    n = 1.0 if stop.law == "kelvin-voigt" else stop.exponent
    return stop.stiffness * max(p, 0.0) ** (n + 1.0) / (n + 1.0)


def bisect(f, a, b, steps=200):
    """A root of f in [a, b] by bisection (f(a), f(b) of opposite signs)."""
    fa = f(a)
    for _ in range(steps):
        m = 0.5 * (a + b)
        if (f(m) > 0) == (fa > 0):
            a, fa = m, f(m)
        else:
            b = m
    return 0.5 * (a + b)


# ------------------------------------------------------------------ scenes
EXAMPLE = load_scene(scene_path("recuperator"))
GAS = Recuperator(initial_pressure=1.0e6, piston_area=0.002, gas_volume=0.002, polytropic_exponent=1.3)
STOP_LAWS = {
    "kelvin-voigt": dict(law="kelvin-voigt", stiffness=2e6, damping=5e4),
    "hunt-crossley": dict(law="hunt-crossley", stiffness=1e9, exponent=1.5, damping_factor=0.5),
    "hertz": dict(law="hertz", stiffness=1e9, exponent=1.5),
    "flores": dict(law="flores", stiffness=1e8, exponent=1.3, restitution=0.5),
}
#: the recuperator alone on the barrel, on a Hertz (elastic) battery stop: conservative
ALONE = Scene(barrel=Barrel(5600.0, initial_velocity=0.6909), recuperator=GAS,
              battery_stop=BatteryStop(position=0.0, **STOP_LAWS["hertz"]), name="recuperator alone")
#: model (i) (absorber riding on the barrel) with a recuperator, both stops and the paper's recoil spring and damper
I_STOPS = model_i(1000.0, 0.0).with_changes(
    recuperator=GAS, recoil_stop=RecoilStop(position=0.2, law="hunt-crossley", stiffness=1e9, exponent=1.5,
                                            damping_factor=0.5),
    battery_stop=BatteryStop(position=-0.002, law="exact-restitution", stiffness=1e8, exponent=1.5, restitution=0.5))
#: model (ii) (absorber on the ground, gap 0) with a recuperator on a Kelvin-Voigt battery stop
II = model_ii(500.0, 0.0).with_changes(recuperator=GAS, battery_stop=BatteryStop(position=0.0,
                                                                                 **STOP_LAWS["kelvin-voigt"]))


def at_rest(scene):
    """The scene without its shot: the barrel held in battery and nothing else."""
    return scene.with_changes(firing=None, **{"barrel.initial_velocity": 0.0})


# ------------------------------------------------------------------ the law and its energy
def test_the_force_and_energy_are_designs_and_the_energy_is_the_integral_of_the_force():
    connector = Mechanism(EXAMPLE).connector["recuperator"]
    rec = EXAMPLE.recuperator
    assert (connector.a, connector.b) == ("ground", "barrel")  # pushes the barrel towards -x: to battery
    for x in (-0.01, 0.0, 0.05, 0.26, 0.9):
        assert connector.python_force(x, 0.3) == pytest.approx(gas_force(rec, x), rel=1e-14)
        assert float(connector.force(np.array([x]), np.array([0.0]))[0]) == pytest.approx(gas_force(rec, x), rel=1e-14)
        assert float(connector.stored_energy(x)) == pytest.approx(gas_energy(rec, x), rel=1e-12, abs=1e-12)
        assert connector.python_stored_energy(x) == pytest.approx(gas_energy(rec, x), rel=1e-12, abs=1e-12)
        h = 1e-6
        slope = (gas_energy(rec, x + h) - gas_energy(rec, x - h)) / (2 * h)
        assert slope == pytest.approx(gas_force(rec, x), rel=1e-6)
    assert connector.python_force(0.0, 0.0) == pytest.approx(2000.0, rel=1e-15)  # the preload p0 A
    assert connector.stored_energy(0.0) == 0.0 and float(connector.stored_energy(-0.01)) < 0
    assert not connector.dissipates and connector.stores_energy and not connector.quadratic_potential
    isothermal = Recuperator(1e6, 0.002, 0.002, 1.0)
    assert float(isothermal.stored_energy(0.3)) == pytest.approx(gas_energy(isothermal, 0.3), rel=1e-14)
    nearly = Recuperator(1e6, 0.002, 0.002, 1.0 + 1e-9)
    assert float(nearly.stored_energy(0.3)) == pytest.approx(float(isothermal.stored_energy(0.3)), rel=1e-8)
    for energy in (-1000.0, 0.0, 500.0, 1e5):
        x = rec.stroke_at_energy(energy)
        assert gas_energy(rec, x) == pytest.approx(energy, rel=1e-12, abs=1e-9)
    # the tangent stiffness n p0 A^2 / V0 r^(n+1) at the stroke bound: the stroke the initial energy gives
    stroke = rec.stroke_at_energy(EXAMPLE.initial_kinetic_energy)
    tangent = (gas_force(rec, stroke + 1e-7) - gas_force(rec, stroke - 1e-7)) / 2e-7
    assert connector.linear_stiffness == pytest.approx(tangent, rel=1e-6)
    assert connector.force_bound(0.3, 1.0, 1e3) == pytest.approx(gas_force(rec, 0.3), rel=1e-14)
    assert connector.force_bound(1.0, 1.0, 1e3) == math.inf  # at V0/A the gas is gone


def test_the_reference_rhs_is_designs_equation(design):
    """The reference's right-hand side of the barrel with the recuperator, the paper's recoil spring and damper
    and a battery stop equals DESIGN.md's equations written out here, in every mode, on random states."""
    scene = Scene(barrel=Barrel(5600.0), firing=Firing(6.86, 564.0), recoil_spring=RecoilSpring(27500.0),
                  recoil_damper=RecoilDamper(6239.0, 14050.0), recuperator=GAS,
                  battery_stop=BatteryStop(position=-0.01, **STOP_LAWS["flores"]))

    def rhs(scene, y, states):
        x, v = y[0], y[1]
        damper = scene.recoil_damper
        c = damper.recoil if states["recoil_damper"] is not False else damper.counter_recoil
        p, rate = scene.battery_stop.position - x, -v
        F_stop, elastic = design.law_force(scene.battery_stop, p, rate, states["battery_stop"])
        f = -27500.0 * x - c * v - gas_force(GAS, x) + F_stop
        return [v, f / 5600.0], {"recoil_damper": c * v ** 2, "battery_stop": (F_stop - elastic) * rate}

    design.check_rhs(scene, rhs, "recuperator")


# ------------------------------------------------------------------ scene errors
def example_mapping() -> dict:
    return tomllib.loads(scene_path("recuperator").read_text())


BAD = [
    ("missing-pressure", "recuperator.initial_pressure", "<delete>", "recuperator.initial_pressure", "missing"),
    ("zero-pressure", "recuperator.initial_pressure", 0.0, "recuperator.initial_pressure", "> 0 Pa"),
    ("pressure-string", "recuperator.initial_pressure", "high", "recuperator.initial_pressure", "must be a number"),
    ("negative-area", "recuperator.piston_area", -0.002, "recuperator.piston_area", "> 0 m^2"),
    ("missing-area", "recuperator.piston_area", "<delete>", "recuperator.piston_area", "missing"),
    ("zero-volume", "recuperator.gas_volume", 0.0, "recuperator.gas_volume", "> 0 m^3"),
    ("volume-bool", "recuperator.gas_volume", True, "recuperator.gas_volume", "must be a number"),
    ("exponent-below-isothermal", "recuperator.polytropic_exponent", 0.9, "recuperator.polytropic_exponent",
     "in [1, 1.67]"),
    ("exponent-above-monatomic", "recuperator.polytropic_exponent", 1.8, "recuperator.polytropic_exponent",
     "in [1, 1.67]"),
    ("missing-exponent", "recuperator.polytropic_exponent", "<delete>", "recuperator.polytropic_exponent", "missing"),
    ("unknown-key", "recuperator.gas_volum", 0.002, "recuperator.gas_volum", "did you mean 'gas_volume'"),
    ("not-a-table", "recuperator", 3.0, "recuperator", "must be a table"),
    # holding in battery: a preload with nothing to rest on
    ("no-battery-stop", "battery_stop", "<delete>", "battery_stop", "needs a [battery_stop] to rest on"),
    # beyond double precision (DESIGN.md, "Bad input beyond the ranges"): 1.3 x 1e6 x 0.002^2 / 1e-320 overflows
    ("stiffness-overflows", "recuperator.gas_volume", 1e-320, "recuperator.gas_volume", "stiffness at battery"),
    # p0 V0 = 1e-94 J against E0 = 1337 J: r^(n-1) = 1 + 0.3 E0 / (p0 V0) = 4e96, F = p0 A r^1.3/0.3 ~ 1e422 N
    ("force-at-stroke-overflows", "recuperator.gas_volume", 1e-100, "recuperator.gas_volume",
     "force at the stroke U^-1(E)"),
]


@pytest.mark.parametrize("path, value, key, text", [c[1:] for c in BAD], ids=[c[0] for c in BAD])
def test_bad_recuperator_tables_are_one_line_errors_naming_the_key(bad_input, changed, path, value, key, text):
    bad_input(changed(example_mapping(), path, value), key, text)


def test_a_preload_that_underflows_is_refused(bad_input, changed):
    """p0 A = 1e-320 x 1e-10 rounds to 0 N: not a preload double precision holds."""
    mapping = changed(changed(example_mapping(), "recuperator.initial_pressure", 1e-320), "recuperator.piston_area",
                      1e-10)
    bad_input(mapping, "recuperator.initial_pressure", "the preload p0 A = 0 N")


def test_the_equilibrium_in_battery_is_found_down_to_a_gas_volume_of_1e_300():
    """With V0 / A ~ 1e-298 m the gas spring's force falls from the preload within 1e-298 m of battery: Brent's
    method brackets the root in [-1e-9, 0] m and needs more than the 500 iterations it was once given.  A shot
    of v0 = 1e-150 m/s (E0 = 2.8e-297 J against p0 V0 = 1e-294 J: a finite force at its stroke) is a valid scene;
    the equilibrium balances the stop's force against the gas spring's at the root."""
    gas = Recuperator(initial_pressure=1.0e6, piston_area=0.002, gas_volume=1e-300, polytropic_exponent=1.3)
    scene = EXAMPLE.with_changes(recuperator=gas, firing=None, barrel=Barrel(5600.0, initial_velocity=1e-150))
    mechanism = Mechanism(scene)
    x0 = held_position(scene, mechanism.connectors)
    stop = mechanism.connector["battery_stop"]
    spring = mechanism.connector["recuperator"]
    assert -1e-9 < x0 < 0.0
    assert math.isclose(stop.python_force(-x0, 0.0), spring.python_force(x0, 0.0), rel_tol=1e-6)


def test_the_recuperator_needs_a_version_2_scene(bad_input, v1_mapping):
    bad_input(dict(v1_mapping, recuperator=example_mapping()["recuperator"]), "recuperator", "version-2 scene")


def test_a_gas_volume_the_stroke_exhausts_is_an_error_giving_both_volumes(bad_input):
    """V0 = 2 L, A = 20 cm^2: a recoil stop at 1.2 m would need 2.4 L; at 0.9 m (1.8 L) the scene is valid."""
    mapping = example_mapping()
    mapping["recoil_stop"] = dict(position=1.2, law="hertz", stiffness=1e9, exponent=1.5)
    bad_input(mapping, "recuperator.gas_volume", "V0 = 0.002 m^3")
    with pytest.raises(SceneError, match=r"A x = 0\.0024 m\^3 at x = 1\.2 m"):
        load_scene_from(mapping)
    mapping["recoil_stop"]["position"] = 0.9
    assert load_scene_from(mapping).recoil_stop.position == 0.9


def load_scene_from(mapping):
    from mbs_models import scene_from_dict
    return scene_from_dict(mapping)


def test_a_preload_that_cannot_return_the_barrel_against_gravity_and_friction_is_an_error():
    """p0 A <= M g (sin(elevation) + mu cos(elevation)): checked with the scene's [cradle] (a stand-in here: the
    cradle's table comes with its own element), the message gives both forces in N."""
    resisting = 5600.0 * G * (math.sin(math.radians(30.0)) + 0.1 * math.cos(math.radians(30.0)))  # 32 222 N
    cradle = SimpleNamespace(elevation=30.0, gravity=G, friction_coefficient=0.1)
    scene = SimpleNamespace(barrel=Barrel(5600.0, initial_velocity=0.0), battery_stop=EXAMPLE.battery_stop,
                            recoil_stop=None, cradle=cradle, initial_velocity=0.0)
    with pytest.raises(SceneError) as info:
        GAS.check_in_scene(scene, "recuperator")
    assert info.value.key == "recuperator.initial_pressure"
    assert "p0 A = 2000 N" in info.value.message and f"{resisting:.6g} N" in info.value.message
    assert "\n" not in str(info.value)
    just_enough = Recuperator(resisting / 0.002 * (1 + 1e-9), 0.002, 0.002, 1.3)
    just_enough.check_in_scene(scene, "recuperator")  # holds: no error
    with pytest.raises(SceneError):
        Recuperator(resisting / 0.002 * (1 - 1e-9), 0.002, 0.002, 1.3).check_in_scene(scene, "recuperator")


@pytest.mark.skipif("cradle" not in ELEMENT_TABLES, reason="the [cradle] element is not in this branch yet")
def test_a_cradle_too_steep_for_the_preload_is_refused_by_the_scene_and_the_command_line(bad_input):
    mapping = example_mapping()
    mapping["cradle"] = dict(elevation=30.0, gravity=G, friction_coefficient=0.1)
    bad_input(mapping, "recuperator.initial_pressure", "cannot return the barrel to battery")


# ------------------------------------------------------------------ holding in battery
@pytest.mark.parametrize("law", list(STOP_LAWS))
def test_the_barrel_starts_in_equilibrium_on_its_battery_stop(law):
    """x0 = position - p_s with F_stop(p_s) = F_gas(x0) + k x0 (DESIGN.md's equation, to round-off), in the
    engine and in the reference, which solve it independently."""
    stop = BatteryStop(position=-0.003, **STOP_LAWS[law])
    scene = model_i(500.0, 0.0).with_changes(recuperator=GAS, battery_stop=stop)
    engine_x0 = Mechanism(scene).bodies[0].initial_position
    reference_x0 = build_model(scene).bodies[0].initial_position
    p_s = stop.position - engine_x0
    assert p_s > 0
    balance = stop_force_at_rest(stop, p_s) - gas_force(GAS, engine_x0) - 27500.0 * engine_x0
    assert abs(balance) <= 1e-12 * gas_force(GAS, 0.0)
    assert reference_x0 == pytest.approx(engine_x0, rel=1e-13)
    expected = bisect(lambda x: stop_force_at_rest(stop, stop.position - x) - gas_force(GAS, x) - 27500.0 * x,
                      stop.position - 1.0, stop.position)
    assert engine_x0 == pytest.approx(expected, rel=1e-12)


def test_bodies_on_the_barrel_ride_with_it_and_bodies_on_the_ground_stay_at_zero():
    """Model (i)'s absorber (on the barrel) starts at x0 with the barrel: its actuator and contact start as without
    preload; model (ii)'s (on the ground) at 0, its contact opened by |x0|.  A scene without a recuperator starts
    every body at 0."""
    for scene, riding in ((model_i(500.0, 0.0).with_changes(recuperator=GAS, battery_stop=EXAMPLE.battery_stop), True),
                          (II, False)):
        for bodies in (Mechanism(scene).bodies, build_model(scene).bodies):
            barrel, absorber = bodies
            assert barrel.initial_position < 0
            assert absorber.initial_position == (barrel.initial_position if riding else 0.0)
    plain = model_i(500.0, 0.0).with_changes(battery_stop=EXAMPLE.battery_stop)
    assert [b.initial_position for b in Mechanism(plain).bodies] == [0.0, 0.0]
    assert [b.initial_position for b in build_model(plain).bodies] == [0.0, 0.0]


def test_the_barrels_weight_on_a_cradle_unloads_the_battery_stop():
    """With a [cradle] (a stand-in: its element is another one) F_stop(p_s) = F_gas(x0) - M g sin(elevation):
    the engine's and the reference's hold, each with the barrel's weight along the axis."""
    stop = EXAMPLE.battery_stop
    weight = 5600.0 * G * math.sin(math.radians(0.01))  # 9.6 N of the 2 kN preload
    scene = SimpleNamespace(barrel=EXAMPLE.barrel, cradle=SimpleNamespace(elevation=0.01, gravity=G,
                                                                         friction_coefficient=0.0))
    x0 = held_position(scene, Mechanism(EXAMPLE).connectors)
    assert stop_force_at_rest(stop, -x0) == pytest.approx(gas_force(GAS, x0) - weight, rel=1e-12)
    builder = ModelBuilder(scene)
    builder.add_body(Body(BARREL, 5600.0))
    builder.add_connector(GasSpring("recuperator", GROUND, BARREL, 1.0e6, 0.002, 0.002, 1.3))
    builder.add_connector(ContactConnector("battery_stop", BARREL, GROUND, 0.0, Law.from_table(stop)))
    hold_in_battery(builder)
    assert builder.positions[BARREL] == pytest.approx(x0, rel=1e-13)
    assert held_position(SimpleNamespace(barrel=EXAMPLE.barrel), Mechanism(EXAMPLE).connectors) < x0  # no weight


@pytest.mark.parametrize("law", list(STOP_LAWS))
@pytest.mark.parametrize("base", ["i", "ii"])
def test_without_a_shot_nothing_moves_for_a_second(law, base):
    """The initial state is a static equilibrium: held in battery, without firing, the barrel and the absorbers
    stay where they start (< 1e-9 m over 1 s) in the engine and in the reference; the mount feels nothing (the
    gas spring and the stop pull it equally).  (The reference runs without the asymmetric recoil damper: its
    branch switch at v = 0, crossed back and forth by the equilibrium's round-off residual of ~1e-12 N, makes
    the event-driven solver chatter -- a sliding mode in which the damper's force is 0 on either branch.)"""
    stop = BatteryStop(position=0.0, **STOP_LAWS[law])
    scene = at_rest((model_i(500.0, 0.0) if base == "i" else model_ii(500.0, 0.0)).with_changes(
        recuperator=GAS, battery_stop=stop))
    result = simulate(scene, 1.0, "reference")
    for name, x in result.positions.items():
        assert np.max(np.abs(x - x[0])) < 1e-9, name
    assert np.max(np.abs(result.support_force)) < 1e-6
    x0 = result.barrel_position[0]  # the stop carries the preload less the recoil spring's pull
    assert result.contacts["battery_stop"].force[-1] == pytest.approx(gas_force(GAS, x0) + 27500.0 * x0, rel=1e-9)
    # that static contact (~1.98 kN, above the 1 kN threshold) is an episode, not an impact (DESIGN.md)
    assert result.contacts["battery_stop"].episodes == 1 and result.contacts["battery_stop"].impacts == []
    reference = solve_reference(scene.with_changes(recoil_damper=None), 1.0, max_segments=500)
    t = np.linspace(0.0, 1.0, 1001)
    for body in reference.bodies:
        x = reference.position(body, t)
        assert np.max(np.abs(x - x[0])) < 1e-9, body
    assert len(reference.contacts["battery_stop"].episodes) == 1 and reference.contacts["battery_stop"].impacts == []


# ------------------------------------------------------------------ the hold is no impact, the landings are
def test_the_example_at_rest_without_a_shot_has_no_impact():
    """Without a shot the barrel stays in battery: the stop carries the 2 kN preload for the whole run, above the
    1 kN threshold, in one episode that never rises above its static value: no impact (DESIGN.md, "Outputs
    every scene gets"), in the engine and in the reference; ``recoil run``'s outputs say so."""
    scene = at_rest(EXAMPLE)
    result = simulate(scene, 2.0)
    contact = result.contacts["battery_stop"]
    static = gas_force(GAS, result.barrel_position[0])
    assert np.all(np.abs(contact.force - static) < 1e-6 * static) and static > 1000.0
    assert contact.episodes == 1 and contact.impacts == [] and result.stops()[0]["impacts"] == []
    assert result.metrics()["stops"][0]["impacts"] == [] and ", 0 impacts" in result.summary()
    reference = solve_reference(scene, 2.0)
    [hold] = reference.contacts["battery_stop"].episodes
    assert hold.start == 0.0 and hold.end == 2.0 and hold.peak_force == pytest.approx(static, rel=1e-9)
    assert reference.contacts["battery_stop"].impacts == [] == reference.stop_metrics["battery_stop"].impacts


def landings(time, barrel_position, barrel_velocity, position: float = 0.0) -> list[tuple[float, float]]:
    """``(time s, approach speed m/s)`` of every landing onto a battery stop at ``position`` in a sampled
    trajectory: x_M from >= position to < position (the penetration ``position - x_M`` turns positive: an onset
    inside the window), interpolated linearly to the crossing."""
    x = np.asarray(barrel_position) - position
    out = []
    for i in np.flatnonzero((x[:-1] >= 0.0) & (x[1:] < 0.0)):
        w = x[i] / (x[i] - x[i + 1])
        out.append((float(time[i] + w * (time[i + 1] - time[i])),
                    float(-(barrel_velocity[i] + w * (barrel_velocity[i + 1] - barrel_velocity[i])))))
    return out


@pytest.fixture(scope="module")
def realistic_runs():
    scene = load_scene(scene_path("realistic"))
    return scene, simulate(scene, 10.0), solve_reference(scene, 10.0)


def test_the_realistic_preloads_hold_is_an_episode_not_an_impact(realistic_runs):
    """The realistic scene starts at rest on its Kelvin-Voigt buffer in static equilibrium (DESIGN.md, "Initial
    state"): the buffer carries the preload less the weight along the cradle, ``F(x0) - M g sin(30 deg)`` =
    8.5 kN, far above the 1 kN threshold.  The breech pulse only pulls the barrel off the stop, so the force never
    rises above that static value: the hold is an episode (the old definition counted it) but not an impact."""
    scene, result, reference = realistic_runs
    force = result.contacts["battery_stop"].force
    x0 = result.barrel_position[0]
    static = gas_force(scene.recuperator, x0) - scene.barrel.mass * G * math.sin(math.radians(30.0))
    assert result.barrel_velocity[0] == 0.0 and x0 < 0.0
    assert force[0] == pytest.approx(static, rel=1e-6) and static > 8000.0  # (Brent's root of the equilibrium)
    off = np.flatnonzero(force <= 0.0)[0]  # the first sample the barrel is off the stop
    assert np.max(force[:off]) == force[0]  # the pulse only unloads the stop
    assert all(impact.start > 0.0 for impact in result.contacts["battery_stop"].impacts)
    hold = reference.contacts["battery_stop"].episodes[0]
    assert hold.start == 0.0 and hold.peak_force == pytest.approx(static, rel=1e-6)
    assert hold not in reference.contacts["battery_stop"].impacts


def test_the_realistic_buffer_counts_the_hit_and_the_rebound_of_every_return(realistic_runs):
    """After each of the 3 shots the recuperator brings the barrel back onto the buffer (at ~0.16 m/s), the
    buffer throws it back out, and it lands again (~0.05 m/s), after which the preload holds it on the stop until
    the next shot (or the end of the window).  Each landing is an onset inside the window (force at rest 0 before
    it) at which a Kelvin-Voigt law's force jumps to ``c v-`` (c = 2e5 N s/m): a landing faster than threshold /
    c = 5 mm/s is an impact.  So 2 impacts per return, 6 for the 3 shots; the last one (the third shot's
    rebound) is still going on at the end of the window and counts once.  The same in the reference."""
    scene, result, reference = realistic_runs
    stop = scene.battery_stop
    contact = result.contacts["battery_stop"]
    found = landings(result.time, result.barrel_position, result.barrel_velocity, stop.position)
    shots = [shot["time"] for shot in result.shots] + [result.end_time]
    per_shot = [[o for o in found if a < o[0] < b] for a, b in zip(shots, shots[1:])]
    assert [len(returns) for returns in per_shot] == [2, 2, 2]
    assert all(stop.damping * speed > 5000.0 for _, speed in found)  # clearly impacts
    assert all(hit[1] > rebound[1] for hit, rebound in per_shot)  # the rebound comes back slower
    assert len(contact.impacts) == 6 and contact.episodes == 7  # + the hold at t = 0
    interval = float(np.max(np.diff(result.time)))
    for impact, (time, _) in zip(contact.impacts, found):  # each impact begins at its landing
        assert abs(impact.start - time) <= interval
    assert contact.impacts[-1].end == result.end_time  # at rest on the stop since the last rebound
    assert result.metrics()["stops"][0]["impacts"] == [impact.to_dict() for impact in contact.impacts]  # --json
    assert re.search(r"\n  battery stop +[0-9.]+ kN, 6 impacts\n", result.summary())  # recoil run's text
    theirs = reference.contacts["battery_stop"]
    assert len(theirs.episodes) == 7 and theirs.impacts == theirs.episodes[1:]
    for ours, its in zip(contact.impacts, theirs.impacts):
        assert abs(ours.start - its.start) <= TOLERANCES["standard"]["time"]


# ------------------------------------------------------------------ energy
def test_the_recuperator_alone_is_conservative():
    """Barrel, recuperator and an elastic (Hertz) battery stop: the energy stays E0 = M v0^2/2 + U_gas(x0) +
    U_stop(p_s) to 1e-9 in the engine (``reference``) and the reference, and the barrel turns where the gas
    alone holds E0: U_gas(x_max) = E0 (DESIGN.md's U, inverted here by bisection)."""
    x0 = Mechanism(ALONE).bodies[0].initial_position
    stop = ALONE.battery_stop
    e0 = 0.5 * 5600.0 * 0.6909 ** 2 + gas_energy(GAS, x0) + stop_energy(stop, -x0)
    x_max = bisect(lambda x: gas_energy(GAS, x) - e0, 0.0, 0.999)
    result = simulate(ALONE, 3.0, "reference")
    energy = result.kinetic_energy_history + result.stored_energy_history
    assert energy[0] == pytest.approx(e0, rel=1e-13)
    assert np.max(np.abs(energy - e0)) < 1e-9 * e0  # measured 5.4e-10
    assert np.max(np.abs(result.energy_error())) < 2e-9 * e0  # with the stop's quadrature (measured 9.8e-10)
    assert result.dissipated_energy["battery_stop"] == pytest.approx(0.0, abs=1e-9 * e0)
    assert result.max_barrel_displacement == pytest.approx(x_max, rel=1e-9)
    # the hold on the stop at t = 0 is an episode but no impact (DESIGN.md: its force never rises above the static
    # preload); the barrel leaves the stop within p_s / v0 and comes back after its flight out and back under the
    # gas alone, 2 integral_0^x_max dx / v(x) with M v^2 / 2 = E0 - U_gas(x) (x = x_max (1 - s^2) removes the
    # 1/sqrt at the turning point); rebounding elastically it would land again a flight later, after the 3 s
    flight = 2 * quad(lambda s: 2 * x_max * s / math.sqrt(
        max(2 * (e0 - gas_energy(GAS, x_max * (1 - s * s))) / 5600.0, 1e-300)), 0.0, 1.0, limit=200)[0]
    contact = result.contacts["battery_stop"]
    assert contact.episodes == 2 and len(contact.impacts) == 1 and 2 * flight > 3.0
    assert flight < contact.impacts[0].start < flight - x0 / 0.6909 + 1e-6  # measured 2.32575 s + 0.23 ms
    reference = solve_reference(ALONE, 3.0, rtol=1e-12, atol=1e-14)
    t = np.linspace(0.0, 3.0, 3001)
    mechanical = sum(reference.kinetic_energy(t).values()) + sum(reference.stored_energy(t).values())
    assert reference.initial_energy == pytest.approx(e0, rel=1e-13)
    assert np.max(np.abs(mechanical - e0)) < 1e-9 * e0
    assert reference.max_barrel_displacement == pytest.approx(x_max, rel=1e-9)


def test_the_energy_balance_closes_element_by_element():
    """Result.energy(): per element kinetic, stored, dissipated at the end; the recuperator stores U_gas(x_end)
    and dissipates nothing; together they are the initial energy (M v0^2/2 + U_gas(x0) + U_stop(p_s))."""
    result = simulate(EXAMPLE, 10.0)
    parts = result.energy()
    x0, x_end = result.barrel_position[0], result.barrel_position[-1]
    e0 = 0.5 * 5600.0 * EXAMPLE.initial_velocity ** 2 + gas_energy(GAS, x0) + stop_energy(EXAMPLE.battery_stop, -x0)
    assert parts["recuperator"] == pytest.approx({"kinetic": 0.0, "stored": gas_energy(GAS, x_end), "dissipated": 0.0},
                                                 rel=1e-9, abs=1e-12)
    assert parts["recuperator"]["stored"] < 0  # the barrel rests forward of battery, the gas expanded
    assert parts["battery_stop"]["stored"] == pytest.approx(stop_energy(EXAMPLE.battery_stop, -x_end), rel=1e-9)
    assert parts["recoil_damper"]["dissipated"] > 0.8 * e0 and parts["battery_stop"]["dissipated"] > 0
    assert sum(sum(p.values()) for p in parts.values()) == pytest.approx(e0, rel=5e-6)
    assert abs(x_end - x0) < 1e-6  # back in battery, at rest where it started


# ------------------------------------------------------------------ items, outputs, building block
def test_a_scene_without_a_recuperator_adds_no_item():
    with assemble(model_ii()) as assembly:
        assert "recuperator" not in assembly.connectors
        plain = len(assembly.connectors)
    with assemble(EXAMPLE) as assembly:
        assert "recuperator" in assembly.connectors and "recuperator" in assembly.user_function_connectors
        assert "recuperator_force" not in assembly.sensors  # its force is not an output: the support force has it
    with assemble(model_ii().with_changes(recuperator=GAS, battery_stop=EXAMPLE.battery_stop)) as assembly:
        assert len(assembly.connectors) == plain + 2


def test_recoil_run_json_of_the_example(capsys):
    assert main(["run", "recuperator", "--end-time", "10", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert 0.25 < data["max_barrel_displacement"] < 0.27  # the recoil length the example is made for
    assert data["energy"]["recuperator"]["dissipated"] == 0.0 and data["energy"]["recuperator"]["stored"] < 0
    assert [s["name"] for s in data["stops"]] == ["battery_stop"]


def test_the_building_block_in_a_hand_built_system():
    """add_recuperator on a caller's own Exudyn system: a 100 kg body at x = 0 moving at 1 m/s into the gas
    turns where U_gas(x_max) = m v^2 / 2 (no stop, no damper: the gas spring alone)."""
    import exudyn
    from exudyn.itemInterface import MarkerNodeCoordinate, NodePointGround

    from mbs_models import add_recuperator

    system = exudyn.SystemContainer()
    mbs = system.AddSystem()
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    node, marker = add_body(mbs, mass=100.0, initial_velocity=1.0)
    connector = add_recuperator(mbs, ground, marker, GAS)
    mbs.Assemble()
    settings = exudyn.SimulationSettings()
    settings.timeIntegration.endTime = 0.2
    settings.timeIntegration.numberOfSteps = 2000
    settings.timeIntegration.verboseMode = 0
    settings.solution.file.write = False
    x_max = bisect(lambda x: gas_energy(GAS, x) - 50.0, 0.0, 0.999)
    positions = []
    mbs.SetPreStepUserFunction(lambda mbs, t: positions.append(mbs.systemData.GetODE2Coordinates()[0]) or True)
    mbs.SolveDynamic(settings, solverType=exudyn.DynamicSolverType.RK44)
    assert connector.index is not None
    assert max(positions) == pytest.approx(x_max, rel=1e-4)
    system.Reset()


# ------------------------------------------------------------------ early stop
REQUESTS = {"x": ("max_barrel_displacement",), "S": ("peak_support_force",),
            "x-F-v-S": ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "peak_support_force"),
            "all": fm.FINAL_METRICS}
EARLY = {"example": EXAMPLE, "i-stops": I_STOPS}


@pytest.fixture(scope="module")
def full_runs():
    return {key: simulate(scene, 10.0) for key, scene in EARLY.items()}


@pytest.mark.parametrize("requested", list(REQUESTS))
@pytest.mark.parametrize("key", list(EARLY))
def test_early_stopped_metrics_are_the_full_runs(key, requested, full_runs):
    """The engine stops once the metrics are proven final (from the gas spring's potential well) with the full
    run's values; the impacts cannot be final while the preload rests on the battery stop above the impact
    threshold (an episode goes on for ever): asked for, the run goes to its end."""
    full = full_runs[key]
    early = simulate(EARLY[key], 10.0, stop_when_final=REQUESTS[requested])
    if "impacts" in REQUESTS[requested]:
        assert early.stop_reason == fm.STOP_END_TIME and full.contacts["battery_stop"].force[-1] > 1000.0
    else:
        assert early.stop_reason == fm.STOP_METRICS_FINAL and early.end_time < 5.0
        np.testing.assert_array_equal(early.barrel_position, full.barrel_position[:len(early.time)])
    for name in early.final_metrics:
        if name == "impacts":
            assert early.impacts == full.impacts
        else:
            assert getattr(early, name) == getattr(full, name), name
    for name in set(fm.FINAL_METRICS) - set(early.final_metrics):
        assert getattr(early, name) is None, name


@pytest.mark.parametrize("key", list(EARLY))
def test_the_reference_stops_early_with_the_full_runs_metrics(key):
    scene = EARLY[key]
    full = solve_reference(scene, 8.0)
    requested = tuple(m for m in METRICS if m != "impacts")
    early = solve_reference(scene, 8.0, stop_when_final=requested)
    assert early.stop_reason == "metrics_final" and early.end_time < 5.0
    for name in requested:
        if getattr(full, name) is None:  # no absorber
            assert getattr(early, name) is None
        else:
            assert getattr(early, name) == pytest.approx(getattr(full, name), rel=1e-12, abs=1e-300), name


@pytest.mark.parametrize("key", list(EARLY))
def test_the_engines_bounds_bound_the_future_of_a_run(key, full_runs):
    """Along a full run, from E(t_i) every later x_M, |S| and stop force stays within its bound; the bound on
    x_M is reached (to 1e-6) by the example's maximum, which all the energy above the well's floor could reach."""
    scene, result = EARLY[key], full_runs[key]
    b = fm.EnergyBounds(scene)
    assert b.well is not None and b.energy_floor < 0
    bodies = [body.name for body in b.mechanism.bodies]
    x = np.array([result.positions[name] for name in bodies]).T
    v = np.array([result.velocities[name] for name in bodies]).T
    energy = np.array([b.energy(xi, vi) for xi, vi in zip(x, v)])
    np.testing.assert_allclose(energy, result.kinetic_energy_history + result.stored_energy_history, rtol=1e-9,
                               atol=1e-9 * energy[0])
    error = 1e-7 * (energy[0] - b.energy_floor)  # the solution's own energy error (it is not exactly dissipative)
    slack = [e + error for e in energy]

    def later(values):
        return np.maximum.accumulate(np.asarray(values)[::-1])[::-1]

    bound_x = np.array([b.barrel_displacement(e) for e in slack])
    assert np.all(later(result.barrel_position) <= bound_x + 1e-15)
    assert np.all(later(np.abs(result.support_force)) <= np.array([b.support_force_bound(e) for e in slack])
                  * (1 + 1e-12))
    for j, contact in enumerate(b.contacts):
        force = result.contacts[contact.name].force
        assert np.all(later(force) <= np.array([b.contact_force_bound(j, e) for e in slack]) * (1 + 1e-12) + 1e-9)
    if key == "example":  # the barrel alone: at the maximum all the energy above the floor is the well's
        k = int(np.argmax(result.barrel_position))
        assert bound_x[k] == pytest.approx(result.max_barrel_displacement, rel=1e-6)


# ------------------------------------------------------------------ the engine against the reference
ENGINE_CASES = {"example": (EXAMPLE, 6.0), "i-stops": (I_STOPS, 4.0), "ii": (II, 4.0)}


@pytest.mark.parametrize("accuracy", list(TOLERANCES))
@pytest.mark.parametrize("name", list(ENGINE_CASES))
def test_engine_against_reference_every_preset(name, accuracy, agrees_with_reference):
    scene, end = ENGINE_CASES[name]
    errors = agrees_with_reference(scene, end, accuracy)
    assert errors["impact_mismatch"] == 0
