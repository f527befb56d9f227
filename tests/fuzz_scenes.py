"""Adversarial scene files run through the ``recoil`` command line (issue #20): the generator and the worker.

:func:`fuzz_cases` draws, from a seed, cases ``{"toml": text or None, "argv": [...]}``: a shipped scene's TOML
mapping with one to four mutations (a number scaled by up to 1e+-8; a number at an extreme or random magnitude,
non-finite or beyond 64 bits;
a value of the wrong type; a key or table removed; an unknown key; 0 to 150 absorbers; a table of numbers
shuffled, emptied, cut to one entry, grown to 25 000 entries or given a NaN; another format version), or its
text cut short, given non-UTF-8 bytes or a repeated header, or a shipped scene with adversarial ``--set``
values.  Each is run as ``recoil run FILE --json --end-time T`` (T of 0.01-0.05 s, sometimes up to 2 s).

:func:`check_outcome` is the contract: exit code 0, 1 or 2; nothing that is not ``recoil``'s own line on stderr
(no traceback, no Python or numpy warning); an error is one line; the JSON of a success holds no NaN or
infinity.  Run as a script (by :func:`extreme_values.run_cases`) this module is the worker: it runs the cases of
a file through :func:`mbs_models.cli.main` in this process, its stdout and stderr captured at the file
descriptors (Exudyn writes there from C++), and prints one JSON outcome per line on the protocol's pipe.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import math
import os
import random
import sys
import tempfile
import tomllib
from pathlib import Path

#: Numbers at the edges of double precision, non-finite, or out of any range.
EXTREME_NUMBERS = [0, -0.0, 5e-324, 1e-300, 1e-30, 1e30, 1e300, 1.8e308, math.inf, -math.inf, math.nan, -1, -1e30,
                   2 ** 63 - 1, 2 ** 70]
#: Values of the wrong type for a number.
WRONG_TYPES = ["abc", "", [], [1.0, "a"], {"x": 1.0}, True, "1e3"]
#: Extra ``--end-time`` values (s) beside the short windows.
END_TIMES = [0.01, 0.02, 0.05, 0.05, 0.2, 2.0]


def _leaves(data, prefix=()):
    """(path, value) of every scalar or array-of-scalars leaf of a TOML mapping (paths of keys and indices)."""
    if isinstance(data, dict):
        for key, value in data.items():
            yield from _leaves(value, prefix + (key,))
    elif isinstance(data, list) and data and isinstance(data[0], dict):
        for index, value in enumerate(data):
            yield from _leaves(value, prefix + (index,))
    else:
        yield prefix, data


def _tables(data, prefix=()):
    """Paths of every table (dict) of a TOML mapping, the top level included."""
    if isinstance(data, dict):
        yield prefix
        for key, value in data.items():
            yield from _tables(value, prefix + (key,))
    elif isinstance(data, list):
        for index, value in enumerate(data):
            if isinstance(value, dict):
                yield from _tables(value, prefix + (index,))


def _at(data, path):
    for part in path:
        data = data[part]
    return data


def _random_number(rng: random.Random):
    if rng.random() < 0.6:
        return rng.choice(EXTREME_NUMBERS)
    return rng.choice([1.0, -1.0]) * 10.0 ** rng.uniform(-320.0, 308.0)


def _numeric_array(rng: random.Random, old: list) -> list:
    flat = [x for x in old if isinstance(x, (int, float))]
    kind = rng.choice(["shuffle", "empty", "one", "grow", "nan", "reverse"])
    if kind == "shuffle":
        return rng.sample(old, len(old))
    if kind == "empty":
        return []
    if kind == "one":
        return old[:1]
    if kind == "reverse":
        return old[::-1]
    if kind == "grow" and flat:
        return [flat[0] + (flat[-1] - flat[0]) * i / 25_000 for i in range(25_001)]
    items = copy.deepcopy(old)
    if items and isinstance(items[0], list):
        items[0][-1] = math.nan
    elif items:
        items[rng.randrange(len(items))] = math.nan
    return items


def _mutate(rng: random.Random, data: dict) -> None:
    """One mutation of a scene mapping, in place."""
    leaves = [(p, v) for p, v in _leaves(data) if p]
    kind = rng.choice(["scale"] * 6 + ["number", "number", "type", "delete", "unknown", "absorbers", "array",
                                       "version"])
    numbers = [(p, v) for p, v in leaves if isinstance(v, (int, float)) and not isinstance(v, bool)]
    arrays = [(p, v) for p, v in leaves if isinstance(v, list) and v]
    if kind == "scale" and numbers:  # a representable value far from the shipped one: a stiff or slow scene
        path, old = rng.choice(numbers)
        _at(data, path[:-1])[path[-1]] = (old or 1.0) * 10.0 ** rng.uniform(-8.0, 8.0)
    elif kind == "number" and numbers:
        path, _ = rng.choice(numbers)
        _at(data, path[:-1])[path[-1]] = _random_number(rng)
    elif kind == "type" and leaves:
        path, _ = rng.choice(leaves)
        _at(data, path[:-1])[path[-1]] = copy.deepcopy(rng.choice(WRONG_TYPES))
    elif kind == "delete" and leaves:
        target = rng.choice([p for p, _ in leaves] + [p for p in _tables(data) if p])
        parent = _at(data, target[:-1])
        if isinstance(parent, list):
            parent.pop(target[-1])
        else:
            parent.pop(target[-1], None)
    elif kind == "unknown":
        table = rng.choice(list(_tables(data)))
        _at(data, table)["bogus_key"] = 1.0
    elif kind == "absorbers" and isinstance(data.get("absorber"), list) and data["absorber"]:
        count = rng.choice([0, 2, 7, 100, 101, 150])
        template = data["absorber"][0]
        data["absorber"] = [{**copy.deepcopy(template), "name": f"a{i}"} for i in range(count)]
        if count == 0:
            del data["absorber"]
    elif kind == "array" and arrays:
        path, old = rng.choice(arrays)
        _at(data, path[:-1])[path[-1]] = _numeric_array(rng, old)
    elif kind == "version":
        data["version"] = rng.choice([3, 0, -1, "2", 2.5])


def _value(value) -> str:
    """TOML text of a value: inline tables and arrays, what TOML writes for inf and nan, integers of any size."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ("nan" if math.isnan(value) else ("inf" if value > 0 else "-inf"))
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return json.dumps(value)  # a TOML basic string is a JSON string for these
    if isinstance(value, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {_value(v)}" for k, v in value.items()) + "}"
    return "[" + ", ".join(_value(item) for item in value) + "]"


