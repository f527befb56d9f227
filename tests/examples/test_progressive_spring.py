"""The out-of-tree example (examples/progressive_spring.py): a user's element, registered from outside the
package, runs through simulate, the early stop, a sweep, the command line (``recoil --plugin``) and the
independent reference, and passes the element contract.

Each case runs in a fresh Python process: registering an element changes the registry of the process that
imports it, and the rest of the suite must see the shipped elements only.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]
EXAMPLE = ROOT / "examples" / "progressive_spring.py"
SCENE = ROOT / "examples" / "progressive_spring.toml"

#: simulate, the conformance clauses, the early stop against the full run, the guarantee against the reference at
#: ``standard``, and a sweep over the new table's key; prints one JSON object
_SCRIPT = """
import json, sys
from mbs_models.cli.plugins import load_plugins
load_plugins([sys.argv[1]])
import conformance
from mbs_models import load_scene, run_sweep, simulate
from mbs_models.engine.mechanism import Mechanism
from validation.studies.guarantee import errors_against_reference, reference_for, violations

scene = load_scene(sys.argv[2])
connector = next(c for c in Mechanism(scene).connectors if c.name == "progressive_spring")
conformance.check_all(connector)
stopped_early = conformance.check_early_stop(scene, 10.0)
result = simulate(scene, 10.0)
errors = errors_against_reference(result, reference_for(scene, 10.0, accuracy="standard"))
table = run_sweep(scene, {"progressive_spring.cubic_stiffness": [0.0, 2.0e6]}, workers=1, progress=False)
print(json.dumps({"stopped_early": stopped_early, "violations": violations(errors, "standard"),
                  "x": result.max_barrel_displacement, "S": result.peak_support_force,
                  "connector": type(connector).__name__,
                  "overrides_nothing": [name for name in ("python_stored_energy", "stored_energy", "force_bound",
                                                          "tangent_stiffness") if name in type(connector).__dict__],
                  "sweep_x": list(table["max_barrel_displacement"]), "sweep_status": list(table["status"]),
                  "peak_force": result.element_metrics["progressive_spring"]["peak_force"],
                  "peak_force_attribute": result.peak_force,
                  "force_history": result.element_histories["progressive_spring"]["force"].tolist(),
                  "barrel_position": result.barrel_position.tolist(),
                  "sweep_peak_force": list(table["progressive_spring.peak_force"])}))
