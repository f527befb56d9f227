"""`recoil paper --reproduce-only`: the paper's results and figures, the studies honestly marked as not run."""

from __future__ import annotations

import json

import pytest

from mbs_models.cli import main
from validation.studies.report import ReportOptions, write_report


@pytest.fixture(scope="module")
def reproduction_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduction")
    write_report(out, ReportOptions.reproduction(gap_step=0.04, masses=(1000.0,)))
    return out


def test_reproduction_has_the_papers_results_and_says_what_it_left_out(reproduction_dir):
    text = (reproduction_dir / "report.html").read_text()
    data = json.loads((reproduction_dir / "results.json").read_text())
    assert {(r["model"], r["absorber_mass"]) for r in data["table2"]} >= {
        ("simplified", 1000.0), ("model (i)", 1000.0), ("model (ii)", 1000.0)}
    assert all(abs(r["engine_vs_reference"]) < 1e-4 for r in data["table2"])
    assert [c["gap"] for c in data["engine_vs_reference"] if c["gap"]] == []  # gap 0 only
    sweeps = {(s["model"], s["absorber_mass"]): s for s in data["gap_sweeps"]}
    assert sweeps[("model (ii)", 1000.0)]["gap"] == pytest.approx([0.0, 0.04, 0.08, 0.12])
    assert all(x is not None for s in sweeps.values() for x in s["max_barrel_displacement"])
    assert data["conventions"] == [] and data["calibration"] is None and data["calibration_table2"] == []
    assert "convention study" not in data["timings"] and "calibration" not in data["timings"]
    assert text.count("Not computed in this run") == 2
    assert not (reproduction_dir / "conventions_gap_trend.png").exists()
    for stem in ("fig4_gap_sweep_model_i", "fig5_gap_sweep_model_ii", "barrel_displacement_m1000",
                 "contact_force_m1000", "absorber_velocity_m1000", "first_impact_m1000", "support_force_m1000"):
        assert (reproduction_dir / f"{stem}.png").read_bytes()[:4] == b"\x89PNG"
    reasons = [item["reason"] for item in data["unreproduced"] if item["paper"] is not None]
    assert reasons and all("--reproduce-only" in reason for reason in reasons)


def test_reproduce_only_and_quick_are_exclusive(tmp_path, capsys):
    assert main(["paper", "--out", str(tmp_path / "x"), "--quick", "--reproduce-only"]) == 2
    assert "--reproduce-only" in capsys.readouterr().err
