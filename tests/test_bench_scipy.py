"""The benchmark's plain scipy script (scripts/plain_scipy.py) and its tolerance choice (scripts/bench_scipy.py): the
script uses no project code, its numbers are the paper's, it solves the right equations (against the independent
event-driven reference), and the tolerance it is timed at is one an engineer can rely on."""

from __future__ import annotations

import ast
import importlib.util
import math
import sys
from pathlib import Path

import pytest

from mbs_models.scene import models
from validation.reference import solve_reference

SCRIPTS = Path(__file__).resolve().parents[1] / "scripts"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


plain_scipy = _load("plain_scipy")


def test_the_plain_script_imports_only_numpy_scipy_and_the_standard_library():
    tree = ast.parse((SCRIPTS / "plain_scipy.py").read_text())
    roots = {alias.name.split(".")[0] for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names}
    roots |= {node.module.split(".")[0] for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module}
    assert roots - {"__future__"} <= {"numpy", "scipy"} | set(sys.stdlib_module_names)


def test_the_plain_script_has_the_papers_numbers():
    """Its own constants against the shipped model's (the project's copy of Section 2.1 and Table 1)."""
    assert plain_scipy.BARREL_MASS == models.PAPER_BARREL_MASS
    assert plain_scipy.RECOIL_STIFFNESS == models.PAPER_RECOIL_STIFFNESS
    assert plain_scipy.RECOIL_DAMPING == models.PAPER_RECOIL_DAMPING
    assert plain_scipy.COUNTER_RECOIL_DAMPING == models.PAPER_COUNTER_RECOIL_DAMPING
    assert plain_scipy.INITIAL_VELOCITY == pytest.approx(
        models.PAPER_PROJECTILE_MASS * models.PAPER_MUZZLE_VELOCITY / models.PAPER_BARREL_MASS, rel=1e-15)
    assert plain_scipy.ABSORBER_STIFFNESS == models.PAPER_ABSORBER_STIFFNESS
    assert plain_scipy.ABSORBER_DAMPING == models.PAPER_ABSORBER_DAMPING
    assert plain_scipy.CONTACT_STIFFNESS == models.PAPER_CONTACT_STIFFNESS
    assert plain_scipy.CONTACT_EXPONENT == models.PAPER_CONTACT_EXPONENT
    assert plain_scipy.CONTACT_DAMPING_FACTOR == models.PAPER_CONTACT_DAMPING_FACTOR


@pytest.mark.parametrize("mass, gap", [(1000.0, 0.0), (100.0, 0.05)])
def test_the_plain_script_agrees_with_the_reference(mass, gap):
    """Both at tight tolerances: the reference's own error is ~1e-10 (rtol 1e-11), the script's at rtol 1e-10 a few
    1e-10 (its metrics are refined to 1e-12 s on a 7th-order interpolant); 1e-7 leaves a wide margin and still
    catches any slip in an equation or a number: a 1 % change of any parameter moves a metric by > 1e-6, or (the
    counter-recoil damping, acting after the maxima) the barrel's position on its way back by far more than the
    1e-7 m allowed there (the positions are a few cm)."""
    reference = solve_reference(models.model_ii(mass, gap), 2.0, rtol=1e-11, atol=1e-13)
    run = plain_scipy.run("DOP853", 1e-10, absorber_mass=mass, gap=gap, end_time=2.0)
    assert run["max_barrel_displacement"] == pytest.approx(reference.max_barrel_displacement, rel=1e-7)
    assert run["peak_contact_force"] == pytest.approx(reference.peak_contact_force, rel=1e-7)
    assert run["max_absorber_velocity"] == pytest.approx(reference.max_absorber_velocity, rel=1e-7)
    for t in (1.0, 1.5, 2.0):
        assert run["dense"](t)[0] == pytest.approx(float(reference.barrel_position(t)), abs=1e-7)


