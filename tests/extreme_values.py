"""Extreme values on the numeric keys of the shipped scenes (issue #20): the cases and the contract they must meet.

:func:`numeric_keys` lists a scene's numeric keys from its tables' own declarations: every field with a
:class:`~mbs_models.elements.table.Rule` (``RULES``, nested tables' too, set or not, the law's own fields for a
contact), and every other field that holds a number or a table of numbers (a tabulated orifice area, the
burst's shots, a pulse's times and forces).  :func:`check_case` sets one key to one value and checks the
contract: a :class:`SceneError` of one line naming that key or a related one, or a scene that loads and whose
short solve returns finite results or raises SceneError/SimulationError with a one-line message -- never another
exception, never a numpy ``RuntimeWarning``.

Run as a script it is the worker of :func:`run_cases`: JSON cases ``[scene, key, value]`` from a file, one JSON
outcome per line on stdout, so that a solve that never ends (a case for the solve budgets, not for the input
checks) can be stopped from outside.
"""

from __future__ import annotations

import json
import math
import os
import select
import subprocess
import sys
import time
import warnings
from dataclasses import fields, is_dataclass
from pathlib import Path

import numpy as np

from mbs_models import SceneError, SimulationError, UnitWarning, apply_overrides, load_scene
from mbs_models.elements.contact_laws import CONTACT_LAWS, LAW_FIELDS
from mbs_models.scenes import list_scenes, scene_path

#: Values beyond what double precision holds for some quantity, or not numbers at all: every case must end in
#: a SceneError or a solve that meets the contract at once.
EXTREME = [0, -0.0, 5e-324, 1e-300, 1e300, 1.8e308, math.inf, -math.inf, math.nan, -1, 10 ** 400, 2 ** 1024 - 1,
           "1e3", "", True, False]
#: Representable values far from the shipped ones: stiff or slow scenes (a never-ending solve is the solve
#: budgets' concern: the slow sweep stops it from outside and reports it).
FAR = [1e-30, 1e30, 2 ** 70]
#: The short solve of every scene that loads.
END_TIME = 0.01


def numeric_keys(scene) -> list[str]:
    """The dotted key of every numeric field of every table of ``scene`` (module docstring), in table order."""
    out = []

    def walk(table, prefix: str) -> None:
        law = CONTACT_LAWS.get(getattr(table, "law", None))
        allowed = None if law is None else law.fields + law.optional
        for f in fields(table):
            value = getattr(table, f.name)
            if f.name in table.NESTED:
                if value is not None:
                    walk(value, f"{prefix}.{f.name}")
            elif f.name in table.RULES:
                if allowed is None or f.name not in LAW_FIELDS or f.name in allowed:
                    out.append(f"{prefix}.{f.name}")
            elif _numbers(value):
                out.append(f"{prefix}.{f.name}")

    for key, table in scene.tables():
        walk(table, key)
    return out


