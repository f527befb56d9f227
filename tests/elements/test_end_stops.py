"""End stops (mbs_models.elements.end_stops, validation/reference/terms/end_stops.py): the barrel against the
ground, any contact law.  Everything particular to the stops: the engine's items, outputs and errors, the
reference's equations, names, outputs and hard cases, and the engine against the reference with the README's
guarantee at every preset.  The generic tests (tests/validation/reference/, ...) run on scenes of every element
that include the stops (the ``every_element`` fixture of tests/conftest.py; checked below)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from mbs_models import (Barrel, BatteryStop, Firing, RecoilDamper, RecoilSpring, RecoilStop, Scene, load_scene,
                        model_ii, simplified_model, simulate)
from mbs_models.cli import main
from mbs_models.elements import TABLES
from mbs_models.elements.contact_laws import CONTACT_LAWS
from mbs_models.engine.assembly import assemble
from mbs_models.scenes import scene_path
from validation.reference import solve_reference
from validation.reference.assembly import build_model
from validation.studies.guarantee import TOLERANCES, reference_for

LAW_FIELDS = {"hunt-crossley": dict(stiffness=1e9, exponent=1.5, damping_factor=0.5),
              "hertz": dict(stiffness=1e9, exponent=1.5), "kelvin-voigt": dict(stiffness=5e7, damping=2e5)}


def law_fields(law: str) -> dict:
    return LAW_FIELDS.get(law, dict(stiffness=1e9, exponent=1.5, restitution=0.5))


def with_stops(scene, law: str, position=0.12):
    return scene.with_changes(recoil_stop=RecoilStop(position=position, law=law, **law_fields(law)),
                              battery_stop=BatteryStop(position=0.0, law=law, **law_fields(law)))


@pytest.mark.parametrize("law", sorted(CONTACT_LAWS))
def test_stops_of_every_law_stop_the_barrel_and_balance_energy(law):
    result = simulate(with_stops(model_ii(1000.0, 0.0), law), 5.0)
    stop = result.contacts["recoil_stop"]
    assert stop.impacts and stop.peak_force > 1e4
    # the stroke ends at the stop (plus its penetration: (F/k)^(1/n) at the peak force)
    penetration = (stop.peak_force / law_fields(law)["stiffness"]) ** (1 / law_fields(law).get("exponent", 1.0))
    assert 0.12 < result.max_barrel_displacement <= 0.12 + 1.01 * penetration
    assert np.all(result.contacts["battery_stop"].force >= 0.0) and np.all(stop.force >= 0.0)
    assert np.max(np.abs(result.energy_error())) < 5e-6 * result.kinetic_energy_history[0]
    assert {"recoil_stop", "battery_stop"} <= set(result.dissipated_energy) or law == "hertz"


def test_the_stops_push_the_mount_in_opposite_directions():
    """Recoil stop (ground -> barrel): +F on the mount; battery stop (barrel -> ground): -F.  The support
    force is minus the rate of momentum at every sample."""
    result = simulate(load_scene(scene_path("end_stops")), 3.0)
    accelerations = 5600.0 * result.accelerations["barrel"] + 1000.0 * result.accelerations["absorber"]
    np.testing.assert_allclose(result.support_force, -accelerations, rtol=0, atol=1e-9 * np.max(np.abs(accelerations)))
    recoil = result.contacts["recoil_stop"]
    i = int(np.argmax(recoil.force))
    assert result.support_force[i] > 0.9 * recoil.force[i]  # the stop dominates the mount's load there
    battery = result.contacts["battery_stop"]
    j = int(np.argmax(battery.force))
    assert result.support_force[j] < -0.5 * battery.force[j]
    stops = {s["name"]: s for s in result.metrics()["stops"]}
    assert stops["recoil_stop"]["peak_contact_force"] == recoil.peak_force and stops["battery_stop"]["impacts"]


@pytest.mark.parametrize("law", ["hunt-crossley", "kelvin-voigt", "exact-restitution"])
def test_stops_hit_at_ten_times_the_firing_velocity(law):
    """A hard case: the barrel hits the recoil stop at ~7 m/s (muzzle velocity 5640 m/s)."""
    scene = with_stops(simplified_model(), law, 0.1).with_changes(**{"firing.muzzle_velocity": 5640.0})
    for accuracy in ("draft", "standard"):
        result = simulate(scene, 2.0, accuracy)
        assert np.all(np.isfinite(result.support_force))
        assert result.contacts["recoil_stop"].peak_force > 1e5
        assert np.max(np.abs(result.energy_error())) < (1e-3 if accuracy == "draft" else 5e-6) * \
            result.kinetic_energy_history[0]


def test_recoil_run_json_reports_the_stops(capsys):
    """``recoil run --json`` of the shipped example: both stops by name, with their peak force, impacts and
    dissipated energy; the recoil stop's impact reaches the mount."""
    assert main(["run", "end_stops", "--end-time", "3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [s["name"] for s in data["stops"]] == ["recoil_stop", "battery_stop"]
    for stop in data["stops"]:
        assert stop["peak_contact_force"] > 1e4 and stop["impacts"] and stop["dissipated_energy"] > 0
    recoil = data["stops"][0]
    assert data["peak_support_force"] > 1e5 and data["peak_support_force"] > 0.9 * recoil["peak_contact_force"]


def test_a_scene_without_stops_adds_no_stop_item():
    with assemble(model_ii()) as assembly:
        assert not {"recoil_stop", "battery_stop"} & set(assembly.connectors)
    with assemble(load_scene(scene_path("end_stops"))) as assembly:
        assert {"recoil_stop", "battery_stop"} <= set(assembly.connectors)
        assert {"recoil_stop_force", "battery_stop_force"} <= set(assembly.sensors)


BAD_STOPS = [
    ("missing-position", "recoil_stop.position", "<delete>", "recoil_stop.position", "missing"),
    ("recoil-stop-behind-the-start", "recoil_stop.position", 0.0, "recoil_stop.position", "> 0 m"),
    ("battery-stop-ahead-of-the-start", "battery_stop.position", 0.01, "battery_stop.position", "<= 0 m"),
    ("position-string", "battery_stop.position", "zero", "battery_stop.position", "must be a number"),
    ("missing-stiffness", "recoil_stop.stiffness", "<delete>", "recoil_stop.stiffness", "missing"),
    ("unknown-law", "battery_stop.law", "kelvin", "battery_stop.law", "did you mean 'kelvin-voigt'"),
    ("missing-damping", "battery_stop.damping", "<delete>", "battery_stop.damping", "missing"),
    ("unknown-key", "recoil_stop.positon", 0.2, "recoil_stop.positon", "did you mean 'position'"),
    ("not-a-table", "recoil_stop", 0.3, "recoil_stop", "must be a table"),
]


STOP_TABLES = {"recoil_stop": {"position": 0.3, "law": "hunt-crossley", "stiffness": 1.0e9, "exponent": 1.5,
                               "damping_factor": 0.5},
               "battery_stop": {"position": 0.0, "law": "kelvin-voigt", "stiffness": 5.0e7, "damping": 2.0e5}}


@pytest.mark.parametrize("path, value, key, text", [c[1:] for c in BAD_STOPS], ids=[c[0] for c in BAD_STOPS])
def test_bad_stop_tables_are_one_line_errors_naming_the_key(bad_input, v2_mapping, changed, path, value, key, text):
    bad_input(changed({**v2_mapping, **STOP_TABLES}, path, value), key, text)


def test_stops_need_a_version_2_scene(bad_input, v1_mapping):
    bad_input(dict(v1_mapping, recoil_stop=STOP_TABLES["recoil_stop"]), "recoil_stop", "version-2 scene")


# ------------------------------------------------------------------ the generic tests' scenes have the stops
def test_the_scene_of_every_element_has_the_stops(every_element):
    """The generic tests run on scenes composed by ``every_element``: with the shipped example's stops."""
    shipped = load_scene(scene_path("end_stops"))
    for base in (None, model_ii(100.0, 0.0)):
        scene = every_element(base)
        assert (scene.recoil_stop, scene.battery_stop) == (shipped.recoil_stop, shipped.battery_stop)


# ------------------------------------------------------------------ the reference: equations and names
def stops_design_rhs(scene, y, states, law_force):
    """dy/dt and dissipated powers of DESIGN.md's equations for a barrel with a recoil spring, the recoil
    damper and both stops: the recoil stop is a contact ground -> barrel with ``p = x_M - position`` (it
    pushes the barrel towards -x), the battery stop barrel -> ground with ``p = position - x_M`` (towards +x);
    ``law_force``: DESIGN.md's contact laws (the ``design`` fixture)."""
    x, v = y[0], y[1]
    damper = scene.recoil_damper
    c = damper.recoil if states["recoil_damper"] is not False else damper.counter_recoil
    f = -scene.recoil_spring.stiffness * x - c * v
    power = {"recoil_damper": c * v ** 2}
    for stop, sign in (("recoil_stop", 1.0), ("battery_stop", -1.0)):
        table = getattr(scene, stop)
        p, rate = sign * (x - table.position), sign * v
        F, elastic = law_force(table, p, rate, states[stop])
        f -= sign * F
        power[stop] = (F - elastic) * rate
    return [v, f / scene.barrel.mass], power


PAPER_BARREL = dict(barrel=Barrel(5600.0), firing=Firing(6.86, 564.0), recoil_spring=RecoilSpring(27500.0),
                    recoil_damper=RecoilDamper(6239.0, 14050.0))
RHS_STOPS = {
    "flores-kelvin-voigt": (dict(law="flores", stiffness=1e9, exponent=1.5, restitution=0.4),
                            dict(law="kelvin-voigt", stiffness=5e7, damping=2e5)),
    "hunt-crossley-hertz": (dict(law="hunt-crossley", stiffness=1e9, exponent=1.5, damping_factor=0.5),
                            dict(law="hertz", stiffness=1e9, exponent=1.2)),
    "exact-lankarani": (dict(law="exact-restitution", stiffness=1e9, exponent=1.5, restitution=0.3,
                             minimum_impact_velocity=0.01),
                        dict(law="lankarani-nikravesh", stiffness=1e8, exponent=1.3, restitution=0.6)),
    "gonthier-gonthier": (dict(law="gonthier", stiffness=1e9, exponent=1.5, restitution=0.5),
                          dict(law="gonthier", stiffness=1e8, exponent=1.0, restitution=0.7)),
}


@pytest.mark.parametrize("key", list(RHS_STOPS))
def test_reference_rhs_is_the_design_equations_of_the_stops(key, design):
    """The reference's right-hand side (and its numpy twin) of the barrel, its spring and damper and both stops
    equals DESIGN.md's equations written out above, in every mode, on random states."""
    recoil, battery = RHS_STOPS[key]
    scene = Scene(**PAPER_BARREL, recoil_stop=RecoilStop(position=0.15, **recoil),
                  battery_stop=BatteryStop(position=-0.01, **battery))
    design.check_rhs(scene, lambda *args: stops_design_rhs(*args, law_force=design.law_force), key)


def test_the_reference_names_the_stops_after_their_tables(every_element, design_connectors):
    """DESIGN.md: the stops' connectors are named like their tables, after the absorbers' (assembly order);
    both dissipate (one dissipated energy each in the state)."""
    scene = every_element()  # the shipped two absorbers, the shipped stops and every other element
    model = build_model(scene)
    assert [b.name for b in model.bodies] == ["barrel", "front", "rear"]
    assert model.names == design_connectors(scene)
    own = {"absorber": ["front_damper", "front_contact", "rear_damper", "rear_contact"],
           "recoil_stop": ["recoil_stop"], "battery_stop": ["battery_stop"]}  # each table's connectors
    named = {name for names in own.values() for name in names}
    assert [n for n in model.names if n in named] == [n for key in TABLES for n in own.get(key, [])]  # registry order
    dissipating = [c.name for c in model.dissipating]
    assert {"recoil_stop", "battery_stop"} <= set(dissipating)
    assert model.n_states == 2 * 3 + len(dissipating) + len(model.work_slot)  # then the work of the inputs


#: model (ii), m = 100 kg, with a hard recoil stop and a Kelvin-Voigt buffer 20 mm behind battery
II_STOPS = model_ii(100.0, 0.0).with_changes(
    recoil_stop=RecoilStop(position=0.12, law="hunt-crossley", stiffness=1e9, exponent=1.5, damping_factor=0.5),
    battery_stop=BatteryStop(position=-0.02, law="kelvin-voigt", stiffness=5e7, damping=2e5))


@pytest.fixture(scope="module")
def ii_stops_reference():
    return solve_reference(II_STOPS, 2.0)


def test_the_stops_push_the_mount_in_opposite_directions_in_the_reference(ii_stops_reference):
    """Support force of the reference: the recoil stop (ground -> barrel) adds +F, the battery stop (barrel ->
    ground) -F, to the paper's S = k x_M + c(v_M) v_M + k_r x_m + c_r v_m."""
    r = ii_stops_reference
    t = np.linspace(0.0, 2.0, 4001)
    x, v, x_m, v_m = r.position("barrel", t), r.velocity("barrel", t), r.position("absorber", t), r.velocity("absorber", t)
    c = np.where(v > 0, 6239.0, 14050.0)
    expected = 27500.0 * x + c * v + 13500.0 * x_m + 3675.0 * v_m \
        + r.connector_force("recoil_stop", t) - r.connector_force("battery_stop", t)
    np.testing.assert_allclose(r.support_force(t), expected, rtol=1e-12, atol=1e-9 * np.max(np.abs(expected)))
    assert np.any(r.connector_force("recoil_stop", t) > 0) and np.any(r.connector_force("battery_stop", t) > 0)


def test_the_reference_reports_each_stop(ii_stops_reference):
    """Per-stop metrics, energies and the metrics dictionary of the reference, keyed by the stops' names."""
    r = ii_stops_reference
    stops = {"recoil_stop", "battery_stop"}
    assert r.connectors[-2:] == ("recoil_stop", "battery_stop")
    assert set(r.contacts) == {"contact"} | stops and set(r.stop_metrics) == stops
    assert stops <= set(r.dissipated_energy) and stops <= set(r.stored_energy(0.1))
    for name, stop in r.stop_metrics.items():
        assert stop.name == name and stop.impacts and stop.impacts == r.contacts[name].impacts
        assert all(i.contact == name for i in stop.impacts)
        assert stop.dissipated_energy == r.dissipated_energy[name] > 0
        assert stop.peak_force == max(e.peak_force for e in stop.episodes)
    assert {i.contact for i in r.impacts} == {"contact"}  # the stops' impacts are not the absorber's
    m = r.metrics()
    assert set(m["stops"]) == stops and m["stops"]["recoil_stop"]["dissipated_energy"] > 0


def test_an_unreachable_stop_changes_nothing():
    plain = model_ii(1000.0, 0.0)
    far = plain.with_changes(recoil_stop=RecoilStop(position=1.0, stiffness=1e9, exponent=1.5, damping_factor=0.5),
                             battery_stop=BatteryStop(position=-1.0, law="hertz", stiffness=1e9, exponent=1.5))
    a, b = solve_reference(plain, 3.0), solve_reference(far, 3.0)
    for name in ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "peak_support_force"):
        assert getattr(b, name) == pytest.approx(getattr(a, name), rel=1e-9, abs=1e-12)
    assert set(b.stop_metrics) == {"recoil_stop", "battery_stop"}
    assert all(m.episodes == [] and m.peak_force == 0.0 for m in b.stop_metrics.values())


# ------------------------------------------------------------------ the reference: hard cases
LN = dict(law="lankarani-nikravesh", stiffness=1e8, exponent=1.5, restitution=0.5)
CHI = 3 * (1 - 0.5 ** 2) / 4   # Lankarani-Nikravesh's chi for e = 0.5
FLOOR = 1e-3                   # the default minimum_impact_velocity, m/s


def test_battery_stop_touching_a_barrel_at_rest(assert_sound):
    """p = 0, p' = 0, p'' = 0 at the battery stop: nothing moves, no force, no division by v- = 0."""
    scene = Scene(barrel=Barrel(5600.0, initial_velocity=0.0), recoil_spring=RecoilSpring(27500.0),
                  recoil_damper=RecoilDamper(6239.0, 14050.0), battery_stop=BatteryStop(position=0.0, **LN))
    r = solve_reference(scene, 1.0)
    assert_sound(r, 1.0)
    assert r.initial_energy == 0.0 and r.max_barrel_displacement == 0.0
    assert r.stop_metrics["battery_stop"].peak_force == 0.0 and r.stop_metrics["battery_stop"].episodes == []
    assert r.peak_support_force == 0.0


def test_grazing_return_onto_the_battery_stop(assert_sound):
    """The barrel returns past x = 0 and turns; a battery stop 2e-8 m short of that turning point is met at
    v- ~ 2e-4 m/s, below minimum_impact_velocity: the law damps as Hunt-Crossley with lambda = chi / 1 mm/s,
    the force stays finite and >= 0, and the energy balance closes."""
    base = Scene(**PAPER_BARREL)
    free = solve_reference(base, 4.0)
    t = np.linspace(0.0, 4.0, 40001)
    i = int(np.argmin(free.barrel_position(t)))
    turn = minimize_scalar(free.barrel_position, bounds=(t[i - 1], t[i + 1]), method="bounded",
                           options={"xatol": 1e-12})
    x_min, a_turn = float(turn.fun), float(free.acceleration("barrel", turn.x))
    v_target = 2e-4
    position = x_min + v_target ** 2 / (2 * a_turn)
    r = solve_reference(base.with_changes(battery_stop=BatteryStop(position=position, **LN)), 4.0)
    onsets = r.contacts["battery_stop"].onsets
    assert len(onsets) == 1
    t_on, v_minus = onsets[0]
    assert v_minus == pytest.approx(v_target, rel=0.05) and v_minus < FLOOR
    state = next(s.mode["battery_stop"] for s in r.segments if s.t0 == t_on)
    assert state.factor == pytest.approx(CHI / FLOOR, rel=1e-15)
    assert_sound(r, 4.0)
    stop = r.stop_metrics["battery_stop"]
    assert 0 < stop.peak_force < 1000.0 and stop.impacts == []  # a touch, not an impact


SPEED = 10  # times the paper's muzzle velocity: v0 = 6.9 m/s
STOP_LAWS = {
    "hunt-crossley": dict(law="hunt-crossley", stiffness=1e9, exponent=1.5, damping_factor=0.5),
    "flores": dict(law="flores", stiffness=1e9, exponent=1.5, restitution=0.5),
    "exact-restitution": dict(law="exact-restitution", stiffness=1e9, exponent=1.5, restitution=0.2),
    "kelvin-voigt": dict(law="kelvin-voigt", stiffness=1e8, damping=1e6),
    "hertz": dict(law="hertz", stiffness=1e9, exponent=1.5),
}


@pytest.mark.parametrize("law", list(STOP_LAWS))
def test_reference_stops_hit_at_ten_times_the_firing_velocity(law, assert_sound):
    scene = model_ii(1000.0, 0.0).with_changes(
        firing=Firing(6.86, 564.0 * SPEED), recoil_stop=RecoilStop(position=0.15, **STOP_LAWS[law]),
        battery_stop=BatteryStop(position=-0.05, law="kelvin-voigt", stiffness=5e7, damping=2e5))
    end = 3.0
    r = solve_reference(scene, end)
    assert_sound(r, end, balance=1e-7)
    energy = r.initial_energy
    assert energy == pytest.approx(0.5 * 5600.0 * (6.86 * 5640.0 / 5600.0) ** 2, rel=1e-14)
    stop = r.stop_metrics["recoil_stop"]
    assert stop.impacts and stop.impacts[0].peak_force > 1e5
    spec = STOP_LAWS[law]
    n = spec.get("exponent", 1.0)
    own = ((n + 1) * energy / spec["stiffness"]) ** (1 / (n + 1))  # the stop's potential cannot exceed E(0)
    assert 0.15 < r.max_barrel_displacement < 0.15 + own
    if law == "hertz":
        assert stop.dissipated_energy == pytest.approx(0.0, abs=1e-8 * energy)
    else:
        assert stop.dissipated_energy > 0
    t = np.linspace(0.0, end, 20001)
    x = r.barrel_position(t)
    np.testing.assert_array_equal(r.connector_force("recoil_stop", t)[x < 0.15 - 1e-12], 0.0)
    np.testing.assert_array_equal(r.connector_force("battery_stop", t)[x > -0.05 + 1e-12], 0.0)


# ------------------------------------------------------------------ the engine against the reference
#: name -> (scene, end time in s): the shipped example, stops of every law, stops hit at ten times the muzzle
#: velocity (each case hits both stops)
ENGINE_CASES = {
    "end_stops": (load_scene(scene_path("end_stops")), 3.0),
    **{f"law-{law}": (with_stops(model_ii(1000.0, 0.0), law), 3.0) for law in sorted(CONTACT_LAWS)},
    **{f"10x-{law}": (with_stops(simplified_model(), law, 0.1).with_changes(**{"firing.muzzle_velocity": 5640.0}),
                      2.0) for law in ("hunt-crossley", "kelvin-voigt", "exact-restitution")},
}


@pytest.mark.parametrize("name", list(ENGINE_CASES))
def test_engine_against_reference_standard(name, agrees_with_reference):
    scene, end = ENGINE_CASES[name]
    agrees_with_reference(scene, end, "standard")
    ref = reference_for(scene, end, (), "standard")  # the reference that was compared (cached)
    assert all(ref.stop_metrics[stop].impacts for stop in ("recoil_stop", "battery_stop"))  # both stops are hit


@pytest.mark.slow
@pytest.mark.parametrize("accuracy", list(TOLERANCES))
@pytest.mark.parametrize("name", list(ENGINE_CASES))
def test_engine_against_reference_every_preset(name, accuracy, agrees_with_reference):
    agrees_with_reference(*ENGINE_CASES[name], accuracy)


def test_the_brake_design_refuses_a_recoil_length_beyond_the_recoil_stop():
    """``recoil design-brake`` (mbs_models.studies.brake_design) finds a stop within the stroke generically."""
    from mbs_models import SceneError
    from mbs_models.studies.brake_design import design_brake

    stop = RecoilStop(position=0.2, stiffness=1e9, exponent=1.5, damping_factor=0.5)
    with pytest.raises(SceneError, match=r"shorter than the position of \[recoil_stop\] \(0.2 m\)"):
        design_brake(simplified_model().with_changes(recoil_stop=stop), 0.22)
    assert design_brake(simplified_model().with_changes(recoil_stop=stop), 0.18).recoil_length == 0.18


def test_a_recoil_stop_out_of_reach_names_its_position():
    """A stop position typed in mm (120 for 120 mm) is reported before any solve (mbs_models/engine/reach.py),
    with the undamped free recoil's sqrt(2 E0 / k) as the barrel's reach."""
    import math

    from mbs_models.engine.energy_bounds import ENERGY_SLACK
    from mbs_models.engine.reach import contacts_out_of_reach

    scene = load_scene(scene_path("end_stops")).with_changes(**{"recoil_stop.position": 120.0})
    [found] = contacts_out_of_reach(scene)
    assert found.key == "recoil_stop.position" and found.length == 120.0
    energy = 0.5 * scene.barrel.mass * scene.initial_velocity ** 2
    assert found.reach == pytest.approx(math.sqrt(2.0 * energy * (1.0 + ENERGY_SLACK) / scene.recoil_spring.stiffness),
                                        rel=1e-9)