def test_the_grid_search_gives_the_same_maxima_as_the_step_search():
    """Both refine the same dense output's local maximum to 1e-12 s: the values agree to rounding."""
    steps = plain_scipy.run("RK45", 1e-6, end_time=2.0)
    grid = plain_scipy.run("RK45", 1e-6, end_time=2.0, grid_spacing=1e-3)
    for key in ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity"):
        assert grid[key] == pytest.approx(steps[key], rel=1e-12)


def _rows(errors, impacts_ok=None):
    """Scan rows from the loosest rtol (1e-3) down, one metric ``x``."""
    impacts_ok = impacts_ok or [True] * len(errors)
    return [{"rtol": 10.0 ** -(3 + i), "errors": {"x": e}, "impacts_ok": ok}
            for i, (e, ok) in enumerate(zip(errors, impacts_ok))]


def test_the_tolerance_is_the_loosest_from_which_on_every_tighter_one_is_as_accurate():
    bench_scipy = _load("bench_scipy")
    # 1e-4 is as accurate by chance (1e-5 is not); from 1e-6 on every one is.
    reliable, first = bench_scipy.loosest(_rows([1e-2, 1e-9, 1e-3, 1e-8, 1e-9, 1e-10]), "x", 1e-8)
    assert (reliable, first) == (1e-6, 1e-4)
    # an equal error qualifies; an impact missed disqualifies a tolerance however accurate.
    reliable, first = bench_scipy.loosest(_rows([1e-8, 1e-8, 1e-9], [True, False, True]), "x", 1e-8)
    assert (reliable, first) == (1e-5, 1e-3)
    # the tightest fails: none is reliable.
    assert bench_scipy.loosest(_rows([1e-9, 1e-7]), "x", 1e-8) == (None, 1e-3)
    assert bench_scipy.relative_error(math.nan, 1.0) == math.inf


def test_the_summary_is_strict_json_that_the_performance_page_renders():
    """bench.py writes the section's summary into docs/_generated/bench.json (no Infinity: 'no max step' is null),
    and docs/_ext/generated_tables.py renders every row of it with the chosen script's tolerances."""
    import json

    bench_scipy = _load("bench_scipy")
    engine = {"errors": {m: 1e-8 for m in bench_scipy.METRICS}, "steps": 1000, "impacts": 6, "wall": 5e-3,
              "cpu": 5e-3, "solve": 3e-3, "floor_step": 1.5e-6, "floor_run": 3.5e-3}
    chosen = {"method": "LSODA", "rtol": 1e-8, "atol": 1e-10, "error": 5e-9, "steps": 1500, "evaluations": 3500,
              "ratio": 3.0, "cpu_ratio": 3.0, "floor_bound": 4.3, "ceiling": 7.5}
    rows = [{"variant": variant, "preset": "standard", "metric": metric, "target": 1e-8, "max_step": max_step,
             **(chosen if metric != "peak_contact_force" else {})}
            for variant, max_step in bench_scipy.VARIANTS.items() for metric in bench_scipy.METRICS]
    accuracy = {"rows": rows, "presets": {"standard": engine}, "rtols": (1e-3, 1e-11, 33), "repeats": 7}
    text = json.dumps(bench_scipy.summary(accuracy, None, "0.1 0.2 0.3"), allow_nan=False)
    data = json.loads(text)["scipy"]
    assert [row["max_step_s"] for row in data] == [None] * 3 + [0.02] * 3
    assert all(row["ratio"] is None for row in data if row["metric"] == "peak contact force")

    docs = Path(__file__).resolve().parents[1] / "docs" / "_ext"
    sys.path.insert(0, str(docs))
    try:
        spec = importlib.util.spec_from_file_location("docs_generated_tables", docs / "generated_tables.py")
        tables = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(tables)
    finally:
        sys.path.remove(str(docs))
    page = "\n".join(tables._scipy_tables(json.loads(text)))
    assert page.count("| LSODA rtol 1e-08, atol 1e-10 | 5.0e-09 | 3500 | 3.00x | 4.30x | 7.50x | >= 8x |") == 4
    assert page.count("none reached it") == 2
