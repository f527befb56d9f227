"""The work-precision study on a tiny grid: errors fall as tolerances tighten, failures are classified,
the outputs are written, and scipy integrates the same equations as the reference."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from mbs_models import model_i, model_ii, simplified_model
from mbs_models.cli import main
from validation.studies.precision import (Parameters, FAILED_STATUSES, METRICS, TARGETS, RunValues, Setting, Study, _exudyn, _scipy,
                                  classify_failure, compute_truth, impact_mismatch, plain_rhs, run_study)

END_TIME = 1.0  # the first impacts of model (ii), m = 1000 kg, gap 0, happen in the first second
TOLERANCES = [1e-4, 1e-7, 1e-10]
ADAPTIVE_FAMILIES = ["Exudyn DOPRI5 (symbolic)", "Exudyn ODE23 (symbolic)", "scipy LSODA", "scipy RK45"]


@pytest.fixture(scope="module")
def study() -> Study:
    grid = (_exudyn("DOPRI5", TOLERANCES) + _exudyn("ODE23", TOLERANCES) + _scipy("LSODA", TOLERANCES)
            + _scipy("RK45", TOLERANCES[:2]) + _exudyn("RK44", [2e-2, 1e-3]) + _exudyn("GeneralizedAlpha", [1e-3])
            + _exudyn("DOPRI5", [1e-6], "python"))
    return run_study(model_ii(1000.0, 0.0), grid, end_time=END_TIME, repeats=1)


def test_truth_is_tight_and_has_the_impacts(study):
    truth = study.truth
    assert truth.impacts, "the tiny study must contain impacts"
    for metric in METRICS:
        assert truth.uncertainty[metric] < 1e-8, (metric, truth.uncertainty)


@pytest.mark.parametrize("family", ADAPTIVE_FAMILIES)
def test_errors_fall_as_tolerance_tightens(study, family):
    outcomes = sorted((o for o in study.outcomes if o.setting.family == family),
                      key=lambda o: -o.setting.relative_tolerance)
    assert len(outcomes) >= 2 and all(o.ok for o in outcomes), [(o.setting.label(), o.reason) for o in outcomes]
    worst = [max(o.errors[m] for m in METRICS) for o in outcomes]
    assert all(later < earlier for earlier, later in zip(worst, worst[1:])), (family, worst)
    for metric in METRICS:
        assert outcomes[-1].errors[metric] < outcomes[0].errors[metric], (family, metric)
    # and by a margin worth the name: 1000x tighter tolerance, >= 30x smaller worst error
    assert worst[-1] * 30 < worst[0], (family, worst)


def test_timings_are_recorded(study):
    for o in study.outcomes:
        if o.ok:
            assert o.median_time > 0 and o.solve_time > 0 and o.runs == 1
            assert o.solve_time <= o.median_time * 1.5


def test_refused_setting_says_why_and_what_would_happen(study):
    refused = next(o for o in study.outcomes if o.setting.label() == "Exudyn RK44 (symbolic) step=0.02 s")
    assert refused.status == "refused" and refused.median_time is None
    assert "safe limit" in refused.reason and "unguarded:" in refused.reason
    assert refused in study.failures()


def test_cheapest_settings_are_successful_and_fit_the_target(study):
    for target in TARGETS:
        best = study.cheapest(target)
        if best is None:
            continue
        assert best.ok and all(best.errors[m] <= target for m in study.metrics())
        fitting = [o for o in study.outcomes if o.ok and all(o.errors[m] <= target for m in study.metrics())]
        assert best.median_time == min(o.median_time for o in fitting)
    assert study.cheapest(1e-2) is not None and study.cheapest(1e-6) is not None


def test_outputs_are_written(study, tmp_path):
    written = study.write(tmp_path)
    rows = list(csv.DictReader(open(written["csv"])))
    assert len(rows) == len(study.outcomes)
    assert {row["status"] for row in rows} <= {"ok", *FAILED_STATUSES}
    data = json.loads(written["json"].read_text())
    assert set(data["cheapest"]) == {f"{t:g}" for t in TARGETS}
    assert data["truth"]["impacts"] and len(data["settings"]) == len(study.outcomes)
    text = written["markdown"].read_text()
    assert "Cheapest setting per error target" in text and "Failing settings" in text and "RK44" in text
    for metric in METRICS:
        assert written[metric].stat().st_size > 10_000


def test_simplified_scene_has_no_contact_metrics():
    truth = compute_truth(simplified_model(), 1.0, check_rtol=None)
    study = run_study(simplified_model(), _exudyn("DOPRI5", [1e-6]) + _scipy("DOP853", [1e-8]), end_time=1.0,
                      repeats=1, truth=truth)
    assert study.metrics() == ["max_barrel_displacement", "barrel_trajectory_l2"]
    for o in study.outcomes:
        assert o.ok and o.errors["peak_contact_force"] is None and o.errors["max_barrel_displacement"] < 1e-4


@pytest.mark.parametrize("scene", [model_i(500.0, 0.0), model_ii(100.0, 0.01)], ids=["model-i", "model-ii"])
def test_plain_rhs_is_the_reference_equations(scene):
    """scipy's plain right-hand side equals the reference's in the mode the state is in (classified by the
    reference itself at a restart from that state)."""
    from validation.reference.assembly import build_model
    from validation.reference.switching import Restart

    f = plain_rhs(Parameters.from_scene(scene))
    model = build_model(scene)
    rng = np.random.default_rng(1)
    for _ in range(200):
        y = np.concatenate([rng.normal(0, 0.01, 4) * [1, 50, 1, 50], np.zeros(model.n_states - 4)])
        mode = Restart(model, 0.0, y, {}, None).mode
        np.testing.assert_allclose(f(0.0, y[:4]), model.rhs(mode)(0.0, y)[:4], rtol=1e-12, atol=1e-9)


def test_failure_classification():
    assert classify_failure("Exudyn RK44 produced a non-finite barrel position at t = 1 s") == "blow-up"
    assert classify_failure("Exudyn RK44 stepped over 2 contact(s) between two steps") == "missed contact"
    assert classify_failure("Exudyn DOPRI5 stopped early at t = 3 s of 10 s") == "stopped"
    assert classify_failure("Exudyn DOPRI5 stopped at t = 1 s: the step budget of 5 steps was spent") == "stopped"
    assert classify_failure("x: the energy balance is off by 0.3 of the initial energy") == "energy"
    assert classify_failure("Exudyn GeneralizedAlpha failed: Newton did not converge") == "failed"


def test_impact_mismatch_counts_are_robust_near_the_threshold():
    truth = compute_truth(model_ii(1000.0, 0.0), 0.05, check_rtol=None)
    assert len(truth.episodes) == 1

    def values(peaks, lenient):
        return RunValues(0.0, 0.0, 0.0, [(0.0, 0.01, p) for p in peaks], np.zeros(1), lenient_impacts=lenient)

    assert impact_mismatch(values([1.2e5], 1), truth) == (0, 0)
    assert impact_mismatch(values([], 0), truth) == (1, 0)            # the impact was stepped over
    assert impact_mismatch(values([1.2e5, 5e3], 2), truth) == (0, 1)  # an impact the truth does not have
    assert impact_mismatch(values([1.2e5, 1.5e3], 2), truth) == (0, 0)  # near the threshold: not judged


def test_setting_labels_and_settings():
    adaptive = Setting("exudyn", "DOPRI5", relative_tolerance=1e-6, user_functions="python")
    assert adaptive.label() == "Exudyn DOPRI5 (python) rtol=1e-06"
    assert adaptive.solver_settings().absolute_tolerance == pytest.approx(1e-8)
    fixed = _exudyn("GeneralizedAlpha", [1e-3])[0]
    assert fixed.label() == "Exudyn GeneralizedAlpha (symbolic) step=0.001 s" and fixed.solver_settings().step == 1e-3
    assert _scipy("Radau", [1e-5])[0].label() == "scipy Radau rtol=1e-05"


def test_precision_cli_quick(tmp_path, capsys):
    out = tmp_path / "p"
    assert main(["precision", "model_ii", "--quick", "--end-time", "0.3", "--repeats", "1", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "Cheapest setting per error target" in printed
    assert (out / "precision.md").is_file() and (out / "work_precision_peak_contact_force.png").is_file()
    assert main(["precision", "model_ii", "--repeats", "0", "--out", str(out)]) == 2
    assert main(["precision", "nosuch.toml", "--out", str(out)]) == 2
