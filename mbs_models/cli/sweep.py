"""``recoil sweep`` (a grid over dotted scene keys into a CSV/Parquet table) and ``--set KEY=VALUE``.

    recoil sweep model_i --param absorber.mass=100,500,1000 --param contact.gap=0:0.12:13 --out gaps.csv

Bad keys, specs, values and paths exit 2 with one line naming them, before anything is written, and so does
a grid of more than 10^6 points without ``--large``, a file another sweep is writing (it is locked) or
one with rows but no ``FILE.sweep.json``; a failing point is a row of the table (``status``, ``error``:
whatever it raised, or a worker process that died on it) and the sweep goes on; running the same command
again resumes (only the points not yet in the file run; rows the file holds damaged are named in one line
and run again). A disk that fills up stops the sweep with one line and exit 1, every row written kept. On a
Dask cluster (``--scheduler``) a malformed address exits 2; an address that does not answer, a scheduler
lost mid-sweep or no worker for ``--worker-timeout`` seconds exits 1 with one line saying how many rows the
file keeps (the same command resumes). Before the points run, one line on stderr says how many there are and
about how long they take (measured on a few points spread over the grid: an estimate). The table stays in
its file: memory does not
grow with the grid. ``--set KEY=VALUE`` (``recoil run``, ``recoil validate``) changes fields of the scene
for one run, with the same keys.
"""

from __future__ import annotations

import json
import sys
import time

from ..errors import SceneError
from ..studies.grid import MAX_POINTS

#: What the accuracy presets mean (mbs_models.engine.accuracy.ACCURACY_PRESETS: the worst relative error of
#: the max barrel displacement stated there, and the time relative to draft).
ACCURACY_HELP = ("solver accuracy (default: standard): draft = fast, for plots and exploration (max barrel "
                 "displacement within 1e-4); standard = results (1e-7, ~1.3x draft's time); reference = "
                 "validation (1e-9, ~2.9x)")

#: run_sweep's argument names -> the options that give them.
_OPTIONS = {"out": "--out", "scheduler": "--scheduler", "workers": "--workers", "end_time": "--end-time",
            "accuracy": "--accuracy", "params": "--param", "worker_timeout": "--worker-timeout"}


def add_set_argument(parser) -> None:
    """``--set KEY=VALUE`` (repeatable) on a subcommand that takes a scene."""
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="change a field of the scene, e.g. --set absorber.mass=500 --set contact.gap=0.01 "
                             "(dotted keys as in the TOML file; absorber.N.* for one of several absorbers)")


def apply_sets(scene, assignments):
    """``scene`` with every ``KEY=VALUE`` of ``assignments`` applied (values read as TOML); its name says what
    was changed (``model (i), m = 1000 kg, gap 0 mm, with absorber.mass=500``) unless ``name`` is set."""
    from ..scene.overrides import apply_overrides, parse_assignment, parse_value

    overrides, texts = {}, []
    for text in assignments or ():
        key, value = parse_assignment(text, "--set")
        if key in overrides:
            raise SceneError(key, "given twice with --set")
        overrides[key] = parse_value(value, key)
        texts.append(f"{key}={value}")
    if overrides and "name" not in overrides:
        overrides["name"] = f"{scene.name}, with {', '.join(texts)}"
    return apply_overrides(scene, overrides)


