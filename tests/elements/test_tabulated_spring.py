"""The tabulated spring (mbs_models.elements.tabulated_spring, validation/reference/terms/tabulated_spring.py): a
force-displacement table F(x) between the ground and the barrel.  Its table and errors, the closed forms (a
two-point table is the linear recoil spring; the stored energy is the integral of the table), the engine against
the reference at every preset, the energy balance, several springs acting together, CSV input, the Exudyn items,
the backends, the early stop and the warning of a run that leaves the table.

Expected values come from DESIGN.md's equations written here with numpy/scipy (:func:`design_force`), from the
linear recoil spring's own run, or from the independent reference, never from the element under test."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import quad

from mbs_models import (Barrel, BatteryStop, Firing, RecoilDamper, RecoilSpring, RecoilStop, Scene, SceneError,
                        TabulatedSpring, load_scene, scene_from_dict, simulate)
from mbs_models.cli import main
from mbs_models.elements.characteristic import TableRangeWarning
from mbs_models.engine.assembly import assemble
from mbs_models.scenes import scene_path
from validation.studies.guarantee import TOLERANCES, errors_against_reference, physical_violations, reference_for, violations

PRESETS = list(TOLERANCES)
M, K = 5600.0, 27500.0                 # kg, N/m: the paper's barrel and recoil spring
DAMPER = RecoilDamper(6239.0, 14050.0)  # N s/m: the paper's asymmetric damper
PROGRESSIVE = ((-0.1, -2600.0), (0.0, 0.0), (0.05, 1400.0), (0.1, 2900.0), (0.15, 4600.0), (0.2, 6500.0),
               (0.25, 8700.0), (0.3, 11600.0), (0.4, 17400.0))   # the shipped example's table (x m, F N)
SHIPPED = load_scene(scene_path("tabulated_spring"))


def design_force(points, x):
    """DESIGN.md: F linear between the points, the end segments extended (N)."""
    xs, fs = np.array([p[0] for p in points]), np.array([p[1] for p in points])
    x = np.asarray(x, dtype=float)
    inside = np.interp(x, xs, fs)
    below = (fs[1] - fs[0]) / (xs[1] - xs[0]) * np.minimum(x - xs[0], 0.0)
    above = (fs[-1] - fs[-2]) / (xs[-1] - xs[-2]) * np.maximum(x - xs[-1], 0.0)
    return inside + below + above


def scene_with(*springs, **tables) -> Scene:
    """The paper's simplified model (firing, asymmetric damper) with ``springs`` instead of its recoil spring."""
    return Scene(barrel=Barrel(M), firing=Firing(6.86, 564.0), recoil_damper=DAMPER, tabulated_springs=springs,
                 **tables)


def base_dict(**spring) -> dict:
    return {"version": 2, "barrel": {"mass": M}, "firing": {"projectile_mass": 6.86, "muzzle_velocity": 564.0},
            "tabulated_spring": [{"name": "s", "points": [[0.0, 0.0], [0.5, 13750.0]], **spring}]}


# ================================================================================================ the table
@pytest.mark.parametrize("change, key, words", [
    ({"points": None}, "tabulated_spring.points", "either points"),
    ({"file": "x.csv"}, "tabulated_spring.points", "either points"),
    ({"points": [[0.0, 0.0]]}, "tabulated_spring.points", "at least 2"),
    ({"points": "0,0"}, "tabulated_spring.points", "list of at least 2 pairs"),
    ({"points": [[0.0, 0.0], [0.5]]}, "tabulated_spring.points.1", "pair"),
    ({"points": [[0.0, 0.0], [0.5, "a"]]}, "tabulated_spring.points.1", "number"),
    ({"points": [[0.0, 0.0], [0.5, math.inf]]}, "tabulated_spring.points.1", "finite"),
    ({"points": [[0.0, 0.0], [math.nan, 1.0]]}, "tabulated_spring.points.1", "finite"),
    ({"points": [[0.0, 0.0], [0.0, 1.0]]}, "tabulated_spring.points.1", "strictly increasing"),
    ({"points": [[0.1, 0.0], [0.5, 1.0]]}, "tabulated_spring.points", "rest point"),
    ({"points": [[0.0, 10.0], [0.5, 20.0]]}, "tabulated_spring.points", "rest point"),
    ({"points": [[0.0, 0.0], [0.2, 500.0], [0.5, 400.0]]}, "tabulated_spring.points.2", "must not decrease"),
    ({"name": "barrel"}, "tabulated_spring.name", "identifier"),
    ({"name": "2x"}, "tabulated_spring.name", "identifier"),
    ({"stiffness": 1.0}, "tabulated_spring.stiffness", "unknown key"),
])
def test_bad_input_names_the_key(change, key, words):
    data = base_dict(**change)
    data["tabulated_spring"][0] = {k: v for k, v in data["tabulated_spring"][0].items() if v is not None}
    with pytest.raises(SceneError) as info:
        scene_from_dict(data)
    assert info.value.key == key and words in info.value.message, str(info.value)
    assert "\n" not in str(info.value)


