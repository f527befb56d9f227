"""Issue #24's ratios against the code before it, measured in one run (a part of ``scripts/bench_scipy.py``).

The code before issue #24 is :data:`BASELINE_COMMIT` (main's HEAD when the issue's work began), exported with
``git archive`` into a temporary directory (no worktree is registered in the repository, nothing is left behind
if the run is interrupted).  Both trees run in their own interpreter with this venv's python and ``PYTHONPATH``
pointing to the tree; each worker reports ``mbs_models.__file__`` and the run refuses to measure if a worker
imported the package from elsewhere.  Three measurements, interleaved between the two trees round by round so
that a shared machine's load drifts into both alike (and in alternating order):

* a complete ``standard`` run of model (ii) (m = 1000 kg, gap 0), 10 s: median wall and CPU time;
* an early-stopped point of the Figs 4/5 grid (``stop_when_final=("max_barrel_displacement",)``), serial: CPU time
  (``time.process_time``) per point, the median over rounds of each round's mean over the points;
* the fixed cost of a call: CPU per ``simulate`` of a 1 ms window (model (ii), ``standard``), a mean over
  :data:`FIXED_COST_CALLS` calls;
* the engine's runs of the ``compression_only`` reading of the convention study (``recoil paper``), whose cases
  fail on a collapsed step: CPU of the reading (the step guard's stall and collapse windows);
* import to the first result in a fresh interpreter (``import mbs_models`` and ``simulate(model_ii(), 0.01)``):
  the interpreter's own clock from before the import to the result, the process's wall time and its CPU time
  (user + system, less sensitive to a shared machine's load); medians of :data:`IMPORT_ROUNDS` rounds.  Both trees'
  modules are compiled to bytecode first (``compileall``, as ``pip install`` does): with ``PYTHONDONTWRITEBYTECODE``
  set, as on some machines, every run would otherwise time Python's compiler on the package's source (some 50 ms).
  In the same rounds the floor no change of this package moves (:data:`FLOORS`): the bare interpreter
  (``python -c pass``) and the interpreter importing numpy and Exudyn's fast module, process wall times.

Each ratio is now / before (< 1: faster now).  With both trees at the same code the ratios must come out ~1:
that is the check that the measurement is fair.
"""

from __future__ import annotations

import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: main's HEAD before issue #24's work (speed): the code the issue's ratios are against.
BASELINE_COMMIT = "0657fb5eda333496f1c3ed034028224136d77de5"
#: Figs 4/5 points of the sweep-point measurement: (model, absorber mass kg, gap m).
SWEEP_POINTS = tuple((model, mass, gap) for model in ("i", "ii") for mass in (100.0, 1000.0)
                     for gap in (0.0, 0.04, 0.08, 0.12))
QUICK_SWEEP_POINTS = tuple((model, mass, gap) for model in ("i", "ii") for mass, gap in ((100.0, 0.0), (1000.0, 0.08)))

#: A worker: reports where it imported mbs_models from, then answers one JSON request per line.
_WORKER = r"""
import json, sys, time, warnings
warnings.simplefilter("ignore")
import mbs_models
from mbs_models import model_i, model_ii, simulate
print(json.dumps({"file": mbs_models.__file__}), flush=True)
for line in sys.stdin:
    request = json.loads(line)
    if request["what"] == "run":
        scene = model_ii(1000.0, 0.0)
        wall, cpu = time.perf_counter(), time.process_time()
        result = simulate(scene, 10.0, "standard")
        answer = {"wall": time.perf_counter() - wall, "cpu": time.process_time() - cpu,
                  "values": [result.max_barrel_displacement, result.steps]}
    elif request["what"] == "call":
        scene = model_ii(1000.0, 0.0)
        cpu = time.process_time()
        for _ in range(request["calls"]):
            simulate(scene, 1e-3, "standard")
        answer = {"cpu": (time.process_time() - cpu) / request["calls"]}
    elif request["what"] == "reading":
        from validation.studies.conventions import CONVENTION_CASES, convention_jobs, engine_job
        labels = [label for label, _ in CONVENTION_CASES]
        scenes = [scene for index, _, scene in convention_jobs() if labels[index] == request["label"]]
        cpu = time.process_time()
        outcomes = [engine_job(scene) for scene in scenes]
        answer = {"cpu": time.process_time() - cpu, "failed": sum("error" in outcome for outcome in outcomes)}
    elif request["what"] == "sweep":  # the Figs 4/5 path: gap_sweep, serial, on the process's kept systems
        from mbs_models.studies.sweep import gap_sweep
        groups = {}
        for model, mass, gap in request["points"]:
            groups.setdefault((model, mass), []).append(gap)
        cpu = time.process_time()
        values = [p.max_barrel_displacement for (model, mass), gaps in groups.items()
                  for p in gap_sweep(model_i if model == "i" else model_ii, mass, gaps, 10.0, "standard", workers=1,
                                     stop_when_final=("max_barrel_displacement",))]
        answer = {"cpu": (time.process_time() - cpu) / len(request["points"]), "values": values}
    else:
        scenes = [(model_i if model == "i" else model_ii)(mass, gap) for model, mass, gap in request["points"]]
        cpu = time.process_time()
        values = [simulate(s, 10.0, "standard", stop_when_final=("max_barrel_displacement",)).max_barrel_displacement
                  for s in scenes]
        answer = {"cpu": (time.process_time() - cpu) / len(scenes), "values": values}
    print(json.dumps(answer), flush=True)
"""

