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


def test_the_committed_benchmark_has_the_sections_its_command_ran(tables):
    data = json.loads((DOCS / "_generated" / "bench.json").read_text())
    command = data["command"]
    assert ("carriage" in data) == ("--skip-carriage" not in command)
    assert ("issue24" in data) == ("--skip-issue24" not in command)
    tables.bench_tables(data)  # renders
