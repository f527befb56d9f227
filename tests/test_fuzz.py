"""Fuzz test of the command line over generated adversarial scene files (issue #20): no traceback, no hang past
a bound, no NaN in any output, an error is one line (tests/fuzz_scenes.py: the generator and the contract).

A seeded sample runs in the fast suite; ``-m slow`` runs ten times as many. Each case runs ``recoil run FILE
--json`` in a worker process that is stopped after :data:`HANG_BOUND` s: a case still running then fails the
test (a run's cost is bounded by its step budget: 200 000 steps for a window of at most 4 s, about 0.1 s per
1 000 steps with 100 absorbers, the most a scene may have)."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pytest

from extreme_values import run_cases
from fuzz_scenes import check_outcome, fuzz_cases

#: Seconds a case may take before it counts as a hang.
HANG_BOUND = 120.0
WORKER = Path(__file__).with_name("fuzz_scenes.py")


def _run(seed: int, count: int, directory: Path) -> Counter:
    outcomes = run_cases(fuzz_cases(seed, count), HANG_BOUND, directory, worker_script=WORKER)
    broken = [(case["scene"], case["argv"], (case["toml"] or "")[:300], outcome, detail)
              for case, outcome, detail in outcomes if outcome != "ok"]
    assert not broken, f"{len(broken)} of {count} cases break the contract; the first: {broken[0]}"
    return Counter(detail for _, _, detail in outcomes)


def test_adversarial_scene_files(tmp_path):
    codes = _run(seed=20, count=200, directory=tmp_path)
    assert codes["exit 2"] > 0 and codes["exit 0"] + codes["exit 1"] > 0, codes  # the sample reaches both


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_adversarial_scene_files_many(tmp_path, seed):
    _run(seed=seed, count=2000, directory=tmp_path)


def test_the_contract_catches_what_it_forbids():
    """check_outcome itself: each kind of breach is named (else the fuzz test could pass by accident)."""
    assert check_outcome(0, '{"a": 1.0}', "") == ""
    assert check_outcome(2, "", "recoil: error: barrel.mass: must be > 0\n") == ""
    assert check_outcome(0, '{"a": 1.0}', "recoil: warning: firing.muzzle_velocity = 1e4 m/s ...\n") == ""
    assert "exit code" in check_outcome(-1, "", "")
    assert "exit code" in check_outcome(139, "", "")
    assert "stderr" in check_outcome(1, "", "Traceback (most recent call last):\n  File ...\nValueError: x\n")
    assert "stderr" in check_outcome(0, "{}", "/x.py:3: RuntimeWarning: overflow encountered in square\n")
    assert "error lines" in check_outcome(2, "", "recoil: error: a\nrecoil: error: b\n")
    assert "error lines" in check_outcome(1, "", "")
    assert "NaN" in check_outcome(0, '{"max_barrel_displacement": NaN}', "")
    assert "Infinity" in check_outcome(0, '{"x": -Infinity}', "")
    assert "JSON" in check_outcome(0, "not json", "")


def test_the_generator_is_seeded_and_adversarial():
    first, again = fuzz_cases(7, 40), fuzz_cases(7, 40)
    assert first == again and fuzz_cases(8, 40) != first
    texts = [case["toml"] for case in first if case["toml"] is not None]
    assert any("nan" in text or "inf" in text for text in texts) and any("bogus_key" in text for text in texts)
