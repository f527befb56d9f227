"""Throughput parts of ``scripts/bench.py`` (issue #11): the Figs 4/5 sweep and the whole-paper job, each
measured against the code *before* issue #11 (commit :data:`BASELINE_REV`, checked out into a temporary
git worktree) in the same run, in fresh interpreters.

Every variant runs in its own Python process (``subprocess``) so that imports, forks and pools are paid
as a user pays them; the baseline's process imports the package from the temporary worktree
(``PYTHONPATH``).  Without git history (a tarball) the baseline is skipped and said so.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: main before issue #11's throughput work (post-processing, model reuse, the paper job, the early stop)
BASELINE_REV = "c952992"
MASSES = (100.0, 500.0, 1000.0)
GAP_COUNT = 121  # 0 .. 120 mm in 1 mm steps: with 2 models x 3 masses, the report's 726 points

#: Runs the Figs 4/5 grid with the early stop, as the report does, and prints one JSON line.  Works on the
#: baseline (``run_sweep(scenes, ...)``) and on today's code (``run_scenes``; ``run_sweep`` over dotted keys
#: for a Dask ``scheduler``).
_SWEEP_CODE = r"""
import json, sys, time, warnings
warnings.simplefilter("ignore")
workers, scheduler, gap_count, full = int(sys.argv[1]), sys.argv[2], int(sys.argv[3]), sys.argv[4] == "full"
masses = %r
gaps = [round(i * 0.12 / (gap_count - 1), 6) for i in range(gap_count)]
from mbs_models import model_i, model_ii
early = () if full else ("max_barrel_displacement",)
try:
    from mbs_models.studies.sweep import run_scenes as run
except ImportError:
    from mbs_models.studies.sweep import run_sweep as run
start_wall, start_cpu = time.perf_counter(), time.process_time()
if scheduler == "local-cluster":
    from dask.distributed import Client, LocalCluster
    from mbs_models.studies.sweep import run_sweep
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster, Client(cluster) as client:
        start_wall, start_cpu = time.perf_counter(), time.process_time()
        values = []
        for factory in (model_i, model_ii):
            table = run_sweep(factory(1000.0, 0.0), {"absorber.mass": list(masses), "contact.gap": gaps},
                              scheduler=client, progress=False, stop_when_final=early)
            values += list(table["max_barrel_displacement"])
else:
    scenes = [f(m, g) for f in (model_i, model_ii) for m in masses for g in gaps]
    points = run(scenes, 10.0, "standard", workers=workers, stop_when_final=early)
    values = [p.max_barrel_displacement for p in points]
print(json.dumps({"wall": time.perf_counter() - start_wall, "cpu": time.process_time() - start_cpu,
                  "points": len(values), "values": values}))
""" % (MASSES,)


@contextmanager
def baseline_checkout(rev: str = BASELINE_REV):
    """A temporary git worktree of ``rev`` (its path), or None without git history; removed afterwards."""
    directory = Path(tempfile.mkdtemp(prefix="recoil-baseline-"))
    target = directory / "tree"
    try:
        done = subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(target), rev],
                              capture_output=True, text=True)
        yield target if done.returncode == 0 else None
    finally:
        if target.exists():
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(target)],
                           capture_output=True)
        shutil.rmtree(directory, ignore_errors=True)


def _python(tree: Path, arguments: list[str], cwd: Path | None = None) -> subprocess.CompletedProcess:
    environment = {**os.environ, "PYTHONPATH": str(tree)}
    return subprocess.run([sys.executable, *arguments], capture_output=True, text=True, env=environment,
                          cwd=str(cwd or tree), check=True)


def sweep_once(tree: Path, workers: int, scheduler: str = "local", gap_count: int = GAP_COUNT,
               full: bool = False) -> dict:
    """One Figs 4/5 sweep with the code in ``tree``: {"wall", "cpu" (s, this process only), "points", "values"}.
    ``full``: complete 10 s runs with every metric (as ``recoil sweep`` does by default) instead of the
    report's early stop on the max barrel displacement."""
    out = _python(tree, ["-c", _SWEEP_CODE, str(workers), scheduler, str(gap_count),
                         "full" if full else "early"]).stdout
    return json.loads(out.strip().splitlines()[-1])


def paper_once(tree: Path) -> float:
    """Wall time (s) of a full ``recoil paper`` with the code in ``tree``, output into a temporary directory."""
    with tempfile.TemporaryDirectory(prefix="recoil-paper-") as out:
        start = time.perf_counter()
        _python(tree, ["-m", "mbs_models", "paper", "--out", out])
        return time.perf_counter() - start


def dask_available() -> bool:
    try:
        import dask.distributed  # noqa: F401
    except ImportError:
        return False
    return True
