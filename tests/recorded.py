"""Numbers recorded on another machine (or by an earlier commit), and how to compare with them.

Floating point differs between CPUs in the last bits: numpy and OpenBLAS pick SIMD kernels by the CPU
they run on (AVX-512, AVX2 or SSE), and a vectorised ``x ** n`` or sum rounds differently from a scalar
one.  A number recorded on one machine is therefore compared on another within a tolerance derived from
what the number claims, never to the bit:

* a result of the engine at an accuracy preset claims the preset's guarantee against the exact solution
  (:data:`validation.studies.guarantee.TOLERANCES`, the README's "What is guaranteed"): lengths and
  velocities to ``metric``, forces and accelerations to ``force``, each impact's peak to ``impact_peak``
  (relative to itself), energies to ``metric`` of the run's energy scale (as the guarantee states the
  dissipated energies), times (of peaks, of impact starts and ends, of the samples) to ``time`` seconds;
* a number computed from the scene's inputs alone (a pulse's impulse) claims round-off: ``1e-12`` relative;
* counts, flags, names and the step count are compared exactly.  Exudyn's solve is compiled code that uses
  neither numpy's nor OpenBLAS's kernels: on x86-64 the same wheel (``requirements/lock.txt`` pins it) takes
  the same steps on every CPU; only the post-processing's numpy arithmetic differs between CPUs.

Lengths, velocities, accelerations, forces and energies are measured against the run's own scales, taken
from the recorded arrays when they were recorded (:func:`scales`): a tolerance never comes from the code
under test.

A time history is recorded as a :func:`summary` (its size, 33 samples spread over it, its extremes and
means), enough to catch a change anywhere in it without storing megabytes.  :func:`machine` records what
kernels the recording ran on.

Bit-identity is kept where it means something: two code paths of this package on the same machine in the
same test (fresh vs reused model, serial vs pool, early stop vs full run), which other tests check afresh.
"""

from __future__ import annotations

import json
import math
import os
import platform
import re
from contextlib import contextmanager

import numpy as np

#: Samples per recorded history (both ends included).
SAMPLES = 33
#: Relative tolerance of a number computed from the scene's inputs only (round-off of a short sum).
INPUT_RTOL = 1e-12


def preset_as_recorded(name: str):
    """The solver settings the preset ``name`` had when the baselines were recorded.

    Issue #24 raised the maximum step of ``draft`` (10 -> 20 ms) and ``standard`` (5 -> 20 ms): at the new
    settings the engine takes other steps, so step counts and histories sampled by index cannot be compared with
    a record of the old ones.  The recorded runs keep the settings they were recorded with (as
    ``SCENES_AS_RECORDED`` keeps a scene file as it was): they test that the engine's code still gives those
    runs.  The presets' new settings are checked against the independent reference instead
    (tests/validation/studies/test_presets.py, the hard cases, the property tests)."""
    from mbs_models import SolverSettings

    return {"draft": SolverSettings(relative_tolerance=1e-6, absolute_tolerance=1e-8, max_step=1e-2),
            "standard": SolverSettings(relative_tolerance=1e-9, absolute_tolerance=1e-11, max_step=5e-3),
            "reference": SolverSettings(relative_tolerance=1e-11, absolute_tolerance=1e-13, max_step=5e-3)}[name]


#: The early stop's cadence when the baselines were recorded: the finality tracker was shown the state at the start
#: of every 4th step, with no time interval (``mbs_models.engine.driver.OBSERVE_EVERY``, ``OBSERVE_INTERVAL``).
RECORDED_OBSERVE_EVERY = 4


@contextmanager
def early_stop_as_recorded():
    """The early stop's cadence as it was when the baselines were recorded (:data:`RECORDED_OBSERVE_EVERY`), for
    the ``with`` block.

    Issue #24 shows the tracker the state once 16 steps or 50 ms passed instead (an evaluation costs about a
    step): an early stop then ends at another step, so its step count and histories cannot be compared with a
    record of the old cadence, while its metrics do not move.  The recorded early stops keep their cadence (as
    :func:`preset_as_recorded` keeps the settings); tests/engine/test_v1_recorded.py checks the metrics at the
    current cadence against the same records."""
    from mbs_models.engine import driver

    saved = driver.OBSERVE_EVERY, driver.OBSERVE_INTERVAL
    driver.OBSERVE_EVERY, driver.OBSERVE_INTERVAL = RECORDED_OBSERVE_EVERY, math.inf
    try:
        yield
    finally:
        driver.OBSERVE_EVERY, driver.OBSERVE_INTERVAL = saved


