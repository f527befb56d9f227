"""mbs_models/results/histories.py: the time histories as a table with units, written exactly."""

from __future__ import annotations

import csv
import io

import numpy as np
import pytest

from mbs_models import model_ii, simplified_model, simulate
from mbs_models.results.histories import histories_csv, history_columns


_RUNS = {}


@pytest.fixture
def every_element_run(every_element):
    """A run of the scene of every element (tests/conftest.py), simulated once for the module."""
    if "run" not in _RUNS:
        _RUNS["run"] = simulate(every_element(), 1.0, "draft")
    return _RUNS["run"]


def test_every_body_contact_and_energy_has_a_column(every_element_run):
    result = every_element_run
    columns = history_columns(result)
    for body in result.positions:
        for what, unit in (("position", "m"), ("velocity", "m/s"), ("acceleration", "m/s^2")):
            assert f"{body} {what} [{unit}]" in columns
    for name in result.contacts:
        assert f"{name} force [N]" in columns
    for name in result.work_histories:
        assert f"{name} work [J]" in columns
    assert result.work_histories and "work [J]" in columns
    assert list(columns)[0] == "time [s]" and "support force [N]" in columns


def test_the_energy_columns_balance_as_the_result_says(every_element_run):
    c = history_columns(every_element_run)
    kinetic = sum(v for k, v in c.items() if k.endswith(" kinetic energy [J]") and k != "kinetic energy [J]")
    np.testing.assert_allclose(kinetic, c["kinetic energy [J]"], rtol=1e-12, atol=1e-9)
    balance = (c["kinetic energy [J]"] + c["stored energy [J]"] + c["dissipated energy [J]"] - c["work [J]"]
               - c["kinetic energy [J]"][0] - c["stored energy [J]"][0])
    np.testing.assert_allclose(balance, c["energy balance error [J]"], rtol=0, atol=1e-9)


def test_csv_round_trips_exactly_and_has_no_missing_cells():
    result = simulate(model_ii(), 0.3, "draft")
    for shown, text in ((result.densified(), histories_csv(result)), (result, histories_csv(result, step_ends=True))):
        rows = list(csv.reader(io.StringIO(text)))
        header = rows[0]
        values = np.array(rows[1:], dtype=float)
        assert values.shape == (len(shown.time), len(header))
        for i, (name, column) in enumerate(history_columns(shown).items()):
            assert header[i] == name
            np.testing.assert_array_equal(values[:, i], column)


def _times(text: str) -> np.ndarray:
    rows = list(csv.reader(io.StringIO(text)))
    assert rows[0][0] == "time [s]"
    return np.array([float(row[0]) for row in rows[1:]])


def test_the_rows_are_dense_by_default_and_the_solver_s_points_on_request():
    """A 10 s ``standard`` run steps up to 20 ms: the CSV's rows are at most 1 ms apart (the default for a 10 s
    window; 0.5 ms asked for), with every step-end sample among them; ``step_ends=True`` writes exactly the
    solver's points."""
    result = simulate(model_ii(1000.0, 0.0), 10.0)
    assert np.max(np.diff(result.time)) > 1.9e-2
    for interval, text in ((1e-3, histories_csv(result)), (5e-4, histories_csv(result, 5e-4))):
        times = _times(text)
        assert np.max(np.diff(times)) <= interval + 1e-14
        assert np.all(np.isin(result.time, times))
    np.testing.assert_array_equal(_times(histories_csv(result, step_ends=True)), result.time)
    assert histories_csv(result.densified(), step_ends=True) == histories_csv(result, step_ends=True)


def test_a_scene_without_absorbers_has_no_contact_columns():
    columns = history_columns(simulate(simplified_model(), 0.3, "draft"))
    assert not any(name.endswith("force [N]") and name != "support force [N]" for name in columns)
    assert not any(name.startswith("absorber") for name in columns)
