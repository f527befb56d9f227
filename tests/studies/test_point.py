"""One sweep point as a row (mbs_models.studies.point): the numbers of a single simulate run, failures kept."""

from __future__ import annotations

import pytest

from mbs_models import Conventions, load_scene, model_i, model_ii, simulate
from mbs_models.scenes import scene_path
from mbs_models.studies.point import PointSettings, evaluate_batch, evaluate_point, metric_columns

SETTINGS = PointSettings(end_time=1.0)


def test_row_equals_a_single_simulate_run():
    row = evaluate_point(model_ii(500.0, 0.0), {"absorber.mass": 1000.0, "contact.gap": 0.04}, SETTINGS)
    result = simulate(model_ii(1000.0, 0.04), 1.0)
    assert row["absorber.mass"] == 1000.0 and row["contact.gap"] == 0.04
    for name in ("max_barrel_displacement", "time_of_max_barrel_displacement", "peak_support_force",
                 "time_of_peak_support_force", "peak_contact_force", "time_of_peak_contact_force",
                 "max_absorber_velocity", "time_of_max_absorber_velocity"):
        assert row[name] == getattr(result, name), name
    assert row["impacts"] == len(result.impacts)
    assert row["end_time"] == result.end_time and row["steps"] == result.steps
    assert type(row["stop_reason"]) is str and row["stop_reason"] == "end_time"  # plain text, as tables always held
    assert row["initial_velocity"] == result.scene.initial_velocity
    assert row["status"] == "ok" and row["error"] is None and row["wall_time"] > 0
    assert list(row) == ["absorber.mass", "contact.gap", *metric_columns(model_ii()), "wall_time", "status", "error"]


def test_per_absorber_columns():
    scene = load_scene(scene_path("two_absorbers"))
    row = evaluate_point(scene, {"absorber.1.contact.gap": 0.01}, SETTINGS)
    result = simulate(scene.with_changes(**{"absorber.1.contact.gap": 0.01}), 1.0)
    for i, entry in enumerate(result.absorbers()):
        assert row[f"absorber.{i}.peak_contact_force"] == entry["peak_contact_force"]
        assert row[f"absorber.{i}.max_absorber_velocity"] == entry["max_absorber_velocity"]
        assert row[f"absorber.{i}.impacts"] == len(entry["impacts"])


def test_per_stop_columns(every_element):
    scene = every_element()
    row = evaluate_point(scene, {}, PointSettings(end_time=0.5))
    result = simulate(scene, 0.5)
    assert result.stops() and row["status"] == "ok"
    for entry in result.stops():
        assert row[f"{entry['element']}.peak_contact_force"] == entry["peak_contact_force"]
        assert row[f"{entry['element']}.impacts"] == len(entry["impacts"])
        assert row[f"{entry['element']}.dissipated_energy"] == entry["dissipated_energy"]



def test_a_scene_with_one_absorber_has_no_per_absorber_columns():
    assert "absorber.0.impacts" not in metric_columns(model_i())


def test_a_failed_solve_is_a_row_with_its_error():
    row = evaluate_point(model_ii(1000.0, 0.0), {"conventions.compression_only": True}, PointSettings(end_time=0.5))
    assert row["status"] == "SimulationError" and "step budget" in row["error"]
    assert row["max_barrel_displacement"] is None and row["conventions.compression_only"] is True


def test_an_invalid_combination_is_a_row_with_its_error():
    row = evaluate_point(model_i(), {"contact.law": "hunt-crossley", "contact.restitution": 0.5}, SETTINGS)
    assert row["status"] == "SceneError"
    assert row["error"].startswith("contact.restitution: not a field of law 'hunt-crossley'")


def test_a_batch_keeps_the_indices():
    out = evaluate_batch((model_i(), SETTINGS, [(7, {"contact.gap": 0.0}), (3, {"contact.gap": -1.0})]))
    assert [index for index, _ in out] == [7, 3]
    assert [row["status"] for _, row in out] == ["ok", "SceneError"]


class _BrokenMessage(Exception):
    def __str__(self):
        raise RuntimeError("no message either")


