"""The outputs elements declare (:mod:`mbs_models.elements.declaration`), computed and placed: generic code.

Each element of a scene may declare histories and metrics in its table's ``OUTPUTS``.  :func:`compute` evaluates
them on a run's samples (histories first, in order, then the metrics, which may read the histories);
:func:`json_entries`, :func:`summary_lines`, :func:`plot_panels`, :func:`sweep_columns` and :func:`sweep_row` put
them where the declarations say -- the JSON of ``recoil run``, its summary and plot, the sweep's columns.  No
element is named here.
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np

from ..elements.declaration import NO_OUTPUTS, ElementRun, Metric, Outputs


def declared(scene) -> list[tuple[str, Any, Outputs]]:
    """``(element name, table, outputs)`` of every element of ``scene`` that declares outputs, in element order."""
    return [(name, table, outputs) for name, table in scene.elements()
            if (outputs := getattr(table, "OUTPUTS", NO_OUTPUTS))]


def compute(mechanism, samples, interpolant) -> tuple[dict[str, dict[str, np.ndarray]], dict[str, dict[str, Any]]]:
    """``(histories, metrics)``, each ``{element: {name: value}}``, of every declared output of the mechanism's
    scene on the samples (a history as a float array, one value per sample)."""
    histories: dict[str, dict[str, np.ndarray]] = {}
    metrics: dict[str, dict[str, Any]] = {}
    for name, run, outputs in _runs(mechanism, samples, interpolant):
        if run.histories:
            histories[name] = run.histories
        if outputs.metrics:
            metrics[name] = {metric.name: _plain(metric.compute(run)) for metric in outputs.metrics}
    return histories, metrics


def compute_histories(mechanism, samples, interpolant) -> dict[str, dict[str, np.ndarray]]:
    """The declared histories alone, ``{element: {name: array}}``, on ``samples`` (any times: the densified
    output's, :mod:`mbs_models.results.dense`); ``interpolant`` gives the state between them."""
    return {name: run.histories for name, run, _ in _runs(mechanism, samples, interpolant) if run.histories}


def _runs(mechanism, samples, interpolant):
    """``(element name, ElementRun with its histories computed, outputs)`` of every declaring element, in order."""
    for name, table, outputs in declared(mechanism.scene):
        own: dict[str, np.ndarray] = {}
        run = ElementRun(table, name, mechanism.scene, mechanism, samples, interpolant, own)
        for history in outputs.histories:
            values = np.asarray(history.compute(run), dtype=float)
            if values.shape != samples.time.shape:
                raise ValueError(f"{name}.{history.name}: the history has shape {values.shape}, the run's time "
                                 f"{samples.time.shape}")
            own[history.name] = values
        yield name, run, outputs


def _plain(value):
    """A numpy scalar as a Python number (JSON-ready); anything else as it is."""
    return value.item() if isinstance(value, np.generic) else value


def metric_specs(scene) -> list[tuple[str, Metric]]:
    """``(element name, metric)`` of every declared metric of ``scene``."""
    return [(name, metric) for name, _table, outputs in declared(scene) for metric in outputs.metrics]


def unproven(metrics: dict[str, dict[str, Any]], scene) -> dict[str, dict[str, Any]]:
    """``metrics`` after an early stop: every metric None but those that describe any window (``window=True``)."""
    keep = {(name, metric.name) for name, metric in metric_specs(scene) if metric.window}
    return {element: {name: value if (element, name) in keep else None for name, value in values.items()}
            for element, values in metrics.items()}


def json_entries(result) -> dict[str, Any]:
    """The declared metrics as keys of ``recoil run --json``: ``{element: {name: value}}``, or the metric's
    ``json_key`` at the top level."""
    out: dict[str, Any] = {}
    for element, metric in metric_specs(result.scene):
        value = copy.deepcopy(result.element_metrics.get(element, {}).get(metric.name))  # the Result's stays as is
        if metric.json_key is not None:
            out[metric.json_key] = value
        else:
            out.setdefault(element, {})[metric.name] = value
    return out


def summary_lines(result) -> list[str]:
    """The lines of the declared metrics in ``Result.summary``: each metric's ``summary(value)``, or
    ``<element> <name>  value unit``; nothing for a metric that is None."""
    lines = []
    for element, metric in metric_specs(result.scene):
        value = result.element_metrics.get(element, {}).get(metric.name)
        if value is None:
            continue
        if metric.summary is not None:
            lines += metric.summary(value)
        else:
            label = f"{element} {metric.name}".replace("_", " ")
            lines.append(f"  {label:24s} {value:.6g} {metric.unit}")
    return lines


def plot_panels(result) -> list[tuple[str, list[tuple[str, np.ndarray]]]]:
    """``(y-label, [(line label, values)])`` of every declared history with a panel: histories of one label share
    its panel; values are the history times its ``scale``."""
    panels: dict[str, list[tuple[str, np.ndarray]]] = {}
    for element, _table, outputs in declared(result.scene):
        for history in outputs.histories:
            if history.panel is not None:
                values = result.element_histories[element][history.name] * history.scale
                panels.setdefault(history.panel, []).append((f"{element} {history.name}".replace("_", " "), values))
    return list(panels.items())


def sweep_columns(scene) -> list[str]:
    """The sweep columns of the declared metrics of ``scene``: ``<element>.<name>`` of each with ``column``."""
    return [f"{element}.{metric.name}" for element, metric in metric_specs(scene) if metric.column]


def sweep_row(result) -> dict[str, Any]:
    """The values of :func:`sweep_columns` for one result."""
    return {f"{element}.{metric.name}": result.element_metrics.get(element, {}).get(metric.name)
            for element, metric in metric_specs(result.scene) if metric.column}


def declared_column_unit(column: str) -> str | None:
    """The SI unit of a sweep column ``<element>.<name>`` that is a metric some registered element declares (a
    column metric ``name`` of a table that has no field ``name``: ``progressive_spring.peak_force``, never the
    parameter ``progressive_spring.cubic_stiffness``); None for any other column."""
    from ..elements import TABLES

    if "." not in column:
        return None
    name = column.rsplit(".", 1)[-1]
    for table in TABLES.values():
        for metric in getattr(table, "OUTPUTS", NO_OUTPUTS).metrics:
            if metric.column and metric.name == name and name not in table.field_names():
                return metric.unit
    return None


def lookup(result, name: str):
    """The declared metric ``name`` of the run's one element that declares it; None when no element of the run
    declares it but a registered element could (``result.shots`` of a scene without a burst); AttributeError when
    no element declares it, or more than one of the run does."""
    found = [values[name] for values in result.element_metrics.values() if name in values]
    if len(found) == 1:
        return found[0]
    if len(found) > 1:
        raise AttributeError(f"{len(found)} elements of the run declare a metric {name!r}: use "
                             f"Result.element_metrics[element][{name!r}]")
    from ..elements import TABLES

    if any(metric.name == name for table in TABLES.values() for metric in getattr(table, "OUTPUTS", NO_OUTPUTS).metrics):
        return None
    raise AttributeError(f"'Result' object has no attribute {name!r}")