def add_sweep_parser(sub) -> None:
    """Register ``recoil sweep`` on the subcommands ``sub``."""
    sweep = sub.add_parser("sweep", help="simulate a scene over a grid of parameter values into a CSV/Parquet "
                                         "table (resumable; local processes or a Dask cluster)")
    sweep.add_argument("scene", help="scene TOML file, or the name of a shipped scene (model_i, model_ii, ...: "
                                         "'recoil scenes' lists them)")
    sweep.add_argument("--param", action="append", default=[], metavar="KEY=SPEC", required=True,
                       help="a dotted scene key and its values: a list 100,500,1000 or a range START:STOP:COUNT "
                            "(both ends included); repeat for a grid, e.g. --param absorber.mass=100,500 "
                            "--param contact.gap=0:0.12:13")
    sweep.add_argument("--out", required=True, metavar="FILE",
                       help="the table: .csv, or .parquet (needs pyarrow); an existing file of the same sweep "
                            "is resumed (missing directories are created)")
    sweep.add_argument("--workers", type=int, default=None, metavar="N",
                       help="local worker processes (default: all CPUs)")
    sweep.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="run on a Dask cluster: the scheduler's tcp://HOST:PORT (needs the cluster extra)")
    add_worker_timeout_argument(sweep)
    sweep.add_argument("--accuracy", default="standard", choices=("draft", "standard", "reference"),
                       help=ACCURACY_HELP)
    sweep.add_argument("--end-time", type=float, default=10.0, help="simulated time in s (default 10)")
    sweep.add_argument("--large", action="store_true",
                       help=f"run a grid of more than {MAX_POINTS:,} points (refused without it: hours to days of "
                            "CPU and a table of gigabytes are rarely meant)")
    sweep.add_argument("--json", action="store_true", help="print the summary as JSON (no progress bar)")
    sweep.set_defaults(handler=run_command)


def add_worker_timeout_argument(parser) -> None:
    """``--worker-timeout SECONDS`` (with ``--scheduler``)."""
    parser.add_argument("--worker-timeout", type=float, default=None, metavar="SECONDS",
                        help="with --scheduler: stop (exit 1) once the cluster has had no worker for this long "
                             "(default 60; inf: wait for ever); a line on stderr says it is waiting")


def run_command(args) -> int:
    """The ``recoil sweep`` handler: exit 0 once every point has a row (failed points included)."""
    from ..scene.overrides import parse_assignment
    from ..studies.grid import GridTooLarge
    from ..studies.sweep import run_sweep
    from ..studies.sweep_table import SweepWriteError
    from . import EXIT_FAILED, EXIT_OK, _resolve_scene

    scene = _resolve_scene(args.scene)
    params = {}
    for text in args.param:
        key, spec = parse_assignment(text, "--param", "KEY=SPEC (e.g. contact.gap=0:0.12:13 or absorber.mass=100,500)")
        if key in params:
            raise SceneError(key, "given twice with --param")
        params[key] = spec
    start = time.perf_counter()
    try:
        summary = run_sweep(scene, params, end_time=args.end_time, accuracy=args.accuracy, workers=args.workers,
                            scheduler=args.scheduler, out=args.out, progress=not args.json, large=args.large,
                            table=False, announce=lambda line: print(line, file=sys.stderr, flush=True),
                            worker_timeout=args.worker_timeout)
    except GridTooLarge as exc:
        raise exc.with_flag("--large", "--large") from None
    except SceneError as exc:
        raise SceneError(_OPTIONS.get(exc.key, exc.key), exc.message) from None
    except SweepWriteError as exc:   # a full disk: the rows written are kept, and resume
        print(f"recoil: error: {exc}", file=sys.stderr)
        return EXIT_FAILED
    except KeyboardInterrupt:
        print(f"recoil sweep: interrupted; the finished points are in {args.out}: run the same command again "
              "to resume", file=sys.stderr)
        raise
    failures = summary.pop("failures")
    summary["wall_time"] = time.perf_counter() - start
    if args.json:   # the first SUMMARY_FAILURES failed points (all of them are in the table)
        summary["failures"] = failures
        print(json.dumps(summary, indent=2, allow_nan=False, default=float))
    else:
        print(f"{summary['points']} points: {summary['run']} run, {summary['resumed']} resumed from the file, "
              f"{summary['failed']} failed; table in {summary['out']} ({summary['wall_time']:.1f} s)")
        for row in failures[:5]:
            where = ", ".join(f"{key}={row[key]}" for key in params)
            print(f"  failed at {where}: {row['status']}: {row['error']}")
        if summary["failed"] > 5:
            print(f"  ... and {summary['failed'] - 5} more (column 'error' of the table)")
    return EXIT_OK