@pytest.mark.parametrize("exc, status, error", [
    (OverflowError(34, "Numerical result out of range"), "OverflowError", "(34, 'Numerical result out of range')"),
    (ZeroDivisionError("float division by zero"), "ZeroDivisionError", "float division by zero"),
    (RuntimeError('line one\n  "line" two\n'), "RuntimeError", "line one; 'line' two"),  # one line, no double quote
    (MemoryError(), "MemoryError", "MemoryError"),                                       # no message: the class
    (RecursionError("maximum recursion depth exceeded"), "RecursionError", "maximum recursion depth exceeded"),
    (_BrokenMessage(), "_BrokenMessage", "_BrokenMessage"),
    (type("no name", (ValueError,), {})("a\x00b\tc \udcff"), "Exception", "a b c ?"),  # what a table cannot hold
], ids=lambda v: type(v).__name__ if isinstance(v, BaseException) else None)
def test_any_exception_of_a_point_is_its_row(monkeypatch, exc, status, error):
    """Whatever a point raises -- while its scene is built or solved -- is its row: the sweep goes on."""
    import mbs_models.studies.point as point

    def broken(scene, settings):
        raise exc

    monkeypatch.setattr(point, "simulate_scene", broken)
    row = evaluate_point(model_i(), {"contact.gap": 0.0}, SETTINGS)
    assert (row["status"], row["error"]) == (status, error)
    assert row["contact.gap"] == 0.0 and row["wall_time"] >= 0
    assert all(row[column] is None for column in metric_columns(model_i()))


def test_interrupts_are_not_rows(monkeypatch):
    import mbs_models.studies.point as point

    for exc in (KeyboardInterrupt, SystemExit):
        def interrupted(scene, settings, exc=exc):
            raise exc

        monkeypatch.setattr(point, "simulate_scene", interrupted)
        with pytest.raises(exc):
            evaluate_point(model_i(), {"contact.gap": 0.0}, SETTINGS)


@pytest.mark.parametrize("column, value, needle", [
    ("max_barrel_displacement", float("nan"), "max_barrel_displacement: the result's value is nan"),
    ("peak_support_force", float("inf"), "peak_support_force: the result's value is inf"),
    ("impacts", 2.5, "impacts: the result's count is 2.5"),
    ("steps", -1, "steps: the result's count is -1"),
    ("time_of_peak_contact_force", "soon", "could not convert string to float"),
])
def test_a_result_that_is_no_number_is_a_failed_point(monkeypatch, column, value, needle):
    """A row is made only of finite numbers (and counts, and text where text belongs): a NaN or an infinity from
    a solve is a failed point, never a value of the table."""
    import mbs_models.studies.point as point

    real = point.result_row
    monkeypatch.setattr(point, "result_row", lambda result, scene: {**real(result, scene), column: value})
    row = evaluate_point(model_i(), {"contact.gap": 0.0}, SETTINGS)
    assert row["status"] in ("SimulationError", "ValueError") and needle in row["error"]
    assert row["max_barrel_displacement"] is None


def test_a_long_message_is_cut():
    from mbs_models.studies.point import MAX_ERROR_LENGTH, error_text

    text = error_text(ValueError("x" * 5000))
    assert len(text) == MAX_ERROR_LENGTH and text.endswith("...")


def test_a_batch_split_and_lost():
    """The parts a backend retries when a worker dies, and the rows of a point that killed its worker each time."""
    from mbs_models.studies.point import WORKER_DIED, lost_batch, split_batch

    task = (model_i(), SETTINGS, [(7, {"contact.gap": 0.0}), (3, {"contact.gap": 0.01})])
    assert split_batch(task) == [(task[0], SETTINGS, [(7, {"contact.gap": 0.0})]),
                                 (task[0], SETTINGS, [(3, {"contact.gap": 0.01})])]
    (index, row), = lost_batch(split_batch(task)[1], "its worker process died of SIGSEGV")
    assert index == 3 and row["status"] == WORKER_DIED == "WorkerDied"
    assert row["error"] == "its worker process died of SIGSEGV" and row["contact.gap"] == 0.01
    assert all(row[column] is None for column in metric_columns(model_i()))


def test_conventions_reach_the_row():
    row = evaluate_point(model_i(), {"conventions.v0_includes_absorber": True}, SETTINGS)
    assert row["initial_velocity"] == model_i(conventions=Conventions(v0_includes_absorber=True)).initial_velocity