def test_the_name_is_required_and_unique():
    data = base_dict()
    del data["tabulated_spring"][0]["name"]
    with pytest.raises(SceneError, match="missing required key") as info:
        scene_from_dict(data)
    assert info.value.key == "tabulated_spring.name"
    data = base_dict()
    data["tabulated_spring"].append(dict(data["tabulated_spring"][0]))
    with pytest.raises(SceneError, match="taken") as info:
        scene_from_dict(data)
    assert info.value.key == "tabulated_spring.1.name"
    data = base_dict(name="recoil_damper")
    data["recoil_damper"] = {"recoil": 1.0, "counter_recoil": 1.0}
    with pytest.raises(SceneError, match="taken"):
        scene_from_dict(data)


def test_a_version_1_scene_cannot_have_it():
    data = {**base_dict(), "version": 1}
    with pytest.raises(SceneError, match="version"):
        scene_from_dict(data)


def test_bad_input_on_the_command_line_is_one_line_and_exit_2(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text('version = 2\n[barrel]\nmass = 5600.0\ninitial_velocity = 0.69\n'
                    '[[tabulated_spring]]\nname = "s"\npoints = [[0.0, 0.0], [0.2, 500.0], [0.5, 400.0]]\n')
    assert main(["run", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "tabulated_spring.points.2" in err[0] and "Traceback" not in err[0]


def test_csv_beside_the_scene_gives_the_same_run(tmp_path):
    (tmp_path / "spring.csv").write_text("displacement,force\n" + "".join(f"{x!r},{f!r}\n" for x, f in PROGRESSIVE))
    text = scene_path("tabulated_spring").read_text()
    start = text.index("points = ")
    end = text.index("\n\n", start)
    (tmp_path / "scene.toml").write_text(text[:start] + 'file = "spring.csv"' + text[end:])
    from_file = load_scene(tmp_path / "scene.toml")
    assert from_file.tabulated_springs[0].pairs == PROGRESSIVE == SHIPPED.tabulated_springs[0].pairs
    a, b = simulate(from_file, 1.0), simulate(SHIPPED, 1.0)
    np.testing.assert_array_equal(a.barrel_position, b.barrel_position)  # the same table: the same run, bit for bit


@pytest.mark.parametrize("content, words", [
    ("displacement,force\n0.0,0.0\n", "at least two rows"),
    ("displacement,force\n0.0,0.0\n0.1,a\n", "line 3: not numbers"),
    ("displacement,force\n0.0,0.0\n0.1,1.0,2.0\n", "two columns"),
])
def test_a_bad_csv_names_the_file_key(tmp_path, content, words):
    (tmp_path / "spring.csv").write_text(content)
    data = base_dict(file=str(tmp_path / "spring.csv"))
    del data["tabulated_spring"][0]["points"]
    with pytest.raises(SceneError, match=words) as info:
        scene_from_dict(data)
    assert info.value.key == "tabulated_spring.file"
    data["tabulated_spring"][0]["file"] = str(tmp_path / "missing.csv")
    with pytest.raises(SceneError, match="not found"):
        scene_from_dict(data)


def test_a_csv_table_is_checked_like_an_inline_one(tmp_path):
    (tmp_path / "spring.csv").write_text("displacement,force\n0.0,0.0\n0.2,500.0\n0.5,400.0\n")
    data = base_dict(file=str(tmp_path / "spring.csv"))
    del data["tabulated_spring"][0]["points"]
    with pytest.raises(SceneError, match="must not decrease") as info:
        scene_from_dict(data)
    assert info.value.key == "tabulated_spring.file"


def test_the_scene_round_trips_through_toml():
    from mbs_models import scene_to_toml
    from mbs_models.scene.io import parse_toml
    again = scene_from_dict(parse_toml(scene_to_toml(SHIPPED), "", "x"))
    assert again.tabulated_springs == SHIPPED.tabulated_springs


# ================================================================================================ the law
def test_force_energy_and_bounds_follow_design():
    connector = TabulatedSpring("s", PROGRESSIVE).connectors(SHIPPED, "s")[0]
    x = np.linspace(-0.3, 0.7, 1001)
    np.testing.assert_allclose(connector.force(x, 0.0 * x), design_force(PROGRESSIVE, x), rtol=1e-13, atol=1e-9)
    for xi in (-0.25, -0.1, -0.03, 0.0, 0.07, 0.2, 0.33, 0.4, 0.55):
        expected, _ = quad(lambda s: float(design_force(PROGRESSIVE, s)), 0.0, xi,
                           points=[p[0] for p in PROGRESSIVE if min(0, xi) < p[0] < max(0, xi)], epsabs=1e-12)
        assert connector.python_stored_energy(xi) == pytest.approx(expected, rel=1e-12, abs=1e-9)
        bound = connector.force_bound(abs(xi), 0.0, 0.0)
        assert bound == pytest.approx(np.max(np.abs(design_force(PROGRESSIVE, np.linspace(-abs(xi), abs(xi), 2001)))),
                                      rel=1e-12, abs=1e-9)
    assert connector.linear_stiffness == pytest.approx((17400.0 - 11600.0) / 0.1)  # the steepest segment
    assert connector.stores_energy and not connector.dissipates and not connector.quadratic_potential


def test_symbolic_and_python_backends_agree():
    a = simulate(SHIPPED, 1.0, user_functions="symbolic")
    b = simulate(SHIPPED, 1.0, user_functions="python")
    np.testing.assert_allclose(a.barrel_position, b.barrel_position, rtol=0, atol=1e-9)


# ================================================================================================ closed forms
@pytest.mark.parametrize("accuracy", PRESETS)
def test_a_two_point_table_is_the_linear_recoil_spring(accuracy):
    """F = k x through (0, 0) and (0.5, k 0.5), extended: the recoil spring's run within the preset's guarantee."""
    linear = simulate(Scene(barrel=Barrel(M), firing=Firing(6.86, 564.0), recoil_spring=RecoilSpring(K),
                            recoil_damper=DAMPER), 3.0, accuracy)
    with pytest.warns(TableRangeWarning, match="reached \\[-0.02"):  # the return past battery: the line extended
        tabulated = simulate(scene_with(TabulatedSpring("k", ((0.0, 0.0), (0.5, K * 0.5)))), 3.0, accuracy)
    tolerance = TOLERANCES[accuracy]
    assert tabulated.max_barrel_displacement == pytest.approx(linear.max_barrel_displacement, rel=tolerance["metric"])
    assert tabulated.peak_support_force == pytest.approx(linear.peak_support_force, rel=tolerance["force"])
    e0 = linear.kinetic_energy_history[0]
    assert abs(tabulated.energy()["k"]["stored"] - linear.energy()["recoil_spring"]["stored"]) <= tolerance["metric"] * e0


# ================================================================================================ engine = reference
def _agree(scene, end, accuracy):
    result = simulate(scene, end, accuracy)
    tolerance = TOLERANCES[accuracy]
    assert not physical_violations(result, tolerance["energy"])
    ref = reference_for(scene, end, (), accuracy)
    errors = errors_against_reference(result, ref, tolerance["time"])
    assert not violations(errors, accuracy), errors
    return result


CASES = {
    "shipped": SHIPPED,
    "with stops": scene_with(TabulatedSpring("progressive", PROGRESSIVE),
                             recoil_stop=RecoilStop(position=0.15, law="hunt-crossley", stiffness=1e8, exponent=1.5,
                                                    damping_factor=0.5),
                             battery_stop=BatteryStop(position=0.0, law="kelvin-voigt", stiffness=5e7, damping=2e5)),
    "two springs": scene_with(TabulatedSpring("front", ((-0.1, -800.0), (0.0, 0.0), (0.1, 1000.0), (0.3, 6000.0))),
                              TabulatedSpring("rear", ((-0.2, -3000.0), (0.0, 0.0), (0.25, 5000.0)))),
}


@pytest.mark.parametrize("accuracy", PRESETS)
@pytest.mark.parametrize("name", list(CASES))
def test_engine_equals_reference(name, accuracy):
    _agree(CASES[name], 3.0, accuracy)


def test_energy_balance():
    result = simulate(SHIPPED, 5.0, "reference")
    e0 = result.kinetic_energy_history[0]
    assert float(np.max(np.abs(result.energy_error()))) <= TOLERANCES["reference"]["energy"] * e0
    assert result.energy()["progressive_spring"]["dissipated"] == 0.0


def test_several_springs_act_as_their_sum():
    """Two tables acting together are one table of their sums (at the union of their points): the same run
    within the preset's guarantee."""
    front, rear = CASES["two springs"].tabulated_springs
    xs = sorted({x for x, _ in front.pairs} | {x for x, _ in rear.pairs})
    summed = tuple((x, float(design_force(front.pairs, x) + design_force(rear.pairs, x))) for x in xs)
    together = simulate(CASES["two springs"], 3.0, "reference")
    one = simulate(scene_with(TabulatedSpring("sum", summed)), 3.0, "reference")
    tolerance = TOLERANCES["reference"]
    assert together.max_barrel_displacement == pytest.approx(one.max_barrel_displacement, rel=tolerance["metric"])
    energy = together.energy()
    e0 = together.kinetic_energy_history[0]
    assert abs(energy["front"]["stored"] + energy["rear"]["stored"] - one.energy()["sum"]["stored"]) <= 1e-6 * e0


# ================================================================================================ Exudyn items
def test_only_assembled_when_the_scene_has_the_table():
    without = Scene(barrel=Barrel(M), firing=Firing(6.86, 564.0), recoil_damper=DAMPER)
    with assemble(without) as assembly:
        assert set(assembly.connectors) == {"recoil_damper"}
        objects = assembly.mbs.systemData.NumberOfObjects()
    with assemble(SHIPPED, fold=False) as assembly:  # one item per connector: the spring's own
        assert assembly.mbs.systemData.NumberOfObjects() == objects + 1
    with assemble(SHIPPED) as assembly:  # folded into the recoil damper's item (the same ends: engine/folding.py)
        assert set(assembly.connectors) == {"progressive_spring", "recoil_damper"}
        assert "progressive_spring" in assembly.user_function_connectors
        assert assembly.mbs.systemData.NumberOfObjects() == objects
        assert assembly.connectors["progressive_spring"] == assembly.connectors["recoil_damper"]


# ================================================================================================ beyond the table
def test_a_run_that_leaves_the_table_says_so():
    short = scene_with(TabulatedSpring("short", ((0.0, 0.0), (0.05, K * 0.05))))
    with pytest.warns(TableRangeWarning, match=r"tabulated_spring: the run's displacement reached .* beyond the "
                                               r"table's \[0, 0.05\] m"):
        result = simulate(short, 3.0)
    linear = simulate(Scene(barrel=Barrel(M), firing=Firing(6.86, 564.0), recoil_spring=RecoilSpring(K),
                            recoil_damper=DAMPER), 3.0)
    # extrapolated: the end segment's line, here the linear spring
    assert result.max_barrel_displacement == pytest.approx(linear.max_barrel_displacement, rel=TOLERANCES["standard"]["metric"])
    with warnings.catch_warnings():
        warnings.simplefilter("error", TableRangeWarning)
        simulate(SHIPPED, 3.0)  # the shipped table covers its run


@pytest.mark.parametrize("name", ["shipped", "with stops"])
def test_the_early_stop_agrees_with_the_full_run(name):
    """The spring's potential well (alone, or with the barrel's stops) bounds the rest of the run: the early stop
    proves the peaks final well before the end, with the full run's values."""
    full = simulate(CASES[name], 5.0)
    early = simulate(CASES[name], 5.0, stop_when_final=("max_barrel_displacement", "peak_support_force"))
    assert early.stop_reason == "metrics_final" and early.time[-1] < 5.0
    assert early.max_barrel_displacement == pytest.approx(full.max_barrel_displacement, rel=1e-9)
    assert early.peak_support_force == pytest.approx(full.peak_support_force, rel=1e-9)


def test_a_table_in_mm_gets_a_unit_warning():
    from mbs_models import UnitWarning
    in_mm = scene_with(TabulatedSpring("mm", ((0.0, 0.0), (100.0, 2750.0), (400.0, 17400.0))))
    with pytest.warns(UnitWarning, match=r"tabulated_spring.points reaches a displacement of 400 m .*in mm\?"):
        simulate(in_mm, 0.5)


def test_building_block_in_your_own_system():
    """add_tabulated_spring between two markers of a system of one's own: a mass at v0 on the two-point table
    (a linear spring k) oscillates as x = v0 / w sin(w t), w = sqrt(k / m)."""
    import exudyn
    from exudyn.itemInterface import MarkerNodeCoordinate, NodePointGround, SensorNode

    from mbs_models import add_body, add_tabulated_spring
    system = exudyn.SystemContainer()
    mbs = system.AddSystem()
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    mass, v0 = 100.0, 0.5
    node, marker = add_body(mbs, mass, v0)
    connector = add_tabulated_spring(mbs, ground, marker, TabulatedSpring("k", ((0.0, 0.0), (1.0, K))))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=exudyn.OutputVariableType.Coordinates,
                                      storeInternal=True))
    mbs.Assemble()
    settings = exudyn.SimulationSettings()
    ti = settings.timeIntegration
    ti.endTime, ti.numberOfSteps, ti.automaticStepSize = 0.2, 100, True
    ti.relativeTolerance, ti.absoluteTolerance, ti.verboseMode = 1e-10, 1e-12, 0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = 0.0
    mbs.SolveDynamic(settings, solverType=exudyn.DynamicSolverType.DOPRI5)
    t, x = mbs.GetSensorStoredData(sensor).T
    w = math.sqrt(K / mass)
    np.testing.assert_allclose(x, v0 / w * np.sin(w * t), rtol=0, atol=1e-8)
    assert connector.index is not None
    system.Reset()


def test_the_reference_term_follows_design():
    """The reference's spring (validation/reference/terms/tabulated_spring.py) against DESIGN.md written out here:
    its force at rest and its potential (scipy's quadrature of the extended table)."""
    from validation.reference.terms.tabulated_spring import TabulatedSpring as ReferenceSpring
    spring = ReferenceSpring("s", "ground", "barrel", PROGRESSIVE)
    for x in (-0.25, -0.1, -0.03, 0.0, 0.07, 0.2, 0.33, 0.4, 0.55):
        expected, _ = quad(lambda s: float(design_force(PROGRESSIVE, s)), 0.0, x,
                           points=[p[0] for p in PROGRESSIVE if min(0, x) < p[0] < max(0, x)], epsabs=1e-12)
        assert spring.stored_energy(x) == pytest.approx(expected, rel=1e-12, abs=1e-9)
        assert spring.static_force(x) == pytest.approx(float(design_force(PROGRESSIVE, x)), rel=1e-13, abs=1e-9)
        assert spring.force_bound(abs(x), 0.0, 0.0) >= abs(float(design_force(PROGRESSIVE, -abs(x))))