"""


def _run(args):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT / "tests"), str(ROOT)]))
    done = subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout


@pytest.fixture(scope="module")
def python_run():
    return json.loads(_run(["-c", _SCRIPT, str(EXAMPLE), str(SCENE)]).strip().splitlines()[-1])


def test_the_user_element_gives_only_its_law_and_passes_the_contract(python_run):
    assert python_run["connector"] == "ProgressiveSpringConnector"
    assert python_run["overrides_nothing"] == []


def test_the_early_stop_of_a_law_alone_gives_the_full_runs_metrics(python_run):
    assert python_run["stopped_early"] is True


def test_engine_matches_the_reference_within_the_guarantee_at_standard(python_run):
    assert python_run["violations"] == []


def test_hand_checks_of_the_progressive_spring(python_run):
    """Energy: the barrel's free-recoil energy E = M v0^2 / 2 (v0 = m_p v_p / M) stored by the spring alone
    would reach U(x) = k1 x^2/2 + k3 x^4/4 = E; the damper takes some, so x_max lies below that root and above
    the root with the damper's work bounded by c_recoil v0 x (the damper's force never exceeds c v0 while the
    barrel slows down)."""
    import math

    M, v0 = 5600.0, 6.86 * 564.0 / 5600.0
    k1, k3, c = 20000.0, 2.0e6, 6239.0
    E = 0.5 * M * v0 ** 2

    def root(extra):
        lo, hi = 0.0, 1.0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if 0.5 * k1 * mid ** 2 + 0.25 * k3 * mid ** 4 + extra(mid) < E else (lo, mid)
        return lo

    upper = root(lambda x: 0.0)
    lower = root(lambda x: c * v0 * x)
    assert lower < python_run["x"] < upper
    assert not math.isclose(python_run["x"], math.sqrt(2 * E / k1), rel_tol=0.1)  # the cubic term matters


def test_a_sweep_over_the_new_tables_key(python_run):
    """k3 = 0 is the linear spring k1 (farther travel); both points run."""
    assert python_run["sweep_status"] == ["ok", "ok"]
    assert python_run["sweep_x"][0] > python_run["sweep_x"][1]
    assert python_run["sweep_x"][1] == pytest.approx(python_run["x"], rel=1e-12)


K1, K3 = 20000.0, 2.0e6  # N/m, N/m^3: examples/progressive_spring.toml


def test_the_declared_force_history_and_its_peak_are_in_the_result(python_run):
    """The declared history is the law on the barrel's position, ``F = k1 x + k3 x^3`` (computed here from the
    positions); the declared peak is its largest magnitude.  F increases with x, so the peak is F at the largest
    sampled x, which lies at or below the refined maximum displacement and within 0.1 % of it in force (an output
    step of the standard accuracy moves x by far less near the turning point, where v ~ 0)."""
    import numpy as np

    x = np.array(python_run["barrel_position"])
    force = np.array(python_run["force_history"])
    assert force == pytest.approx(K1 * x + K3 * x ** 3, rel=1e-12, abs=1e-9)
    peak = python_run["peak_force"]
    assert peak == pytest.approx(float(np.max(np.abs(K1 * x + K3 * x ** 3))), rel=1e-12)
    at_max = K1 * python_run["x"] + K3 * python_run["x"] ** 3
    assert at_max * (1.0 - 1e-3) <= peak <= at_max * (1.0 + 1e-12)
    assert python_run["peak_force_attribute"] == peak  # the declared metric by its name on the Result


def test_the_declared_peak_is_a_sweep_column(python_run):
    """k3 = 0: the linear spring, F = k1 x at its larger travel; the second point is the scene as run."""
    assert python_run["sweep_peak_force"][1] == pytest.approx(python_run["peak_force"], rel=1e-12)
    assert python_run["sweep_peak_force"][0] == pytest.approx(K1 * python_run["sweep_x"][0], rel=1e-3)


def test_recoil_run_and_validate_with_the_plugin(python_run, tmp_path):
    csv_path = tmp_path / "histories.csv"
    run = json.loads(_run(["-m", "mbs_models", "--plugin", str(EXAMPLE), "run", str(SCENE), "--json",
                           "--csv", str(csv_path)]))
    assert run["max_barrel_displacement"] == pytest.approx(python_run["x"], rel=1e-12)
    assert run["peak_support_force"] == pytest.approx(python_run["S"], rel=1e-12)
    assert run["progressive_spring"] == {"peak_force": pytest.approx(python_run["peak_force"], rel=1e-12)}
    import pandas as pd

    histories = pd.read_csv(csv_path)  # densified rows: the declared history is the law at every one of them
    x = histories["barrel position [m]"].to_numpy()
    assert len(x) > len(python_run["force_history"])
    assert list(histories["progressive_spring force [N]"]) == pytest.approx(list(K1 * x + K3 * x ** 3), rel=1e-12,
                                                                             abs=1e-9)
    validate = json.loads(_run(["-m", "mbs_models", "--plugin", str(EXAMPLE), "validate", str(SCENE), "--json"]))
    assert validate["passed"] is True


def test_a_plugin_that_cannot_be_imported_is_one_line_of_bad_input():
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    done = subprocess.run([sys.executable, "-m", "mbs_models", "--plugin", "no_such_plugin_module", "scenes"],
                          capture_output=True, text=True, cwd=ROOT, env=env, timeout=300)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "recoil: error: --plugin: cannot import 'no_such_plugin_module': ModuleNotFoundError: No module named "
        "'no_such_plugin_module'"]


def test_the_module_imported_twice_registers_its_second_definition():
    """``--plugin path.py`` and an ``import`` of the same file give two class objects of one definition: the
    second replaces the first on both sides (no "name taken" error), and scenes use the one imported last."""
    script = ("import sys\nfrom mbs_models.cli.plugins import load_plugins\n"
              f"load_plugins([{str(EXAMPLE)!r}])\n"
              f"sys.path.insert(0, {str(EXAMPLE.parent)!r})\n"
              "import progressive_spring\n"
              "from mbs_models import load_scene\n"
              "from mbs_models.elements import TABLES\n"
              "from validation.reference.terms import TERMS\n"
              f"scene = load_scene({str(SCENE)!r})\n"
              "print(TABLES['progressive_spring'] is progressive_spring.ProgressiveSpring,\n"
              "      TERMS['progressive_spring'] is progressive_spring.ReferenceTerm,\n"
              "      type(scene.progressive_spring) is progressive_spring.ProgressiveSpring)\n")
    assert _run(["-c", script]).split() == ["True", "True", "True"]


def test_the_optimiser_minimises_the_declared_metric_with_the_plugin(tmp_path):
    """``recoil --plugin ... optimise`` over the new table's key, minimising the element's declared metric: the
    optimum's objective is that metric, and it is the spring's force at the run's maximum displacement
    (F = k1 x + k3 x^3, the peak of a spring whose force rises with x, within 0.1 %)."""
    import tomllib

    _run(["-m", "mbs_models", "--plugin", str(EXAMPLE), "optimise", str(SCENE), "--vary",
          "progressive_spring.cubic_stiffness=0:4e6", "--minimise", "progressive_spring.peak_force", "--end-time", "2",
          "--popsize", "3", "--maxiter", "1", "--accuracy", "draft", "--out", str(tmp_path)])
    optimum = json.loads((tmp_path / "optimum.json").read_text())
    metrics, k3 = optimum["metrics"], optimum["parameters"]["progressive_spring.cubic_stiffness"]
    assert optimum["objective"] == metrics["progressive_spring.peak_force"] and 0.0 <= k3 <= 4e6
    k1 = tomllib.loads(SCENE.read_text())["progressive_spring"]["linear_stiffness"]
    x = metrics["max_barrel_displacement"]
    assert optimum["objective"] == pytest.approx(k1 * x + k3 * x ** 3, rel=1e-3)
