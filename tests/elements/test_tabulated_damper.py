"""The tabulated damper (mbs_models.elements.tabulated_damper, validation/reference/terms/tabulated_damper.py): a
force-velocity table F(v) between the ground and the barrel.  Its table and errors, the closed form (a linear
table is the symmetric recoil damper), the engine against the reference at every preset, the energy balance,
several dampers acting together, CSV input, the Exudyn items, the backends and the warning of a run that leaves
the table.

Expected values come from DESIGN.md's equations written here with numpy (:func:`design_force`), from the linear
recoil damper's own run, or from the independent reference, never from the element under test."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from mbs_models import (Barrel, Firing, RecoilDamper, RecoilSpring, Scene, SceneError, TabulatedDamper, load_scene,
                        scene_from_dict, simulate)
from mbs_models.cli import main
from mbs_models.elements.characteristic import TableRangeWarning
from mbs_models.engine.assembly import assemble
from mbs_models.scenes import scene_path
from validation.studies.guarantee import TOLERANCES, errors_against_reference, physical_violations, reference_for, violations

PRESETS = list(TOLERANCES)
M, K, C = 5600.0, 27500.0, 6239.0         # kg, N/m, N s/m: the paper's barrel, recoil spring, recoil damping
MEASURED = ((-1.0, -12500.0), (-0.5, -7000.0), (-0.2, -2900.0), (0.0, 0.0), (0.2, 1350.0), (0.5, 3200.0),
            (0.8, 4800.0), (1.5, 8000.0))  # the shipped example's table (v m/s, F N)
SHIPPED = load_scene(scene_path("tabulated_damper"))


def design_force(points, v):
    """DESIGN.md: F linear between the points, the end segments extended (N)."""
    vs, fs = np.array([p[0] for p in points]), np.array([p[1] for p in points])
    v = np.asarray(v, dtype=float)
    below = (fs[1] - fs[0]) / (vs[1] - vs[0]) * np.minimum(v - vs[0], 0.0)
    above = (fs[-1] - fs[-2]) / (vs[-1] - vs[-2]) * np.maximum(v - vs[-1], 0.0)
    return np.interp(v, vs, fs) + below + above


def scene_with(*dampers, **tables) -> Scene:
    """The paper's simplified model (firing, recoil spring) with ``dampers`` instead of its recoil damper."""
    return Scene(barrel=Barrel(M), firing=Firing(6.86, 564.0), recoil_spring=RecoilSpring(K), tabulated_dampers=dampers,
                 **tables)


def base_dict(**damper) -> dict:
    return {"version": 2, "barrel": {"mass": M}, "firing": {"projectile_mass": 6.86, "muzzle_velocity": 564.0},
            "tabulated_damper": [{"name": "d", "points": [[-1.0, -C], [0.0, 0.0], [1.0, C]], **damper}]}


# ================================================================================================ the table
@pytest.mark.parametrize("change, key, words", [
    ({"points": None}, "tabulated_damper.points", "either points"),
    ({"points": [[0.0, 0.0]]}, "tabulated_damper.points", "at least 2"),
    ({"points": [[0.0, 0.0], [1.0, "x"]]}, "tabulated_damper.points.1", "number"),
    ({"points": [[0.0, 0.0], [1.0, math.inf]]}, "tabulated_damper.points.1", "finite"),
    ({"points": [[0.0, 0.0], [-1.0, -1.0]]}, "tabulated_damper.points.1", "strictly increasing"),
    ({"points": [[-1.0, -10.0], [1.0, 10.0]]}, "tabulated_damper.points", "rest point"),
    ({"points": [[0.0, 5.0], [1.0, 10.0]]}, "tabulated_damper.points", "rest point"),
    ({"points": [[-1.0, 10.0], [0.0, 0.0], [1.0, 10.0]]}, "tabulated_damper.points.0", "passive"),
    ({"points": [[0.0, 0.0], [1.0, -10.0]]}, "tabulated_damper.points.1", "passive"),
    ({"points": [[0.0, 0.0], [1.0, 1000.0], [2.0, 900.0]]}, "tabulated_damper.points.2", "end segment"),
    ({"points": [[-2.0, -900.0], [-1.0, -1000.0], [0.0, 0.0]]}, "tabulated_damper.points.0", "end segment"),
    ({"name": "ground"}, "tabulated_damper.name", "identifier"),
    ({"damping": 1.0}, "tabulated_damper.damping", "unknown key"),
])
def test_bad_input_names_the_key(change, key, words):
    data = base_dict(**change)
    data["tabulated_damper"][0] = {k: v for k, v in data["tabulated_damper"][0].items() if v is not None}
    with pytest.raises(SceneError) as info:
        scene_from_dict(data)
    assert info.value.key == key and words in info.value.message, str(info.value)
    assert "\n" not in str(info.value)