def _toml_text(data: dict, header: str = "") -> str:
    """TOML text of a mapping: scalars first, then sub-tables ``[a.b]`` and arrays of tables ``[[a]]``."""
    def tables(value):
        return isinstance(value, list) and value and all(isinstance(item, dict) for item in value)

    lines = [f"{json.dumps(k)} = {_value(v)}" for k, v in data.items() if not isinstance(v, dict) and not tables(v)]
    for key, value in data.items():
        path = f"{header}.{json.dumps(key)}" if header else json.dumps(key)
        if isinstance(value, dict):
            lines += ["", f"[{path}]", _toml_text(value, path)]
        elif tables(value):
            for item in value:
                lines += ["", f"[[{path}]]", _toml_text(item, path)]
    return "\n".join(lines) + ("" if header else "\n")


def _corrupt(rng: random.Random, text: str) -> str | bytes:
    kind = rng.choice(["cut", "bytes", "header", "nest"])
    if kind == "cut":
        return text[: rng.randrange(1, max(len(text), 2))]
    if kind == "bytes":
        at = rng.randrange(len(text))
        return text[:at].encode() + bytes([0xFF, 0xFE, 0x00, 0x80]) + text[at:].encode()
    if kind == "header":
        header = next((line for line in text.splitlines() if line.startswith("[")), "[barrel]")
        return text + "\n" + header + "\n"
    return text + "\ndeep = " + "[" * 200 + "]" * 200 + "\n"