def load_script(name: str):
    """The module ``scripts/<name>.py`` (the recorders: they are scripts, not a package)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "scripts" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# ------------------------------------------------------------------ recording
def summary(array) -> dict | None:
    """``{"size", "samples", "max", "min", "mean", "mean_abs"}`` of a history (None for None).  The samples are
    at the indices ``round(linspace(0, size - 1, 33))`` (every element of a shorter array)."""
    if array is None:
        return None
    values = np.asarray(array, dtype=float).ravel()
    if values.size == 0:
        return {"size": 0}
    return {"size": int(values.size), "samples": [float(v) for v in values[sample_indices(values.size)]],
            "max": float(values.max()), "min": float(values.min()), "mean": float(values.mean()),
            "mean_abs": float(np.abs(values).mean())}


def sample_indices(size: int) -> np.ndarray:
    """The indices a :func:`summary` samples of an array of ``size`` elements."""
    return np.unique(np.round(np.linspace(0, size - 1, min(size, SAMPLES))).astype(int))


def digest(array) -> str | None:
    """``"size:sha256"`` of an array's float64 bytes: how the first recordings kept a history (to verify against
    them; never to compare across machines)."""
    import hashlib

    if array is None:
        return None
    array = np.ascontiguousarray(np.asarray(array, dtype=float))
    return f"{array.size}:" + hashlib.sha256(array.tobytes()).hexdigest()


def recorder_arguments(doc: str, here):
    """The arguments of a recording script: ``out``, ``--tree`` (the checkout recorded, default ``here``) and
    ``--verify`` (the first recording, checked to the bit)."""
    import argparse

    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--tree", default=str(here), help="the checkout whose engine or reference is recorded")
    parser.add_argument("--verify", help="the first recording, to check every run against to the bit")
    return parser.parse_args()


def scales(*, length, velocity, acceleration, force, energy) -> dict[str, float]:
    """A run's scales (each the largest magnitude of the arrays given, at least the smallest normal float):
    tolerances of lengths (m), velocities (m/s), accelerations (m/s^2), forces (N) and energies (J) are
    relative to these."""
    def largest(arrays):
        out = 0.0
        for a in arrays:
            if a is not None and np.size(a):
                out = max(out, float(np.max(np.abs(a))))
        return max(out, np.finfo(float).tiny)
    return {"length": largest(length), "velocity": largest(velocity), "acceleration": largest(acceleration),
            "force": largest(force), "energy": largest(energy)}


def machine() -> dict:
    """What the recording ran on: the CPU, numpy's enabled SIMD features (its kernels dispatch on them),
    the variables that change the kernels, and the versions."""
    import scipy
    try:
        from numpy._core import _multiarray_umath as umath
    except ImportError:  # numpy < 2
        from numpy.core import _multiarray_umath as umath
    model = ""
    try:
        with open("/proc/cpuinfo") as cpuinfo:
            model = next((line.split(":", 1)[1].strip() for line in cpuinfo if line.startswith("model name")), "")
    except OSError:
        pass
    try:
        import exudyn
        exudyn_version = exudyn.__version__
    except ImportError:
        exudyn_version = None
    return {"machine": platform.machine(), "cpu": model or platform.processor(),
            "numpy_dispatch": [f for f in umath.__cpu_dispatch__ if umath.__cpu_features__.get(f)],
            "numpy_baseline": list(umath.__cpu_baseline__),
            "NPY_DISABLE_CPU_FEATURES": os.environ.get("NPY_DISABLE_CPU_FEATURES"),
            "OPENBLAS_CORETYPE": os.environ.get("OPENBLAS_CORETYPE"),
            "python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__,
            "exudyn": exudyn_version}


def dumps(data: dict) -> str:
    """A record as JSON text: the top-level tables indented, each run on one line (sorted keys; floats exact)."""
    def block(value, indent):
        if isinstance(value, dict) and indent < 2 and not _is_run(value):
            inner = ",\n".join(f"{' ' * (indent + 1)}{json.dumps(k)}: {block(v, indent + 1)}"
                                for k, v in sorted(value.items()))
            return "{\n" + inner + "\n" + " " * indent + "}"
        return json.dumps(value, sort_keys=True)
    return block(data, 0) + "\n"


def _is_run(value: dict) -> bool:
    return "scales" in value


# ------------------------------------------------------------------ comparing
def tolerance(kind: str, accuracy: str, run_scales: dict, recorded: float) -> float:
    """The absolute tolerance of a number of ``kind`` (see the module docstring) of a run at ``accuracy``."""
    from validation.studies.guarantee import TOLERANCES

    claim = TOLERANCES[accuracy]
    if kind in ("length", "velocity"):
        return claim["metric"] * run_scales[kind]
    if kind in ("force", "acceleration"):
        return claim["force"] * run_scales[kind]
    if kind == "impact_peak":
        return claim["impact_peak"] * abs(recorded)
    if kind == "energy":
        return claim["metric"] * run_scales["energy"]
    if kind == "time":
        return claim["time"]
    if kind == "input":
        return INPUT_RTOL * abs(recorded)
    raise ValueError(f"no tolerance for {kind!r}")


def differences(new, recorded, kind_of, accuracy: str, run_scales: dict, path: str = "") -> list[str]:
    """Where ``new`` differs from ``recorded`` beyond the tolerances (module docstring); ``kind_of(path)`` names
    the kind of the number at a path (``"exact"`` for counts, flags and names).  Keys added to the outputs
    since the recording are not compared; every recorded key must be there.  A recorded :func:`summary`
    (a dict with ``"size"``) is compared with the summary of the new array."""
    if is_summary(recorded):
        if not isinstance(new, dict) or "size" not in new:
            return [f"{path}: recorded a history, got {type(new).__name__}"]
        if new["size"] != recorded["size"]:
            return [f"{path}: {new['size']} samples, recorded {recorded['size']}"]
        if recorded["size"] == 0:
            return []
        fields = {f"{path}.{name}": (new[name], recorded[name]) for name in ("max", "min", "mean", "mean_abs")}
        fields.update({f"{path}[{i}]": pair for i, pair in zip(sample_indices(recorded["size"]).tolist(),
                                                               zip(new["samples"], recorded["samples"]))})
        kind = kind_of(path)
        return [d for p, (a, b) in fields.items() for d in _number(a, b, kind, accuracy, run_scales, p)]
    if isinstance(recorded, dict):
        if not isinstance(new, dict):
            return [f"{path}: recorded a table, got {new!r}"]
        out = [f"{path}: missing keys {sorted(set(recorded) - set(new))}"] if set(recorded) - set(new) else []
        for key in recorded:
            if key in new:
                out += differences(new[key], recorded[key], kind_of, accuracy, run_scales, f"{path}/{key}")
        return out
    if isinstance(recorded, (list, tuple)):
        if not isinstance(new, (list, tuple)) or len(new) != len(recorded):
            return [f"{path}: {len(new) if isinstance(new, (list, tuple)) else new!r} items, recorded {len(recorded)}"]
        return [d for i, (a, b) in enumerate(zip(new, recorded))
                for d in differences(a, b, kind_of, accuracy, run_scales, f"{path}[{i}]")]
    if isinstance(recorded, float) and not isinstance(recorded, bool):
        return _number(new, recorded, kind_of(path), accuracy, run_scales, path)
    if new != recorded:
        return [f"{path}: {new!r} != recorded {recorded!r}"]
    return []


def is_summary(value) -> bool:
    """True for a recorded :func:`summary` of a history."""
    return isinstance(value, dict) and "size" in value and set(value) <= {"size", "samples", "max", "min", "mean",
                                                                          "mean_abs"}


def _number(new, recorded: float, kind: str, accuracy: str, run_scales: dict, path: str) -> list[str]:
    if kind == "exact":
        return [] if new == recorded else [f"{path}: {new!r} != recorded {recorded!r}"]
    if not isinstance(new, (int, float)) or isinstance(new, bool) or not math.isfinite(new):
        return [f"{path}: {new!r}, recorded {recorded!r}"]
    allowed = tolerance(kind, accuracy, run_scales, recorded)
    if abs(new - recorded) <= allowed:
        return []
    return [f"{path}: {new!r} differs from the recorded {recorded!r} by {abs(new - recorded):.3g} "
            f"(allowed: {allowed:.3g}, {kind} at {accuracy!r})"]


# ------------------------------------------------------------------ kinds of the recorded outputs
_TIME = re.compile(r"(^|_)(time|start|end)(_|$)|^time_to_battery$")


def kind_of_output(path: str) -> str:
    """The kind of the number at ``path`` in the records of ``scripts/record_v1_baseline.py`` and
    ``scripts/record_postprocess_baseline.py`` (the key names say what a number is)."""
    parts = [p for p in re.split(r"[/\[\].]+", path) if p and not p.isdigit()]
    key = parts[-1] if parts else ""
    if len(parts) == 2 and parts[0] == "scales":
        return key
    if re.search(r"/impacts\[\d+\]/peak_force$", path) or re.search(r"/impacts\[\d+\]\[2\]$", path):
        return "impact_peak"
    if re.search(r"/impacts\[\d+\]\[[013]\]$", path):
        return "time"
    if re.search(r"/onsets\[\d+\]\[0\]$", path) or re.search(r"/max_velocities/[^/]+\[1\]$", path):
        return "time"
    if re.search(r"/onsets\[\d+\]\[1\]$", path) or re.search(r"/max_velocities/[^/]+\[0\]$", path):
        return "velocity"
    if key in ("steps", "impact_threshold") or key.startswith("max_step"):
        return "exact"
    if key == "pulse_impulse":
        return "input"
    if any(p in ("histories", "energy", "dissipated_energy", "work", "dissipated_energy_history") for p in parts) \
            or "energy" in key:
        return "energy"
    if key == "time" or _TIME.search(key):
        return "time"
    if "acceleration" in key:
        return "acceleration"
    if "velocity" in key:
        return "velocity"
    if "force" in key:
        return "force"
    if "displacement" in key or "position" in key:
        return "length"
    raise KeyError(f"no kind for the recorded number at {path!r}: name it in tests/recorded.py")
