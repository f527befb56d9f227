"""The Result built once from a run record (mbs_models.engine.result_builder)."""

from __future__ import annotations

import dataclasses

import pytest

from mbs_models import StopReason, model_ii, simulate
from mbs_models.engine import result_builder


def test_metrics_not_proven_final_are_none_in_copies_of_the_post_processings_outputs(monkeypatch):
    """An early stop that proves the displacement final only: the contacts' peaks and impacts are None in the
    Result, in copies of the post-processing's (frozen) outputs: nothing is patched after it is built."""
    analysed = []
    original = result_builder.analyse

    def spy(*args, **kwargs):
        analysed.append(original(*args, **kwargs))
        return analysed[-1]

    monkeypatch.setattr(result_builder, "analyse", spy)
    result = simulate(model_ii(1000.0, 0.0), 10.0, "draft", stop_when_final=("max_barrel_displacement",))
    assert result.stop_reason is StopReason.METRICS_FINAL and result.end_time < result.requested_end_time == 10.0
    [metrics] = analysed
    unproven = {"peak_contact_force", "impacts"} - set(result.final_metrics)
    assert unproven and result.max_barrel_displacement is not None
    for name, output in result.contacts.items():
        before = metrics.contacts[name]
        assert output is not before and output.force is before.force  # a copy, sharing the history
        if "peak_contact_force" in unproven:
            assert output.peak_force is None and output.time_of_peak_force is None
        if "impacts" in unproven:
            assert output.impacts is None


def test_a_record_is_frozen():
    fields = {f.name for f in dataclasses.fields(result_builder.RunRecord)}
    assert {"stop_reason", "final_metrics", "end_time", "requested_end_time", "samples", "steps"} <= fields
    assert result_builder.RunRecord.__dataclass_params__.frozen


def test_a_declared_metric_is_none_after_an_early_stop_unless_it_holds_for_any_window(monkeypatch):
    """The recoil spring given (for this test) a declared history F = k x_M and two metrics of its peak: the full
    run reports both (the peak of k x_M over the samples, computed here from the positions); a run stopped early
    once the maximum displacement is final reports only the one declared ``window=True``."""
    import numpy as np

    from mbs_models.elements.declaration import History, Metric, Outputs
    from mbs_models.elements.recoil_spring import RecoilSpring

    peak = lambda run: float(np.max(run.history("force")))  # noqa: E731
    monkeypatch.setattr(RecoilSpring, "OUTPUTS", Outputs(
        histories=(History("force", "N", lambda run: run.force()),),
        metrics=(Metric("peak", "N", peak), Metric("peak_seen", "N", peak, window=True))))
    scene = model_ii(1000.0, 0.0)
    full = simulate(scene, 10.0, "draft")
    k = scene.recoil_spring.stiffness
    assert full.element_metrics["recoil_spring"]["peak"] == pytest.approx(float(np.max(k * full.barrel_position)), rel=1e-14)
    assert full.metrics()["recoil_spring"]["peak"] == full.element_metrics["recoil_spring"]["peak"]
    early = simulate(scene, 10.0, "draft", stop_when_final=("max_barrel_displacement",))
    assert early.stop_reason == StopReason.METRICS_FINAL
    assert early.element_metrics["recoil_spring"]["peak"] is None
    assert early.element_metrics["recoil_spring"]["peak_seen"] == pytest.approx(float(np.max(k * early.barrel_position)),
                                                                             rel=1e-14)