def test_bad_input_on_the_command_line_is_one_line_and_exit_2(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text('version = 2\n[barrel]\nmass = 5600.0\ninitial_velocity = 0.69\n'
                    '[[tabulated_damper]]\nname = "d"\npoints = [[-1.0, 10.0], [0.0, 0.0], [1.0, 10.0]]\n')
    assert main(["run", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "tabulated_damper.points.0" in err[0] and "passive" in err[0]


def test_csv_beside_the_scene_gives_the_same_run(tmp_path):
    (tmp_path / "damper.csv").write_text("velocity,force\n" + "".join(f"{v!r},{f!r}\n" for v, f in MEASURED))
    text = scene_path("tabulated_damper").read_text()
    start = text.index("points = ")
    (tmp_path / "scene.toml").write_text(text[:start] + 'file = "damper.csv"\n')
    from_file = load_scene(tmp_path / "scene.toml")
    assert from_file.tabulated_dampers[0].pairs == MEASURED == SHIPPED.tabulated_dampers[0].pairs
    a, b = simulate(from_file, 1.0), simulate(SHIPPED, 1.0)
    np.testing.assert_array_equal(a.barrel_position, b.barrel_position)  # the same table: the same run, bit for bit


def test_a_bad_csv_names_the_file_key(tmp_path):
    (tmp_path / "damper.csv").write_text("velocity,force\n-1.0,10.0\n0.0,0.0\n1.0,10.0\n")
    data = base_dict(file=str(tmp_path / "damper.csv"))
    del data["tabulated_damper"][0]["points"]
    with pytest.raises(SceneError, match="passive") as info:
        scene_from_dict(data)
    assert info.value.key == "tabulated_damper.file"


# ================================================================================================ the law
def test_force_power_and_bounds_follow_design():
    connector = TabulatedDamper("d", MEASURED).connectors(SHIPPED, "d")[0]
    v = np.linspace(-2.0, 2.5, 901)
    np.testing.assert_allclose(connector.force(0.0 * v, v), design_force(MEASURED, v), rtol=1e-13, atol=1e-9)
    assert np.all(design_force(MEASURED, v) * v >= 0)  # passive, extrapolation included
    for bound in (0.1, 0.5, 1.2, 3.0):
        grid = np.linspace(-bound, bound, 4001)
        assert connector.force_bound(0.0, bound, 0.0) == pytest.approx(np.max(np.abs(design_force(MEASURED, grid))),
                                                                       rel=1e-12)
    assert connector.linear_damping == pytest.approx(2900.0 / 0.2)  # the steepest segment, -0.2 .. 0 m/s, N s/m
    assert connector.dissipates and not connector.stores_energy


def test_symbolic_and_python_backends_agree():
    a = simulate(SHIPPED, 1.0, user_functions="symbolic")
    b = simulate(SHIPPED, 1.0, user_functions="python")
    np.testing.assert_allclose(a.barrel_position, b.barrel_position, rtol=0, atol=1e-9)


# ================================================================================================ closed form
@pytest.mark.parametrize("accuracy", PRESETS)
def test_a_linear_table_is_the_symmetric_recoil_damper(accuracy):
    linear = simulate(Scene(barrel=Barrel(M), firing=Firing(6.86, 564.0), recoil_spring=RecoilSpring(K),
                            recoil_damper=RecoilDamper(C, C)), 3.0, accuracy)
    tabulated = simulate(scene_with(TabulatedDamper("c", ((-2.0, -2.0 * C), (0.0, 0.0), (2.0, 2.0 * C)))), 3.0,
                         accuracy)
    tolerance = TOLERANCES[accuracy]
    assert tabulated.max_barrel_displacement == pytest.approx(linear.max_barrel_displacement, rel=tolerance["metric"])
    assert tabulated.peak_support_force == pytest.approx(linear.peak_support_force, rel=tolerance["force"])
    e0 = linear.kinetic_energy_history[0]
    assert abs(tabulated.dissipated_energy["c"] - linear.dissipated_energy["recoil_damper"]) <= tolerance["metric"] * e0


# ================================================================================================ engine = reference
CASES = {
    "shipped": SHIPPED,
    "two dampers": scene_with(TabulatedDamper("soft", ((-1.0, -3000.0), (0.0, 0.0), (0.4, 900.0), (1.0, 1500.0))),
                              TabulatedDamper("hard", ((-1.0, -6000.0), (-0.1, -2000.0), (0.0, 0.0), (1.0, 3000.0)))),
}


@pytest.mark.parametrize("accuracy", PRESETS)
@pytest.mark.parametrize("name", list(CASES))
def test_engine_equals_reference(name, accuracy):
    result = simulate(CASES[name], 3.0, accuracy)
    tolerance = TOLERANCES[accuracy]
    assert not physical_violations(result, tolerance["energy"])
    ref = reference_for(CASES[name], 3.0, (), accuracy)
    errors = errors_against_reference(result, ref, tolerance["time"])
    assert not violations(errors, accuracy), errors


def test_energy_balance():
    result = simulate(SHIPPED, 5.0, "reference")
    e0 = result.kinetic_energy_history[0]
    assert float(np.max(np.abs(result.energy_error()))) <= TOLERANCES["reference"]["energy"] * e0
    assert np.all(np.diff(result.dissipated_energy_history["measured_damper"]) >= -1e-9 * e0)


def test_several_dampers_act_as_their_sum():
    soft, hard = CASES["two dampers"].tabulated_dampers
    vs = sorted({v for v, _ in soft.pairs} | {v for v, _ in hard.pairs})
    summed = tuple((v, float(design_force(soft.pairs, v) + design_force(hard.pairs, v))) for v in vs)
    together = simulate(CASES["two dampers"], 3.0, "reference")
    one = simulate(scene_with(TabulatedDamper("sum", summed)), 3.0, "reference")
    tolerance = TOLERANCES["reference"]
    assert together.max_barrel_displacement == pytest.approx(one.max_barrel_displacement, rel=tolerance["metric"])
    e0 = together.kinetic_energy_history[0]
    both = together.dissipated_energy["soft"] + together.dissipated_energy["hard"]
    assert abs(both - one.dissipated_energy["sum"]) <= tolerance["metric"] * e0


# ================================================================================================ Exudyn items
def test_only_assembled_when_the_scene_has_the_table():
    without = Scene(barrel=Barrel(M), firing=Firing(6.86, 564.0), recoil_spring=RecoilSpring(K))
    with assemble(without) as assembly:
        assert set(assembly.connectors) == {"recoil_spring"}
        objects = assembly.mbs.systemData.NumberOfObjects()
    with assemble(SHIPPED, fold=False) as assembly:  # one item per connector: the damper's own
        assert assembly.mbs.systemData.NumberOfObjects() == objects + 1
    with assemble(SHIPPED) as assembly:  # folded into the recoil spring's item (the same ends: engine/folding.py)
        assert set(assembly.connectors) == {"recoil_spring", "measured_damper"}
        assert "measured_damper" in assembly.user_function_connectors
        assert assembly.mbs.systemData.NumberOfObjects() == objects
        assert assembly.connectors["measured_damper"] == assembly.connectors["recoil_spring"]


# ================================================================================================ beyond the table
def test_a_run_that_leaves_the_table_says_so():
    short = scene_with(TabulatedDamper("short", ((-0.1, -0.1 * C), (0.0, 0.0), (0.1, 0.1 * C))))
    with pytest.warns(TableRangeWarning, match=r"tabulated_damper: the run's velocity reached .* beyond the table's "
                                               r"\[-0.1, 0.1\] m/s"):
        simulate(short, 3.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", TableRangeWarning)
        simulate(SHIPPED, 3.0)  # the shipped table covers its run


def test_a_table_in_mm_per_s_gets_a_unit_warning():
    from mbs_models import UnitWarning
    in_mm = scene_with(TabulatedDamper("mm", ((-1000.0, -6239.0), (0.0, 0.0), (1000.0, 6239.0))))
    with pytest.warns(UnitWarning, match=r"tabulated_damper.points reaches a velocity of 1000 m/s .*in mm/s\?"):
        simulate(in_mm, 0.5)


def test_the_early_stop_agrees_with_the_full_run():
    full = simulate(SHIPPED, 5.0)
    early = simulate(SHIPPED, 5.0, stop_when_final=("max_barrel_displacement", "peak_support_force"))
    assert early.stop_reason == "metrics_final" and early.time[-1] < 5.0
    assert early.max_barrel_displacement == pytest.approx(full.max_barrel_displacement, rel=1e-9)
    assert early.peak_support_force == pytest.approx(full.peak_support_force, rel=1e-9)


def test_the_reference_term_follows_design():
    """The reference's damper (validation/reference/terms/tabulated_damper.py) against DESIGN.md written out here:
    its force on every piece and its bound."""
    from validation.reference.terms.tabulated_damper import TabulatedDamper as ReferenceDamper
    damper = ReferenceDamper("d", "ground", "barrel", MEASURED)
    for v in (-2.0, -1.0, -0.7, -0.2, -0.05, 0.0, 0.1, 0.5, 1.2, 1.5, 3.0):
        start, value, slope = damper.table.pieces[damper.table.piece_of(v)]
        assert value + slope * (v - start) == pytest.approx(float(design_force(MEASURED, v)), rel=1e-13, abs=1e-9)
        grid = np.linspace(-abs(v), abs(v), 4001)
        assert damper.force_bound(0.0, abs(v), 0.0) == pytest.approx(np.max(np.abs(design_force(MEASURED, grid))),
                                                                     rel=1e-12)
