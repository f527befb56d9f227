"""``recoil optimise SCENE --vary KEY=LOW:HIGH [--vary ...] --minimise METRIC [--constraint METRIC<=VALUE ...]
[--out DIR]``: the best design within the bounds, its history (CSV) and a plot.

Every argument is checked before the first simulation and before DIR is created (one line, exit 2).  Exit
code 1 when no feasible design was found (the least violating one is still written and reported), or when
the Dask cluster of ``--scheduler`` fails the run (unreachable, lost, no worker for ``--worker-timeout`` s).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from ..errors import SceneError
from .sweep import ACCURACY_HELP, add_worker_timeout_argument


def _progress(message: str) -> None:
    print(f"[recoil] {message}", file=sys.stderr, flush=True)


def _cmd_optimise(args) -> int:
    from . import _resolve_scene
    from ..outputs import check_output_dir
    from ..studies.backends import check_backend
    from ..studies.optimise import check_problem, optimise, parse_bound

    scene = _resolve_scene(args.scene)
    if not args.vary:
        raise SceneError("--vary", "give at least one parameter to vary: --vary KEY=LOW:HIGH")
    bounds = {}
    for text in args.vary:
        key, pair = parse_bound(text)
        if key in bounds:
            raise SceneError("--vary", f"{key} is given twice")
        bounds[key] = pair
    options = dict(end_time=args.end_time, accuracy=args.accuracy, seed=args.seed, popsize=args.popsize,
                   maxiter=args.maxiter, tol=args.tol)
    try:
        check_problem(scene, bounds, args.minimise, args.constraint or (), **options)
    except SceneError as exc:
        names = {"minimise": "--minimise", "constraints": "--constraint", "popsize": "--popsize",
                 "maxiter": "--maxiter", "seed": "--seed", "tol": "--tol", "bounds": "--vary"}
        if exc.key in names:
            raise SceneError(names[exc.key], exc.message) from None
        raise
    if args.workers is not None and args.scheduler is not None:
        raise SceneError("--workers", "give either --workers (a local pool) or --scheduler (a Dask cluster)")
    if args.workers is not None and args.workers < 1:
        raise SceneError("--workers", f"must be >= 1, got {args.workers}")
    try:
        check_backend(args.workers, args.scheduler, args.worker_timeout)
    except SceneError as exc:
        raise SceneError(f"--{exc.key.replace('_', '-')}", exc.message) from None
    out = check_output_dir(Path(args.out))  # bad --out: exit 2 before any simulation; created by write()
    result = optimise(scene, bounds, args.minimise, args.constraint or (), workers=args.workers,
                      scheduler=args.scheduler, worker_timeout=args.worker_timeout, stop_when_final=not args.full_run,
                      progress=_progress, **options)
    data = result.write(out)
    if args.json:
        print(json.dumps(data, indent=2, allow_nan=False))
    else:
        print(result.summary())
        print(f"wrote optimum.json, history.csv, convergence.csv and optimise.png to {out}")
    return 0 if result.feasible else 1


def add_parser(sub) -> None:
    """Register the ``optimise`` subcommand on the ``recoil`` parser's subparsers."""
    opt = sub.add_parser("optimise", help="the design within bounds that minimises a metric, subject to "
                                          "constraints on metrics (differential evolution)")
    opt.add_argument("scene", help="scene TOML file or shipped scene (model_i, model_ii, ...: 'recoil scenes' lists them)")
    opt.add_argument("--vary", action="append", metavar="KEY=LOW:HIGH",
                     help="a dotted scene key and its bounds in SI units, e.g. contact.gap=0:0.12 (repeatable)")
    opt.add_argument("--minimise", "--minimize", required=True, metavar="METRIC",
                     help="metric to minimise, e.g. max_barrel_displacement, peak_support_force")
    opt.add_argument("--constraint", action="append", metavar="METRIC<=VALUE",
                     help="a constraint in SI units, METRIC<=VALUE or METRIC>=VALUE (repeatable)")
    opt.add_argument("--out", default="optimise", help="output directory (created; default ./optimise)")
    opt.add_argument("--end-time", type=float, default=10.0, help="simulated time in s (default 10)")
    opt.add_argument("--accuracy", default="standard", choices=("draft", "standard", "reference"),
                     help=ACCURACY_HELP)
    opt.add_argument("--full-run", action="store_true",
                     help="simulate every point to the end time (default: stop once the metrics are final)")
    opt.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    opt.add_argument("--popsize", type=int, default=10,
                     help="population per varied parameter (default 10)")
    opt.add_argument("--maxiter", type=int, default=30, help="generations at most (default 30)")
    opt.add_argument("--tol", type=float, default=1e-4,
                     help="stop when the population's objective spread is below this fraction of its mean "
                          "(scipy's tol; default 1e-4)")
    opt.add_argument("--workers", type=int, default=None, help="local worker processes (default: all CPUs)")
    opt.add_argument("--scheduler", default=None, metavar="ADDRESS",
                     help="Dask scheduler tcp://HOST:PORT (instead of local processes)")
    add_worker_timeout_argument(opt)
    opt.add_argument("--json", action="store_true", help="print the optimum as JSON")
    opt.set_defaults(handler=_cmd_optimise)