def _numbers(value) -> bool:
    """A number (not a bool), or a non-empty table of numbers or of pairs of numbers."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return True
    return isinstance(value, (list, tuple)) and bool(value) and all(
        _numbers(item) and not isinstance(item, (list, tuple)) or
        isinstance(item, (list, tuple)) and all(_numbers(x) for x in item) for item in value)


def current(scene, key: str):
    """The value at ``key`` in ``scene`` (attribute path; ``absorber.N`` indexes the absorbers, and likewise
    every array of tables)."""
    parts = key.split(".")
    array = getattr(scene, parts[0] + "s", None)   # an array of tables: [[absorber]], [[tabulated_spring]]
    if isinstance(array, tuple):
        if len(parts) > 1 and parts[1].isdigit():
            target, parts = array[int(parts[1])], parts[2:]
        else:
            target, parts = array[0], parts[1:]
    else:
        target, parts = getattr(scene, parts[0]), parts[1:]
    for part in parts:
        target = getattr(target, part)
    return target


def with_value(old, value):
    """What to set for ``value`` at a key whose value is ``old``: the value itself for a number (or an absent
    field), and for a table the table with one entry replaced -- its largest number (a pulse's peak force, its
    last time) or, for pairs, the second number of the first pair (a tabulated area)."""
    if not isinstance(old, (list, tuple)):
        return value
    items = [list(item) if isinstance(item, (list, tuple)) else item for item in old]
    if isinstance(items[0], list):
        items[0][1] = value
    else:
        items[int(np.argmax(np.abs(items)))] = value
    return items


def related(error: SceneError, key: str) -> bool:
    """Does the error name ``key`` or a related key: a key of the same table (``absorber.1.contact.gap`` and
    ``absorber.1.mass``), or ``key`` itself in its message (a quantity of several tables lists every key; the
    message of a nested table's check names it from that table: ``contact.restitution``)?"""
    table = ".".join(key.split(".")[:2]) if key.startswith("absorber.") and key.split(".")[1].isdigit() \
        else key.split(".")[0]
    return error.key.startswith(table) or key in error.message or ".".join(key.split(".")[-2:]) in error.message


def one_line(error: Exception) -> bool:
    text = str(error)
    return bool(text.strip()) and "\n" not in text


def check_case(scene_name: str, key: str, value, solver: str = "engine") -> tuple[str, str]:
    """``(outcome, detail)`` of one case: ``refused`` (SceneError naming the key), ``failed`` (a SceneError or
    SimulationError from the solve), ``solved`` (finite results); ``violation`` for anything else: another
    exception, a RuntimeWarning, a message of several lines, an error naming an unrelated key, or non-finite
    results.  ``solver="reference"`` solves with the independent reference instead (its own errors,
    ReferenceSolveError and ReferenceModelError, are failures; its results must be finite)."""
    scene = load_scene(scene_path(scene_name))
    if solver == "reference":
        from validation.reference import ReferenceModelError, ReferenceSolveError, solve_reference
        solve, errors = solve_reference, (SceneError, ReferenceSolveError, ReferenceModelError)
    else:
        from mbs_models.engine.simulation import simulate
        solve, errors = (lambda changed, end_time: simulate(changed, end_time, "draft")), (SceneError, SimulationError)

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        warnings.simplefilter("ignore", UnitWarning)
        try:
            changed = apply_overrides(scene, {key: with_value(current(scene, key), value)})
        except SceneError as error:
            if not one_line(error) or not related(error, key):
                return "violation", f"SceneError not one line naming {key}: {error}"
            return "refused", str(error)
        except Exception as error:  # the contract: nothing else
            return "violation", f"{type(error).__name__} while loading: {error}"
        try:
            result = solve(changed, END_TIME)
        except errors as error:
            if not one_line(error):
                return "violation", f"{type(error).__name__} of several lines: {error}"
            return "failed", f"{type(error).__name__}: {error}"
        except Exception as error:
            return "violation", f"{type(error).__name__} while solving: {error}"
        if solver == "reference":
            samples = result.sample()
            finite = all(np.all(np.isfinite(v)) for v in samples.values()) and \
                np.all(np.isfinite(result.energy_balance(samples["t"])))
        else:
            try:
                json.dumps(result.metrics(), allow_nan=False)
            except ValueError as error:
                return "violation", f"non-finite metrics: {error}"
            finite = np.all(np.isfinite(result.energy_error()))
        return ("solved", "") if finite else ("violation", "non-finite results")


def all_cases(values) -> list[tuple[str, str, object]]:
    """``(scene, key, value)`` for every shipped scene, every numeric key and every value."""
    return [(name, key, value) for name in list_scenes() for key in numeric_keys(load_scene(scene_path(name)))
            for value in values]


def run_cases(cases, timeout: float, directory: Path, solver: str = "engine",
              worker_script: Path | None = None) -> list[tuple[tuple, str, str]]:
    """``(case, outcome, detail)`` of every case, each run by a worker process (this module as a script, the cases
    in a file in ``directory``); a case that takes longer than ``timeout`` s is stopped (outcome ``timeout``) and
    a worker started again after it.  ``worker_script``: another worker script with the same protocol (arguments: the
    cases' file and the first case's index; one JSON ``[outcome, detail]`` per line on stdout), whose cases are
    JSON mappings."""
    cases = [case if isinstance(case, dict) else tuple(case) for case in cases]
    path = directory / "cases.jsonl"
    path.write_text("".join(json.dumps(case if isinstance(case, dict) else list(case)) + "\n" for case in cases))
    arguments = [__file__, str(path)] if worker_script is None else [str(worker_script), str(path)]
    extra = [solver] if worker_script is None else []
    out: list[tuple[tuple, str, str]] = []
    while len(out) < len(cases):
        errors = directory / "worker.err"
        with open(errors, "wb") as stderr:
            worker = subprocess.Popen([sys.executable, *arguments, str(len(out)), *extra],
                                      stdout=subprocess.PIPE, stderr=stderr)
        buffer = b""
        while len(out) < len(cases):
            deadline = time.monotonic() + timeout
            ended = False
            while b"\n" not in buffer and not ended and time.monotonic() < deadline:
                ready, _, _ = select.select([worker.stdout], [], [], max(deadline - time.monotonic(), 0.0))
                if ready:
                    chunk = os.read(worker.stdout.fileno(), 65536)
                    ended = not chunk
                    buffer += chunk
            if b"\n" not in buffer:
                worker.kill()
                worker.wait()
                worker.stdout.close()
                last = (errors.read_text(errors="replace").strip().splitlines() or [""])[-1]
                out.append((cases[len(out)], "violation" if ended else "timeout",
                            f"the worker died: {last}" if ended else f"no outcome within {timeout:g} s"))
                break
            line, buffer = buffer.split(b"\n", 1)
            outcome, detail = json.loads(line)
            out.append((cases[len(out)], outcome, detail))
        else:
            worker.wait()
            worker.stdout.close()
    return out


def _worker(path: str, start: int, solver: str) -> None:
    lines = Path(path).read_text().splitlines()[start:]
    for line in lines:
        scene_name, key, value = json.loads(line)
        print(json.dumps(check_case(scene_name, key, value, solver)), flush=True)


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # validation/, not tests/validation/
    _worker(sys.argv[1], int(sys.argv[2]), sys.argv[3])
