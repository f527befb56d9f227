"""Extreme values on every numeric key of every shipped scene (issue #20): a one-line SceneError naming the key,
or a scene that loads and whose short solve (``simulate(scene, 0.01, "draft")``) returns finite results or raises
SceneError/SimulationError with a one-line message -- never another exception, never a numpy RuntimeWarning.

The keys come from the tables' own declarations (``tests/extreme_values.py``: ``numeric_keys``); every case runs
in a worker process that is stopped after a time limit: a solve that does not end (a stiff but representable
scene) is the solve budgets' concern, reported here as a warning, not judged.  By default a seeded sample of the
values beyond double precision (``EXTREME``); ``-m slow``: every key, every value, the far but representable
values (``FAR``) too, and the independent reference on a seeded sample of 600 values beyond double precision.
"""

from __future__ import annotations

import os
import random
import tomllib
import warnings

import pytest

from extreme_values import EXTREME, FAR, all_cases, run_cases
from mbs_models.cli import main
from mbs_models.scene.io import mapping_to_toml
from mbs_models.scenes import scene_path

#: Cases of the fast sample, and its seed; cases of the reference's (slow) sample.
SAMPLE, SEED = 120, 20
REFERENCE_SAMPLE = 600
#: Seconds a case may take before it is stopped (the slowest sampled case takes well under a second).
TIMEOUT = 30.0


def _judge(outcomes) -> None:
    violations = [f"{case}: {detail}" for case, outcome, detail in outcomes if outcome == "violation"]
    stopped = [case for case, outcome, _ in outcomes if outcome == "timeout"]
    if stopped:
        warnings.warn(f"{len(stopped)} solves stopped after {TIMEOUT:g} s (the solve budgets' concern): {stopped}")
    assert not violations, "\n".join(violations)


def test_a_seeded_sample_of_values_beyond_double_precision_meets_the_contract(tmp_path):
    cases = all_cases(EXTREME)
    sample = random.Random(SEED).sample(cases, SAMPLE)
    outcomes = run_cases(sample, TIMEOUT, tmp_path)
    _judge(outcomes)
    kinds = {outcome for _, outcome, _ in outcomes}
    assert {"refused", "solved"} <= kinds, kinds  # the sample reaches both sides of the checks


@pytest.mark.slow
def test_every_key_of_every_scene_at_every_extreme_value_meets_the_contract(tmp_path):
    _judge(run_cases(all_cases(EXTREME + FAR), TIMEOUT, tmp_path))


@pytest.mark.slow
def test_the_reference_meets_the_contract_on_the_scenes_the_checks_accept(tmp_path):
    """The independent reference reads the same scenes: its own errors (ReferenceSolveError, ReferenceModelError)
    or finite results, never another exception or a numpy warning.  A seeded sample (every case takes about an hour
    on 2 cores: the reference solves slowly where the scene is extreme)."""
    cases = random.Random(SEED).sample(all_cases(EXTREME), REFERENCE_SAMPLE)
    _judge(run_cases(cases, TIMEOUT, tmp_path, "reference"))


def _file(tmp_path, scene: str, key: str, value: str):
    """The shipped scene's file with ``key`` (``table.field``, ``table.sub.field``; the first of ``[[absorber]]``)
    set to ``value``, TOML text (``1.8e308`` is inf to TOML: a float cannot carry it); a pulse's file replaces
    its table."""
    data = tomllib.loads(scene_path(scene).read_text())
    *tables, name = key.split(".")
    target = data
    for table in tables:
        target = target[table][0] if isinstance(target[table], list) else target[table]
    target[name] = "VALUE"
    if name == "file":
        del target["times"], target["forces"]
    path = tmp_path / f"{scene}.toml"
    path.write_text(mapping_to_toml(data).replace('"VALUE"', value))
    return path


CLI_CASES = [  # (scene, key set, value as TOML, the key the one line names): the cases of issue #20
    ("model_ii", "barrel.mass", "1e-300", "barrel.mass"),                                   # v0 = I / M overflows
    ("simplified", "firing.projectile_mass", "1e300", "firing.projectile_mass"),
    ("recoil_brake", "recoil_brake.discharge_coefficient", "1e-300", "recoil_brake.discharge_coefficient"),  # Cd^2 = 0
    ("realistic", "recuperator.gas_volume", "1e-300", "recuperator.gas_volume"),            # was brentq's RuntimeError
    ("model_ii", "recoil_damper.recoil", "1.8e308", "recoil_damper.recoil"),                # inf to TOML
    ("model_ii", "recoil_spring.stiffness", str(10 ** 400), "recoil_spring.stiffness"),    # float() would overflow
    ("two_absorbers", "absorber.name", '"recoil_spring"', "absorber.0.name"),               # a colliding name
    ("breech_pulse", "firing.pulse.file", '"/dev/zero"', "firing.pulse.file"),              # read without limit
]


@pytest.mark.parametrize("scene, key, value, named", CLI_CASES, ids=[f"{c[0]}-{c[1]}" for c in CLI_CASES])
def test_recoil_run_on_an_extreme_file_exits_2_with_one_line(tmp_path, capsys, scene, key, value, named):
    if "/dev/zero" in value and not os.path.exists("/dev/zero"):
        pytest.skip("needs /dev/zero")
    assert main(["run", str(_file(tmp_path, scene, key, value)), "--json"]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert captured.out == "" and len(lines) == 1 and "Traceback" not in captured.err, captured.err
    assert lines[0].startswith(f"recoil: error: {named}:"), lines[0]


def test_recoil_run_on_a_file_nested_1000_deep_exits_2_with_one_line(tmp_path, capsys):
    """The TOML parser recursed once per level (a RecursionError near 1000): the depth is refused first."""
    path = tmp_path / "deep.toml"
    path.write_text(scene_path("model_ii").read_text() + "\n[conventions]\nx = " + "[" * 1000 + "]" * 1000 + "\n")
    assert main(["run", str(path)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and "nested more than 32 deep" in lines[0] and "Traceback" not in captured.err