_IMPORT = ("import time; start = time.perf_counter(); import mbs_models; from mbs_models import model_ii, simulate; "
           "simulate(model_ii(), 0.01); print(time.perf_counter() - start, mbs_models.__file__)")
#: What the first result costs whatever this package does: (name, code) run in a fresh interpreter, process wall.
FLOORS = (("interpreter (python -c pass)", "pass"),
          ("interpreter, numpy and Exudyn", "import contextlib, io, sys; sys.exudynFast = True\n"
                                            "with contextlib.redirect_stdout(io.StringIO()): import numpy, exudyn"))
#: Rounds of the import measurement (each: both trees and the floors, in alternating order).
IMPORT_ROUNDS = 15


@contextmanager
def baseline_tree(commit: str = BASELINE_COMMIT):
    """The files of ``commit`` in a temporary directory (``git archive``), or None without git history."""
    directory = Path(tempfile.mkdtemp(prefix="recoil-before-24-"))
    try:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", commit], capture_output=True)
        if archive.returncode != 0:
            yield None
            return
        subprocess.run(["tar", "-x", "-C", str(directory)], input=archive.stdout, check=True, capture_output=True)
        yield directory
    finally:
        shutil.rmtree(directory, ignore_errors=True)


def _environment(tree: Path) -> dict:
    return {**os.environ, "PYTHONPATH": str(tree)}


def _check_origin(tree: Path, file: str) -> None:
    if not Path(file).resolve().is_relative_to(tree.resolve()):
        raise RuntimeError(f"a worker for {tree} imported mbs_models from {file}: the measurement would be wrong")


