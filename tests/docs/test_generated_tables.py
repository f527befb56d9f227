"""The performance page's tables are the benchmark's JSON (docs/_ext/generated_tables.py): every section the
benchmark wrote is rendered, with the numbers it measured."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"


@pytest.fixture(scope="module")
def tables():
    """docs/_ext/generated_tables.py, loaded from its file (it imports its sibling ``_write``)."""
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        spec = importlib.util.spec_from_file_location("docs_generated_tables", DOCS / "_ext" / "generated_tables.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(DOCS / "_ext"))
    return module


def _minimal() -> dict:
    return {"date": "2026-01-01 00:00 UTC", "command": "python scripts/bench.py", "scene": "model (ii)",
            "end_time_s": 10.0, "repeats": 5, "cpus": 2, "machine_load": 1.0, "load_average_1min": 0.5,
            "standard": {"steps": 2604, "errors": {"max_barrel_displacement": 3.6e-9}},
            "ratios": {"LSODA / standard": 2.5}, "breakdown": {"solve": 0.65}}


def test_the_carriage_and_scipy_sections_are_rendered_with_their_numbers(tables):
    data = _minimal()
    data["carriage"] = {"rows": [{"scene": "towed_howitzer", "preset": "standard", "run_ratio": 17.94,
                                  "solve_ratio": 21.3, "step_ratio": 2.4}], "bare_tree_us": 12.2, "bare_mass_us": 0.8}
    data["issue24"] = {"scipy": [{"variant": "no maximum step", "preset": "standard", "metric": "peak contact force",
                                  "target_error": 4.7e-8, "method": "LSODA", "rtol": 3.2e-8, "ratio": 1.57,
                                  "issue_target": 8},
                                 {"variant": "no maximum step", "preset": "draft", "metric": "max barrel displacement",
                                  "target_error": 6.2e-6, "method": None, "rtol": None, "ratio": None,
                                  "issue_target": 4}],
                       "commit": "0657fb5eda33aa", "now_before": {"complete standard run (wall)": 0.877}}
    text = tables.bench_tables(data)
    assert "| `towed_howitzer` | `standard` | 17.9x | 21.3x | 2.40x |" in text
    assert "15.2x a bare 1-D mass" in text
    assert "| LSODA rtol 3.2e-08 | 1.57x | >= 8x |" in text
    assert "none reached it" in text
    assert "| complete standard run (wall) | 0.877 |" in text and "`0657fb5eda33`" in text
    assert "gun on its carriage" not in tables.bench_tables(_minimal())
    assert "Import to the first result" not in text  # (no floor measured: not rendered)


def test_import_to_the_first_result_is_rendered_beside_its_floor(tables):
    data = _minimal()
    data["issue24"] = {"scipy": [], "import_process_s": 0.1324,
                       "import_floor_s": {"interpreter (python -c pass)": 0.0171,
                                          "interpreter, numpy and Exudyn": 0.0986}}
    text = tables.bench_tables(data)
    assert "| `import mbs_models` and a first result | 132 ms |" in text
    assert "| interpreter (python -c pass) | 17 ms |" in text and "| interpreter, numpy and Exudyn | 99 ms |" in text


def test_the_scipy_section_states_the_search_the_products_runs_and_each_metrics_script(tables):
    """The JSON shape of scripts/bench_scipy.py's summary: which script, which methods and tolerances, the product's
    runs beside Exudyn's floor, and per metric the chosen script with its atol, error, evaluations and both ratios."""
    data = _minimal()
    data["issue24"] = {
        "script": {"file": "scripts/plain_scipy.py", "methods": ["RK45", "DOP853", "LSODA", "Radau", "BDF"],
                   "rtol_first": 1e-3, "rtol_last": 1e-11, "rtol_count": 33, "atol_per_rtol": 0.01, "repeats": 7},
        "presets": {"standard": {"steps": 1314, "complete_s": 6.1e-3, "solve_s": 3.3e-3, "floor_step_s": 1.5e-6,
                                 "floor_run_s": 4.77e-3}},
        "scipy": [{"variant": "no max step (solve_ivp's default)", "preset": "standard", "metric": "peak contact force",
                   "target_error": 4.7e-8, "method": "LSODA", "rtol": 3.16e-8, "atol": 3.16e-10, "max_step_s": None,
                   "error": 4.0e-8, "steps": 1655, "evaluations": 3819, "ratio": 2.51, "cpu_ratio": 2.5,
                   "floor_bound": 3.21, "ceiling": 7.9, "issue_target": 8},
                  {"variant": "max step 20 ms (the presets')", "preset": "standard",
                   "metric": "max barrel displacement",
                   "target_error": 1.8e-9, "method": None, "rtol": None, "atol": None, "max_step_s": 0.02,
                   "error": None, "steps": None, "evaluations": None, "ratio": None, "cpu_ratio": None,
                   "floor_bound": None, "ceiling": None, "issue_target": 8}]}
    text = tables.bench_tables(data)
    assert "RK45, DOP853, LSODA, Radau, BDF at rtol 1e-03 down to 1e-11 (33 values), atol = rtol x 0.01" in text
    assert "| `standard` | 1314 | 6.10 ms | 3.30 ms | 2.51 µs | 1.50 µs | 4.77 ms |" in text
    assert ("| no max step (solve_ivp's default) | `standard` | peak contact force | 4.7e-08 | LSODA rtol 3.2e-08, "
            "atol 3.2e-10 | 4.0e-08 | 3819 | 2.51x | 3.21x | 7.90x | >= 8x |") in text
    assert "| max barrel displacement | 1.8e-09 | none reached it | | | - | - | - | >= 8x |" in text

def test_the_committed_benchmark_has_the_sections_its_command_ran(tables):
    data = json.loads((DOCS / "_generated" / "bench.json").read_text())
    command = data["command"]
    assert ("carriage" in data) == ("--skip-carriage" not in command)
    assert ("issue24" in data) == ("--skip-issue24" not in command)
    tables.bench_tables(data)  # renders


def test_what_a_step_adds_to_the_floor_is_rendered_layer_by_layer(tables):
    data = _minimal()
    assert "adds to Exudyn's floor" not in tables.bench_tables(data)  # (not measured: not rendered)
    data["step_layers"] = [
        {"name": "Exudyn's floor", "solve_s": 6.6e-4, "steps": 526, "rejected": 33, "per_step_s": 1.25e-6,
         "per_attempt_s": 1.18e-6, "per_step_over_floor": 1.0, "per_attempt_over_floor": 1.0},
        {"name": "the laws as symbolic user functions", "solve_s": 2.41e-3, "steps": 1314, "rejected": 237,
         "per_step_s": 1.83e-6, "per_attempt_s": 1.55e-6, "per_step_over_floor": 1.464, "per_attempt_over_floor": 1.314}]
    text = tables.bench_tables(data)
    assert "| Exudyn's floor | 526 | 33 | 1.25 µs | 1.00x | 1.18 µs | 1.00x |" in text
    assert "| the laws as symbolic user functions | 1314 | 237 | 1.83 µs | 1.46x | 1.55 µs | 1.31x |" in text