def _set_values(rng: random.Random, data: dict) -> list[str]:
    numbers = [p for p, v in _leaves(data) if isinstance(v, (int, float)) and not isinstance(v, bool) and p]
    out = []
    for _ in range(rng.randint(1, 3)):
        path = rng.choice(numbers) if numbers else ("barrel", "mass")
        key = ".".join(str(part) for part in path)
        value = rng.choice([repr(_random_number(rng)), "nan", "inf", "1e999", "abc", "[1, 2]", "{a = 1}", ""])
        out += ["--set", f"{key}={value}"]
    return out


def fuzz_cases(seed: int, count: int) -> list[dict]:
    """``count`` cases drawn from ``seed`` (module docstring): ``{"scene": name, "toml": text or None,
    "binary": bool, "argv": [...]}``; ``toml`` is None for the shipped scene with ``--set`` values."""
    from mbs_models.scenes import list_scenes, scene_path

    rng = random.Random(seed)
    names = list_scenes()
    out = []
    for _ in range(count):
        name = rng.choice(names)
        data = tomllib.loads(scene_path(name).read_text())
        argv = ["--end-time", repr(rng.choice(END_TIMES))]
        if rng.random() < 0.15:
            out.append({"scene": name, "toml": None, "binary": False, "argv": argv + _set_values(rng, data)})
            continue
        for _ in range(rng.randint(1, 4)):
            _mutate(rng, data)
        text = _toml_text(data)
        if rng.random() < 0.1:
            text = _corrupt(rng, text)
        binary = isinstance(text, bytes)
        out.append({"scene": name, "toml": text.decode("latin-1") if binary else text, "binary": binary,
                    "argv": argv})
    return out


def check_outcome(code: int, stdout: str, stderr: str) -> str:
    """What the outcome of one case breaks of the contract (module docstring); empty: nothing."""
    if code not in (0, 1, 2):
        return f"exit code {code}: " + " | ".join(stderr.strip().splitlines()[-3:])
    lines = [line for line in stderr.splitlines() if line.strip()]
    foreign = [line for line in lines if not line.startswith("recoil: ")]
    if foreign:
        return f"not recoil's own line on stderr: {foreign[0][:200]}"
    errors = [line for line in lines if line.startswith(("recoil: error:", "recoil: simulation failed:"))]
    if code != 0 and len(errors) != 1:
        return f"exit {code} with {len(errors)} error lines"
    if code == 0:
        def refuse(constant):
            raise ValueError(f"{constant} in the JSON")
        try:
            json.loads(stdout, parse_constant=refuse)
        except ValueError as error:
            return f"JSON output: {error}"
    return ""


def run_case(case: dict, directory: Path) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of ``recoil run`` on one case in this process, captured at the descriptors."""
    from mbs_models.cli import main

    if case["toml"] is None:
        scene = case["scene"]
    else:
        path = directory / "scene.toml"
        path.write_bytes(case["toml"].encode("latin-1") if case["binary"] else case["toml"].encode())
        scene = str(path)
    captured = {}
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        sys.stdout.flush()
        sys.stderr.flush()
        saved = os.dup(1), os.dup(2)
        os.dup2(out.fileno(), 1)
        os.dup2(err.fileno(), 2)
        try:
            python_out, python_err = io.StringIO(), io.StringIO()
            with contextlib.redirect_stdout(python_out), contextlib.redirect_stderr(python_err):
                try:
                    code = main(["run", scene, "--json", *case["argv"]])
                except BaseException as error:  # the contract: main returns a code, whatever happens
                    code = -1
                    print(f"{type(error).__name__} escaped main: {error}", file=sys.stderr)
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
        for name, handle, python in (("out", out, python_out), ("err", err, python_err)):
            handle.seek(0)
            captured[name] = handle.read().decode(errors="replace") + python.getvalue()
    return code, captured["out"], captured["err"]


def _worker(path: str, start: int) -> None:
    protocol = os.fdopen(os.dup(1), "w")
    with tempfile.TemporaryDirectory() as directory:
        for line in Path(path).read_text().splitlines()[start:]:
            code, stdout, stderr = run_case(json.loads(line), Path(directory))
            broken = check_outcome(code, stdout, stderr)
            outcome = ("violation", broken) if broken else ("ok", f"exit {code}")
            print(json.dumps(outcome), file=protocol, flush=True)


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # validation/, not tests/validation/
    _worker(sys.argv[1], int(sys.argv[2]))
