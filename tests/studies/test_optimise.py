"""Design optimisation: the optimiser finds what a fine sweep finds; constraints, failed points, seeds, input.

The known optima come from a brute-force sweep (every 1 mm of gap, simulated here with ``simulate``),
not from the optimiser.  Model (i) with m = 1000 kg has an interior optimum of the recoil length at a
gap of 64 mm, and a peak force on the mount that rises past 59 mm: a constraint on that force moves the
optimum to the edge of the feasible gaps.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mbs_models import model_i, simulate
from mbs_models.errors import ClusterError, SceneError, SimulationError
from mbs_models.studies import point
from mbs_models.studies.optimise import (Constraint, early_stop_metrics, optimise, parse_bound, parse_constraint)

GAPS = np.linspace(0.0, 0.12, 121)  # the sweep's resolution: 1 mm
STEP = GAPS[1] - GAPS[0]
BOUNDS = {"contact.gap": (0.0, 0.12)}
FORCE_LIMIT = 6020.0  # N: excludes the unconstrained optimum (6026 N at 64 mm)


@pytest.fixture(scope="module")
def sweep():
    """Recoil length (m) and peak force on the mount (N) of model (i), m = 1000 kg, every 1 mm of gap."""
    results = [simulate(model_i(1000.0, g), 10.0, "standard",
                        stop_when_final=("max_barrel_displacement", "peak_support_force")) for g in GAPS]
    return (np.array([r.max_barrel_displacement for r in results]),
            np.array([r.peak_support_force for r in results]))


def test_finds_the_sweeps_optimum(sweep):
    length, _ = sweep
    best = int(np.argmin(length))
    assert 0 < best < len(GAPS) - 1  # an interior optimum: not found by pushing to a bound
    result = optimise(model_i(1000.0, 0.0), BOUNDS, "max_barrel_displacement", seed=1, workers=2)
    assert result.feasible and result.success
    assert abs(result.parameters["contact.gap"] - GAPS[best]) <= STEP
    # to the sweep's resolution: better than the swept neighbours of the sweep's best point
    assert result.objective < min(length[best - 1], length[best + 1])
    assert result.objective >= length[best] - 1e-4  # and not implausibly better (0.1 mm)
    history = result.history
    assert len(history) == result.evaluations and history["evaluation"].tolist() == list(range(len(history)))
    assert history["generation"].iloc[0] == 0 and history["generation"].max() == result.generations
    assert history["max_barrel_displacement"].min() == result.objective  # the optimum is an evaluated point
    assert result.settings["backend"] == "processes" and result.settings["stop_when_final"] == "max_barrel_displacement"
    assert len(result.convergence) == result.generations
    assert np.all(np.diff(result.convergence["best_objective"]) <= 0)  # the best never gets worse


def test_constraint_moves_the_optimum_to_the_sweeps_constrained_one(sweep):
    length, force = sweep
    feasible = force <= FORCE_LIMIT
    assert not feasible[np.argmin(length)]  # the constraint is active
    best = int(np.flatnonzero(feasible)[np.argmin(length[feasible])])
    result = optimise(model_i(1000.0, 0.0), BOUNDS, "max_barrel_displacement",
                      [f"peak_support_force<={FORCE_LIMIT}"], seed=1, workers=2)
    assert result.feasible
    (value,) = result.constraint_values
    assert value["satisfied"] and value["value"] <= FORCE_LIMIT and value["limit"] == FORCE_LIMIT
    assert abs(result.parameters["contact.gap"] - GAPS[best]) <= STEP
    # to the sweep's resolution: better than every other feasible swept point
    assert result.objective < np.delete(length[feasible], np.flatnonzero(np.flatnonzero(feasible) == best)).min()
    history = result.history
    solved = history[history["status"] == "ok"]
    expected = np.maximum(0.0, solved["peak_support_force"] - FORCE_LIMIT) / FORCE_LIMIT
    np.testing.assert_allclose(solved["violation"], expected)
    assert (solved["feasible"] == (expected == 0)).all()
    assert (~solved["feasible"]).any()  # it did explore the infeasible gaps


def _fail_above_90_mm(how):
    """simulate_scene, failing above a gap of 90 mm: raising ``how``, or (``"SIGKILL"``) killing its process."""
    import os
    import signal

    simulate_scene = point.simulate_scene

    def failing(scene, settings):
        if scene.absorbers[0].contact.gap > 0.09:
            if how == "SIGKILL":
                os.kill(os.getpid(), signal.SIGKILL)
            raise how("made to fail above a gap of 90 mm")
        return simulate_scene(scene, settings)
    return failing


@pytest.mark.parametrize("how, workers, status", [
    (SimulationError, 1, "SimulationError"), (OverflowError, 1, "OverflowError"),
    (ZeroDivisionError, 2, "ZeroDivisionError"), ("SIGKILL", 2, "WorkerDied")],
    ids=["SimulationError", "OverflowError", "ZeroDivisionError on a pool", "a worker killed"])
def test_failed_points_are_infeasible_and_do_not_stop_it(monkeypatch, sweep, how, workers, status):
    """Whatever fails a point -- an error of the solve, any other exception, a worker process that dies on it --
    makes it infeasible, never an exception of the optimisation."""
    length, _ = sweep
    monkeypatch.setattr(point, "simulate_scene", _fail_above_90_mm(how))  # this process, and a forked pool's
    result = optimise(model_i(1000.0, 0.0), BOUNDS, "max_barrel_displacement", seed=1, workers=workers)
    failed = result.history[result.history["status"] != "ok"]
    assert len(failed) > 0 and (failed["contact.gap"] > 0.09).all()
    assert (failed["status"] == status).all() and (~failed["feasible"]).all()
    assert np.isinf(failed["violation"]).all() and failed["max_barrel_displacement"].isna().all()
    assert result.feasible and abs(result.parameters["contact.gap"] - GAPS[np.argmin(length)]) <= STEP
    assert result.to_dict()["failed_evaluations"] == len(failed)


def test_no_feasible_design_is_reported_as_such():
    result = optimise(model_i(1000.0, 0.0), BOUNDS, "peak_support_force", ["max_barrel_displacement<=0.1"],
                      seed=1, popsize=4, maxiter=2, workers=1)
    assert not result.feasible and not result.history["feasible"].any()
    (value,) = result.constraint_values
    assert not value["satisfied"] and value["value"] > 0.1
    assert "NO FEASIBLE DESIGN" in result.summary()


def test_same_seed_same_points_on_any_backend():
    runs = [optimise(model_i(500.0, 0.0), {"contact.gap": (0.0, 0.12), "absorber.mass": (100.0, 2000.0)},
                     "max_barrel_displacement", seed=7, popsize=3, maxiter=2, workers=w) for w in (1, 2)]
    columns = ["contact.gap", "absorber.mass", "max_barrel_displacement", "generation"]
    assert runs[0].history[columns].equals(runs[1].history[columns])
    assert runs[0].parameters == runs[1].parameters
    other = optimise(model_i(500.0, 0.0), {"contact.gap": (0.0, 0.12), "absorber.mass": (100.0, 2000.0)},
                     "max_barrel_displacement", seed=8, popsize=3, maxiter=2, workers=1)
    assert not other.history["contact.gap"].equals(runs[0].history["contact.gap"])


def test_dask_backend_gives_the_same_points():
    distributed = pytest.importorskip("dask.distributed")
    serial = optimise(model_i(1000.0, 0.0), BOUNDS, "max_barrel_displacement", seed=3, popsize=4, maxiter=1,
                      workers=1)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = optimise(model_i(1000.0, 0.0), BOUNDS, "max_barrel_displacement", seed=3, popsize=4, maxiter=1,
                          scheduler=client)
    assert remote.settings["backend"] == "dask"
    columns = ["contact.gap", "max_barrel_displacement"]
    assert remote.history[columns].equals(serial.history[columns])


def test_a_cluster_without_workers_stops_the_whole_optimisation(workerless_dask_cluster):
    """A fault of the cluster is an error of the optimisation, not a failed (infeasible) point."""
    address, said = workerless_dask_cluster.scheduler_address, []
    with pytest.raises(ClusterError) as info:
        optimise(model_i(1000.0, 0.0), BOUNDS, "max_barrel_displacement", seed=3, popsize=4, maxiter=1,
                 scheduler=address, worker_timeout=1.0, progress=said.append)
    assert str(info.value) == (f"no Dask worker has been available at {address} for 1 s (the worker timeout) after 0 "
                               "evaluations (generation 0); the optimisation stopped, nothing of it is kept: run it "
                               "again")
    assert said == []   # no generation was reported done


def test_writes_history_plot_and_summary(tmp_path):
    result = optimise(model_i(1000.0, 0.0), {"contact.gap": (0.0, 0.12), "absorber.mass": (100.0, 2000.0)},
                      "max_barrel_displacement", ["peak_support_force<=6500"], seed=1, popsize=3, maxiter=2,
                      workers=1)
    data = result.write(tmp_path)
    import pandas as pd
    assert pd.read_csv(tmp_path / "history.csv").shape[0] == result.evaluations
    assert (tmp_path / "optimise.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert data["parameters"] == result.parameters and data["feasible"] == result.feasible
    assert data["settings"]["seed"] == 1 and data["settings"]["population"] == 6


def test_figure_shows_convergence_and_design_space():
    from matplotlib.collections import PathCollection

    from mbs_models.results.optimise_plots import best_so_far, plot_optimisation

    np.testing.assert_array_equal(best_so_far(np.array([3.0, 1.0, 2.0, 0.5]), np.array([False, True, True, False])),
                                  [np.nan, 1.0, 1.0, 1.0])
    one = optimise(model_i(1000.0, 0.0), BOUNDS, "max_barrel_displacement", ["peak_support_force<=6020"],
                   seed=1, popsize=4, maxiter=2, workers=1)
    fig = plot_optimisation(one)
    convergence, space = fig.axes[:2]
    infeasible = (~one.history["feasible"]).any()
    assert len(convergence.get_lines()) == 2 + infeasible  # feasible, [infeasible,] best so far
    assert len(space.get_lines()) == 2 + infeasible       # feasible, [infeasible,] optimum
    star = space.get_lines()[-1]
    assert star.get_marker() == "*" and star.get_xdata()[0] == pytest.approx(one.parameters["contact.gap"] * 1e3)
    assert "[mm]" in space.get_xlabel() and "[mm]" in convergence.get_ylabel()
    two = optimise(model_i(1000.0, 0.0), {"contact.gap": (0.0, 0.12), "absorber.mass": (100.0, 2000.0)},
                   "max_barrel_displacement", seed=1, popsize=3, maxiter=1, workers=1)
    space = plot_optimisation(two).axes[1]
    (points,) = [c for c in space.collections if isinstance(c, PathCollection)]
    assert len(points.get_offsets()) == int(two.history["feasible"].sum())
    assert space.get_ylabel() == "absorber.mass [kg]"


def test_parsing():
    assert parse_bound("contact.gap=0:0.12") == ("contact.gap", (0.0, 0.12))
    assert parse_constraint("peak_support_force <= 7e3") == Constraint("peak_support_force", 7000.0, True)
    assert parse_constraint("max_barrel_displacement>=0.1") == Constraint("max_barrel_displacement", 0.1, False)
    assert Constraint("x", 2.0).violation(3.0) == 0.5 and Constraint("x", 2.0, False).violation(3.0) == 0.0
    assert math.isinf(Constraint("x", 2.0).violation(None))
    assert early_stop_metrics(["peak_support_force", "time_of_max_barrel_displacement"]) == \
        ("peak_support_force", "max_barrel_displacement")
    assert early_stop_metrics(["max_barrel_displacement", "wall_time"]) == ()


@pytest.mark.parametrize("bounds, minimise, constraints, options, key, text", [
    ({"contact.gapp": (0, 0.1)}, "max_barrel_displacement", (), {}, "contact.gapp", "did you mean"),
    ({"contact.gap": (0.1, 0.0)}, "max_barrel_displacement", (), {}, "contact.gap", "low < high"),
    ({"absorber.mass": (-1.0, 100.0)}, "max_barrel_displacement", (), {}, "absorber.mass", "> 0"),
    ({}, "max_barrel_displacement", (), {}, "bounds", "at least one"),
    (BOUNDS, "max_barrel_displacment", (), {}, "minimise", "did you mean 'max_barrel_displacement'"),
    (BOUNDS, "steps", (), {}, "minimise", "unknown metric"),
    (BOUNDS, "max_barrel_displacement", ["peak_force<=1"], {}, "constraints", "unknown metric"),
    (BOUNDS, "max_barrel_displacement", ["peak_support_force<1"], {}, "constraints", "METRIC<=VALUE"),
    (BOUNDS, "max_barrel_displacement", ["peak_support_force<=x"], {}, "constraints", "must be a number"),
    (BOUNDS, "max_barrel_displacement", (), {"popsize": 0}, "popsize", ">= 1"),
    (BOUNDS, "max_barrel_displacement", (), {"seed": 1.5}, "seed", "whole number"),
    (BOUNDS, "max_barrel_displacement", (), {"accuracy": "sloppy"}, "accuracy", "sloppy"),
])
def test_bad_input_fails_before_any_simulation(monkeypatch, bounds, minimise, constraints, options, key, text):
    def no_simulation(*args, **kwargs):  # pragma: no cover - must not run
        raise AssertionError("simulated despite bad input")

    monkeypatch.setattr(point, "simulate_scene", no_simulation)
    with pytest.raises(SceneError) as info:
        optimise(model_i(1000.0, 0.0), bounds, minimise, constraints, workers=1, **options)
    assert info.value.key == key and text in info.value.message, (info.value.key, info.value.message)