class Worker:
    """A python process with ``tree`` on its path, answering the requests of :data:`_WORKER`."""

    def __init__(self, tree: Path):
        self.process = subprocess.Popen([sys.executable, "-c", _WORKER], cwd=str(tree), env=_environment(tree),
                                        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.file = json.loads(self.process.stdout.readline())["file"]
        _check_origin(tree, self.file)

    def ask(self, **request) -> dict:
        self.process.stdin.write(json.dumps(request) + "\n")
        self.process.stdin.flush()
        line = self.process.stdout.readline()
        if not line:
            raise RuntimeError(f"the worker importing {self.file} ended (exit code {self.process.wait()})")
        return json.loads(line)

    def close(self) -> None:
        self.process.stdin.close()
        self.process.wait(timeout=60)


def import_once(tree: Path) -> tuple[float, float, float]:
    """(seconds from before ``import mbs_models`` to the first result, in the interpreter; the process's wall
    seconds; its CPU seconds, user + system) with the code in ``tree``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", _IMPORT], cwd=str(tree), env=_environment(tree), check=True,
                         capture_output=True, text=True).stdout.split()
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    _check_origin(tree, out[1])
    return float(out[0]), wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def compile_tree(tree: Path) -> None:
    """Compile the package in ``tree`` to bytecode (``__pycache__``, as an installed package has it)."""
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(tree / "mbs_models")], check=True,
                   capture_output=True)


def floor_once(code: str) -> float:
    """The process wall time (s) of ``python -c code``."""
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, cwd=tempfile.gettempdir())
    return time.perf_counter() - start


def paper_cpu(tree: Path) -> tuple[float, float]:
    """(CPU s, user + system, and wall s) of a full serial ``recoil paper --workers 1`` with the code in ``tree``,
    output into a temporary directory."""
    with tempfile.TemporaryDirectory(prefix="recoil-paper-") as out:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "mbs_models", "paper", "--out", out, "--workers", "1"], cwd=str(tree),
                       env=_environment(tree), check=True, capture_output=True)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), wall


def _alternating(items: dict, round_: int) -> list:
    """The items in their order in even rounds, reversed in odd ones (neither tree always goes first)."""
    pairs = list(items.items())
    return pairs if round_ % 2 == 0 else pairs[::-1]


#: Calls of a 1 ms run per round of the fixed-cost measurement.
FIXED_COST_CALLS = 50
#: The reading of the paper whose cases collapse the engine's step (the step guard's collapse window).
COLLAPSING_READING = "compression_only"


def import_samples(trees: dict[str, Path], samples: dict[str, dict[str, list[float]]], rounds: int = IMPORT_ROUNDS,
                   progress=lambda message: None) -> dict[str, list[float]]:
    """Import to the first result with each tree, ``rounds`` times, appended to ``samples[tree name]`` (``"import"``,
    ``"import process"``, ``"import process cpu"``: s); returns the floors' process wall times (s) of the same rounds,
    by :data:`FLOORS` name."""
    for tree in trees.values():  # bytecode as installed, then a warm-up (the file system's cache)
        compile_tree(tree)
        import_once(tree)
    floors: dict[str, list[float]] = {name: [] for name, _ in FLOORS}
    for round_ in range(rounds):
        progress(f"before/now: import to the first result, round {round_ + 1} of {rounds}")
        for name, what in _alternating({**trees, **dict(FLOORS)}, round_):
            if name in floors:
                floors[name].append(floor_once(what))
                continue
            inside, process, cpu = import_once(what)
            tree_samples = samples.setdefault(name, {})
            tree_samples.setdefault("import", []).append(inside)
            tree_samples.setdefault("import process", []).append(process)
            tree_samples.setdefault("import process cpu", []).append(cpu)
    return floors


def measure(trees: dict[str, Path], rounds: int = 9, points=SWEEP_POINTS, import_rounds: int = IMPORT_ROUNDS,
            progress=lambda message: None, reading_rounds: int = 3) -> dict:
    """Median times per tree (``{"run wall", "run cpu", "point cpu", "sweep point cpu", "call cpu", "reading cpu",
    "import", "import process", "import process cpu"}`` in s; ``"point cpu"``: an early-stopped point through
    ``simulate``, each on a fresh system; ``"sweep point cpu"``: the same points as the Figs 4/5 sweeps run them,
    ``studies.sweep.gap_sweep`` serial, on the process's kept systems (:mod:`mbs_models.engine.reuse`)), the files each imported (``"file"``) and whether the trees gave the
    same values (``"same values"``).  ``"call cpu"``: CPU per ``simulate`` of a 1 ms window (model (ii), standard):
    the fixed cost of a call; ``"reading cpu"``: the engine's runs of the :data:`COLLAPSING_READING` reading of the
    convention study (its cases fail on a collapsed step), in the first ``reading_rounds`` rounds.  ``"floor"``: the
    median process wall time (s) of each of :data:`FLOORS`, measured in the import rounds."""
    samples: dict[str, dict[str, list[float]]] = {name: {} for name in trees}
    values: dict[str, list] = {name: [] for name in trees}
    workers = {name: Worker(tree) for name, tree in trees.items()}
    try:
        for worker in workers.values():  # warm-up: first calls, caches, symbolic user functions
            worker.ask(what="run")
            worker.ask(what="points", points=[list(p) for p in points[:2]])
            worker.ask(what="sweep", points=[list(p) for p in points])
        for round_ in range(rounds):
            progress(f"before/now: run and sweep points, round {round_ + 1} of {rounds}")
            for name, worker in _alternating(workers, round_):
                run = worker.ask(what="run")
                sweep = worker.ask(what="points", points=[list(p) for p in points])
                call = worker.ask(what="call", calls=FIXED_COST_CALLS)
                samples[name].setdefault("run wall", []).append(run["wall"])
                samples[name].setdefault("run cpu", []).append(run["cpu"])
                samples[name].setdefault("point cpu", []).append(sweep["cpu"])
                samples[name].setdefault("sweep point cpu", []).append(
                    worker.ask(what="sweep", points=[list(p) for p in points])["cpu"])
                samples[name].setdefault("call cpu", []).append(call["cpu"])
                if round_ < reading_rounds:
                    samples[name].setdefault("reading cpu", []).append(
                        worker.ask(what="reading", label=COLLAPSING_READING)["cpu"])
                if round_ == 0:
                    values[name] = [run["values"], sweep["values"]]
    finally:
        for worker in workers.values():
            worker.close()
    floors = import_samples(trees, samples, import_rounds, progress)
    out = {name: {key: statistics.median(v) for key, v in s.items()} for name, s in samples.items()}
    out["floor"] = {name: statistics.median(v) for name, v in floors.items()}
    for name in trees:
        out[name]["file"] = workers[name].file
        out[name]["values"] = values[name]  # [[displacement m, steps] of the run, [displacement m per point]]
    first = next(iter(values.values()))
    out["same values"] = all(v == first for v in values.values())
    return out
