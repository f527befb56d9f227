"""``recoil run``: simulate one scene, print its metrics, optionally write the plot and the time histories.

The plot and the CSV show the densified histories (:mod:`mbs_models.results.dense`; ``--history-interval S``,
default 1 ms) or, with ``--step-ends``, the solver's step-end samples.

Every output is checked before the solve (exit 2, nothing written, for a figure format other than
png/pdf/svg or a directory that cannot be written or created); a missing directory is created when the file is
written, after the solve (:mod:`mbs_models.outputs`: the rule of every command); unit slips (implausible magnitudes, contacts that can
never close: :mod:`mbs_models.engine.unit_slips`) are warned of by ``simulate`` before it solves, one line
each on stderr.  A run stopped at rest (:mod:`mbs_models.engine.rest`) says so on stderr, in one line.
"""

from __future__ import annotations

import json
import sys

#: What ``--impact-threshold`` means (DESIGN.md, "Outputs every scene gets": which episodes are impacts).
IMPACT_THRESHOLD_HELP = ("a contact episode counts as an impact when its peak force rises by more than this (N) above "
                         "the force at rest it began with (0 unless a preload holds the contact at t = 0; default "
                         "1000)")


def add_parser(sub, accuracy_help: str) -> None:
    """The ``run`` subcommand's arguments."""
    from .sweep import add_set_argument

    run = sub.add_parser("run", help="simulate one scene and print its metrics")
    run.add_argument("scene", help="scene TOML file, or the name of a shipped scene (model_i, model_ii, "
                                   "two_absorbers, ...: 'recoil scenes' lists them)")
    run.add_argument("--end-time", type=float, default=10.0, help="simulated time in s (default 10)")
    run.add_argument("--accuracy", default="standard", choices=("draft", "standard", "reference"),
                     help=accuracy_help)
    run.add_argument("--json", action="store_true", help="print the metrics as one JSON object")
    run.add_argument("--plot", metavar="FILE",
                     help="write the time histories and a zoom on the first impact as a figure; the extension "
                          "names the format: .png, .pdf or .svg (missing directories are created)")
    run.add_argument("--csv", metavar="FILE",
                     help="write the time histories (time, positions, velocities, accelerations, every contact "
                          "force, the force on the mount, energies) as CSV, units in the header (missing "
                          "directories are created)")
    samples = run.add_mutually_exclusive_group()
    samples.add_argument("--history-interval", type=float, default=None, metavar="S",
                         help="the largest gap (s) between the times --plot draws and --csv writes: the solver's "
                              "step-end samples and, in every longer step, times this far apart on the Hermite "
                              "interpolant of the samples and the elements' laws (from 1e-05 to 1; default 0.001, "
                              "finer for an end time under 2 s: end time / 2000, coarser beyond 1000 s: end time "
                              "/ 1e6). The metrics do not depend on it")
    samples.add_argument("--step-ends", action="store_true",
                         help="draw and write the solver's step-end samples alone (up to the preset's maximum "
                              "step apart), not the densified histories")
    run.add_argument("--user-functions", choices=("symbolic", "python"), default=None,
                     help="user-function backend (default symbolic; python is slower, for debugging)")
    run.add_argument("--impact-threshold", type=float, default=1000.0,
                     help=IMPACT_THRESHOLD_HELP)
    run.add_argument("--no-stop-at-rest", dest="stop_at_rest", action="store_false",
                     help="integrate to the end time even where the scene is proven at rest (by default a run "
                          "longer than 100 s stops there and holds the rest state)")
    add_set_argument(run)
    run.set_defaults(handler=command)


def history_interval(args) -> float | None:
    """The largest gap (s) between the output times of ``--plot`` and ``--csv`` (None: the default); SceneError
    naming ``--history-interval`` outside its range (before the solve)."""
    from ..results.dense import check_interval

    return None if args.history_interval is None else check_interval(args.history_interval, key="--history-interval")


def command(args) -> int:
    from ..engine.simulation import simulate
    from ..outputs import check_output_file, prepare_output_file
    from . import EXIT_OK, _resolve_scene
    from .sweep import apply_sets

    scene = apply_sets(_resolve_scene(args.scene), args.set)
    interval = history_interval(args)
    if args.plot:
        from ..results.plotting import figure_format
        figure_format(args.plot, key="--plot")
        check_output_file(args.plot, key="--plot")
    if args.csv:
        check_output_file(args.csv, key="--csv")
    result = simulate(scene, args.end_time, args.accuracy, user_functions=args.user_functions,
                      impact_threshold=args.impact_threshold, stop_at_rest=args.stop_at_rest)
    if result.rest_note() is not None:
        print(f"recoil: {result.rest_note()}", file=sys.stderr, flush=True)
    if args.plot:
        from ..results.plotting import plot_result, save_figure
        prepare_output_file(args.plot, key="--plot")
        save_figure(plot_result(result, interval=interval, step_ends=args.step_ends), args.plot)
    if args.csv:
        from ..results.histories import write_histories_csv
        prepare_output_file(args.csv, key="--csv")
        write_histories_csv(result, args.csv, interval, args.step_ends)
    if args.json:
        print(json.dumps(result.metrics(), indent=2, allow_nan=False))
    else:
        print(result.summary())
        if args.plot:
            print(f"  plot                     {args.plot}")
        if args.csv:
            print(f"  time histories (CSV)     {args.csv}")
    return EXIT_OK
