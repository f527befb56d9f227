"""The declared outputs computed and placed (mbs_models/results/element_outputs.py), on a stand-in element.

The stand-in declares a history ``x2 = 2 x_M`` (a plot panel), a metric ``peak`` reduced from it (a sweep column,
under the element's block), a list metric at a top-level JSON key (no column, its own summary lines, kept after an
early stop): every placement rule is checked against values computed here by hand.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from mbs_models.elements.declaration import History, Metric, Outputs
from mbs_models.results import element_outputs
from mbs_models.results.samples import Samples

X = np.array([0.0, 0.3, 0.1])  # m

OUTPUTS = Outputs(
    histories=(History("x2", "m", lambda run: 2.0 * run.samples.positions["barrel"], panel="twice x [mm]", scale=1e3),
               History("unplotted", "m", lambda run: run.history("x2") + 1.0)),
    metrics=(Metric("peak", "m", lambda run: np.max(run.history("x2"))),
             Metric("events", "-", lambda run: [{"k": 1}], json_key="events", column=False,
                    summary=lambda value: [f"  {len(value)} event"], window=True)))


class _Scene:
    def __init__(self, outputs=OUTPUTS):
        self.table = SimpleNamespace(OUTPUTS=outputs)

    def elements(self):
        return [("barrel", SimpleNamespace()), ("gadget", self.table)]


def _computed(scene=None):
    scene = scene or _Scene()
    samples = Samples(np.array([0.0, 0.5, 1.0]), {"barrel": X}, {"barrel": 0 * X}, {"barrel": 0 * X})
    return element_outputs.compute(SimpleNamespace(scene=scene), samples, None)


def _result():
    histories, metrics = _computed()
    return SimpleNamespace(scene=_Scene(), element_histories=histories, element_metrics=metrics)


def test_histories_then_metrics_from_them():
    histories, metrics = _computed()
    assert histories["gadget"]["x2"] == pytest.approx([0.0, 0.6, 0.2], rel=1e-15)
    assert histories["gadget"]["unplotted"] == pytest.approx([1.0, 1.6, 1.2], rel=1e-15)
    assert metrics == {"gadget": {"peak": pytest.approx(0.6, rel=1e-15), "events": [{"k": 1}]}}
    assert type(metrics["gadget"]["peak"]) is float  # a numpy scalar made a plain number (JSON-ready)
    assert "barrel" not in histories and "barrel" not in metrics  # it declares nothing


def test_a_history_of_the_wrong_length_is_refused():
    bad = Outputs(histories=(History("short", "m", lambda run: np.zeros(2)),))
    with pytest.raises(ValueError, match=r"gadget.short: the history has shape \(2,\), the run's time \(3,\)"):
        _computed(_Scene(bad))


def test_json_places_a_metric_under_its_element_or_at_its_key():
    result = _result()
    entries = element_outputs.json_entries(result)
    assert entries == {"gadget": {"peak": pytest.approx(0.6, rel=1e-15)}, "events": [{"k": 1}]}
    entries["events"][0]["k"] = 99  # a copy: the result's value stays
    assert result.element_metrics["gadget"]["events"] == [{"k": 1}]


def test_sweep_columns_are_the_metrics_that_ask_for_one():
    result = _result()
    assert element_outputs.sweep_columns(result.scene) == ["gadget.peak"]
    assert element_outputs.sweep_row(result) == {"gadget.peak": pytest.approx(0.6, rel=1e-15)}


def test_summary_lines_default_and_declared():
    assert element_outputs.summary_lines(_result()) == [f"  {'gadget peak':24s} 0.6 m", "  1 event"]


def test_plot_panels_scale_the_histories_that_have_one():
    (label, lines), = element_outputs.plot_panels(_result())
    assert label == "twice x [mm]" and lines[0][0] == "gadget x2"
    assert lines[0][1] == pytest.approx([0.0, 600.0, 200.0], rel=1e-15)


def test_after_an_early_stop_only_window_metrics_remain():
    result = _result()
    assert element_outputs.unproven(result.element_metrics, result.scene) == {"gadget": {"peak": None,
                                                                                        "events": [{"k": 1}]}}


def test_lookup_by_name():
    """One element declares it: its value; a registered element could (the burst's ``shots``): None; none: an
    AttributeError; two of the run: an AttributeError naming the way to ask."""
    result = _result()
    assert element_outputs.lookup(result, "peak") == pytest.approx(0.6, rel=1e-15)
    assert element_outputs.lookup(result, "shots") is None
    with pytest.raises(AttributeError, match="no attribute 'nothing_declares_this'"):
        element_outputs.lookup(result, "nothing_declares_this")
    twice = SimpleNamespace(element_metrics={"a": {"peak": 1.0}, "b": {"peak": 2.0}})
    with pytest.raises(AttributeError, match="2 elements of the run declare a metric 'peak'"):
        element_outputs.lookup(twice, "peak")


def test_a_declared_column_is_known_by_its_registered_element(monkeypatch):
    """A column metric of a registered table is a metric column in its unit; the table's own fields stay parameters;
    a declared metric without a column (the burst's ``shots``, also a field of ``[burst]``) is no metric column."""
    from mbs_models.elements.recoil_spring import RecoilSpring
    from mbs_models.results.sweep_plots import is_metric_column, metric_label
    from mbs_models.results.units import metric_si_unit

    monkeypatch.setattr(RecoilSpring, "OUTPUTS", OUTPUTS)
    assert element_outputs.declared_column_unit("recoil_spring.peak") == "m"
    assert is_metric_column("recoil_spring.peak") and metric_si_unit("recoil_spring.peak") == "m"
    assert metric_label("recoil_spring.peak") == ("recoil spring.peak [m]", 1.0)
    assert element_outputs.declared_column_unit("recoil_spring.events") is None  # column=False
    assert not is_metric_column("recoil_spring.stiffness")
    assert element_outputs.declared_column_unit("burst.shots") is None and not is_metric_column("burst.shots")
