"""The ``recoil`` command line.

Exit codes: 0 success; 1 a simulation or check failed, or the Dask cluster of a run did; 2 bad input (one
line on stderr naming the problem, never a traceback for user mistakes).  A
:class:`~mbs_models.errors.UnitWarning` (an implausible magnitude, a contact that can never close:
:mod:`mbs_models.engine.unit_slips`), an ``AccuracyWarning`` or any other of the project's warnings is one line on
stderr, ``recoil: warning: ...``, and the command goes on.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings
from pathlib import Path
from typing import Sequence

from .. import __version__
from ..errors import ClusterError, SceneError, SimulationError, UnitWarning
from ..scene import load_scene
from . import run
from .plugins import add_plugin_argument, load_plugins
from .sweep import ACCURACY_HELP, add_set_argument, add_sweep_parser, apply_sets

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2
_ARGUMENT_NAMES = {"end_time": "--end-time", "accuracy": "--accuracy", "impact_threshold": "--impact-threshold",
                   "user_functions": "--user-functions"}


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit code 2."""

    def error(self, message: str):
        raise SceneError("", f"{message} (see '{self.prog} --help')")


def _progress():
    """Stage lines and tqdm bars on stderr, quiet when stderr is not a terminal."""
    from .progress import ProgressBars
    return ProgressBars(sys.stderr)


def _resolve_scene(path: str):
    """A scene file path, or the name of a shipped scene (``simplified``, ``model_i``, ``model_ii``: see
    ``recoil scenes``); a name that is neither gets a "did you mean" over the shipped names."""
    from ..scenes import closest_scene, list_scenes, scene_path, unknown_scene

    candidate = Path(path)
    if candidate.exists() or "/" in path or os.sep in path or candidate.suffix not in ("", ".toml"):
        return load_scene(candidate)  # a path: its own errors (not found, malformed, ...)
    if candidate.suffix == "":
        if path in list_scenes():
            return load_scene(scene_path(path))
        raise SceneError("", f"no scene file {path!r} and {unknown_scene(path)}")
    close = closest_scene(candidate.stem)  # model_ii.toml or model_iii.toml, not in this directory
    if close is not None:
        raise SceneError("", f"scene file not found: {path}; did you mean the shipped scene {close!r} (a name, "
                             f"without .toml)?")
    return load_scene(candidate)


def _cmd_scenes(args) -> int:
    from ..scenes import describe_scenes, scene_path

    rows = [[name, str(scene_path(name)), description] if args.path else [name, description]
            for name, description in describe_scenes()]
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]) - 1)]
    for row in rows:
        print("  ".join([f"{cell:{width}s}" for cell, width in zip(row, widths)] + row[-1:]))
    return EXIT_OK


def _cmd_paper(args) -> int:
    from validation.studies.report import ReportOptions, table2_markdown, table2_rows, write_report

    if args.workers is not None and args.workers < 1:
        raise SceneError("--workers", f"must be >= 1, got {args.workers}")
    if args.quick and args.reproduce_only:
        raise SceneError("--reproduce-only", "cannot be combined with --quick")
    from ..outputs import check_output_dir
    check_output_dir(args.out)  # bad --out: exit 2 before any work; created when the report is written
    if args.quick:
        options = ReportOptions.reduced(workers=args.workers)
    elif args.reproduce_only:
        options = ReportOptions.reproduction(workers=args.workers)
    else:
        options = ReportOptions(workers=args.workers)
    data = write_report(args.out, options, progress=_progress())
    print(table2_markdown(table2_rows(data)))
    failed = [c["scene"] for c in data["comparisons"] if not c["passed"]]
    print(f"wrote report.html, results.json, table2.md/json and the figures to {args.out} "
          f"in {data['timings']['total']:.1f} s")
    if failed:
        print(f"engine vs reference FAILED for: {', '.join(failed)}", file=sys.stderr)
        return EXIT_FAILED
    return EXIT_OK


def _cmd_validate(args) -> int:
    from validation.studies.compare import compare

    scene = apply_sets(_resolve_scene(args.scene), args.set)
    comparison = compare(scene, args.end_time, args.accuracy, impact_threshold=args.impact_threshold)
    if args.json:
        print(json.dumps(comparison.to_dict(), indent=2, allow_nan=False))
    else:
        print(comparison.table())
    return EXIT_OK if comparison.passed else EXIT_FAILED


def _cmd_precision(args) -> int:
    from validation.studies.precision import preset_study, run_study

    from ..outputs import check_output_dir

    scene = _resolve_scene(args.scene)
    if not 0.0 < args.end_time <= 1e4:
        raise SceneError("end_time", f"must be a number of seconds in (0, 10000], got {args.end_time!r}")
    if args.repeats < 1:
        raise SceneError("--repeats", f"must be a whole number >= 1, got {args.repeats}")
    out = check_output_dir(args.out)  # bad --out: exit 2 before any work; the study's write() creates it
    start = time.perf_counter()
    progress = _progress()
    if scene.carriage is not None:  # the planar model: its own study against the planar reference
        from validation.studies.carriage_precision import carriage_study

        if args.presets:
            raise SceneError("--presets", "runs the presets on the 19 paper cases: not with a carriage scene")
        study = carriage_study(scene, end_time=args.end_time, repeats=args.repeats, quick=args.quick,
                               progress=progress)
        study.write(out)
        print(study.summary_markdown())
        print(f"wrote carriage_precision.md, .csv, .json and work_precision_carriage.png to {out} in "
              f"{time.perf_counter() - start:.1f} s")
        return EXIT_OK
    study = run_study(scene, end_time=args.end_time, repeats=args.repeats, quick=args.quick, progress=progress)
    study.write(out)
    print(study.summary_markdown().split("\n## All settings")[0])
    if args.presets:
        progress("accuracy presets on the 19 paper cases")
        presets = preset_study(end_time=args.end_time, repeats=args.repeats, progress=progress)
        presets.write(out)
        print(presets.table_markdown())
    print(f"wrote precision.md, precision.csv, precision.json, the work-precision figures"
          f"{' and presets.md/json' if args.presets else ''} to {out} in {time.perf_counter() - start:.1f} s")
    return EXIT_OK


def _cmd_contact_laws(args) -> int:
    from validation.studies.contact_laws import run_study, write

    from ..outputs import check_output_dir

    out = check_output_dir(args.out)  # bad --out: exit 2 before any work; write() creates it
    start = time.perf_counter()
    study = run_study(args.accuracy)
    write(study, out)
    if args.json:
        print(json.dumps(study.to_dict(), indent=2, allow_nan=False))
    else:
        print(study.markdown())
        print(f"wrote contact_laws.png, contact_laws.json and contact_laws.md to {out} in "
              f"{time.perf_counter() - start:.1f} s (worst engine - closed form: {study.worst_error:.1e})")
    return EXIT_OK


def _design_stable(scene, args) -> int:
    """``recoil design-brake --stable``: :func:`~mbs_models.studies.stable_brake.design_stable_brake`."""
    from ..outputs import atomic_write_json, atomic_write_text, check_output_dir, prepare_output_dir
    from ..scene.io import scene_to_toml
    from ..scene.overrides import parse_spec
    from ..studies.stable_brake import design_stable_brake

    elevations = parse_spec(args.elevations, "--elevations")
    bands = parse_spec(args.bands, "--bands") if args.bands.strip() else []
    for key, values in (("--elevations", elevations), ("--bands", bands)):
        if any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in values):
            raise SceneError(key, f"must be numbers of degrees, got {values!r}")
    if not 0.0 < args.end_time <= 1e4:
        raise SceneError("--end-time", f"must be a number of seconds in (0, 10000], got {args.end_time!r}")
    check_output_dir(args.out)
    start = time.perf_counter()
    design = design_stable_brake(scene, elevations, bands, margin=args.margin, max_recoil=args.max_recoil,
                                 accuracy=args.accuracy, end_time=args.end_time, progress=_progress())
    out = prepare_output_dir(args.out)
    atomic_write_text(out / "designed.toml", scene_to_toml(design.scene))
    data = design.to_dict()
    atomic_write_json(out / "stable_design.json", data)
    if args.json:
        print(json.dumps(data, indent=2, allow_nan=False))
        return EXIT_OK
    for band in design.bands:
        print(f"band up to {band.up_to:g} deg ({', '.join(f'{e:g}' for e in band.elevations)}): recoil "
              f"{band.achieved * 1e3:.1f} mm (constant resistance, designed for {band.design_length * 1e3:.1f} mm)"
              + (f"; counter-recoil orifice {band.counter_recoil_orifice_area:.3g} m^2"
                 if band.counter_recoil_orifice_area is not None else ""))
        for note in band.notes:
            print(f"    {note}")
    for elevation, reason in design.refused.items():
        print(f"  {elevation:5g} deg: left out, the scene is invalid there ({reason})")
    for check in design.checks:
        verdict = "stays down" if check.lift_off_time is None else f"LIFTS at {check.lift_off_time:.3g} s"
        print(f"  {check.elevation:5g} deg: recoil {check.recoil * 1e3:6.1f} mm, peak resistance "
              f"{check.peak_resistance / 1e3:7.1f} kN, stability margin {check.stability_margin:.3f}, {verdict}")
    print(("every support stays on the ground at every elevation" if design.stable else
           "a support still leaves the ground: see above") + f"; wrote designed.toml and stable_design.json to {out} "
          f"in {time.perf_counter() - start:.1f} s")
    return EXIT_OK


def _cmd_design_brake(args) -> int:
    from ..outputs import atomic_write_json, atomic_write_text, check_output_dir, prepare_output_dir
    from ..results.plotting import save_figure
    from ..scene.io import scene_to_toml
    from ..studies.brake_design import compare_with_linear_damper, plot_comparison
    from ..studies.recoil_peaks import peak_forces

    scene = _resolve_scene(args.scene)
    if args.stable:
        return _design_stable(scene, args)
    if args.recoil_length is None or not args.recoil_length > 0:
        raise SceneError("--recoil-length", f"must be a length > 0 m, got {args.recoil_length!r}")
    if not 0.0 < args.end_time <= 1e4:
        raise SceneError("--end-time", f"must be a number of seconds in (0, 10000], got {args.end_time!r}")
    check_output_dir(args.out)  # bad --out: exit 2 before any work
    start = time.perf_counter()
    try:  # a length it cannot design: exit 2 (exit 1 if it does not converge), nothing written
        comparison = compare_with_linear_damper(scene, args.recoil_length, args.accuracy, args.end_time,
                                                tolerance=args.tolerance)
    except SceneError as exc:
        if exc.key in ("recoil_length", "tolerance"):
            raise SceneError(f"--{exc.key.replace('_', '-')}", exc.message) from None
        raise
    out = prepare_output_dir(args.out)
    atomic_write_text(out / "designed.toml", scene_to_toml(comparison.design.scene))
    save_figure(plot_comparison(comparison), out / "design_brake.png")
    data = comparison.to_dict()
    atomic_write_json(out / "design_brake.json", data)
    if args.json:
        print(json.dumps(data, indent=2, allow_nan=False))
    else:
        length, lin = comparison.length, data["linear_damper"]
        runs = len(length.iterations)
        print(f"recoil length {length.recoil_length:.5f} m for {length.asked:g} m asked (tolerance "
              f"{1e3 * length.tolerance:.3g} mm; {runs} simulation{'s' if runs > 1 else ''}: the table is the "
              f"constant-resistance design for {length.design_length:.5g} m)")
        print(f"constant resistance R = {data['constant_resistance'] / 1e3:.3f} kN "
              f"(flat to {100 * data['resistance_flatness_over_90_percent']:.2f} % over 90 % of the stroke)")
        for title, result in (("designed brake", comparison.designed), ("linear damper", comparison.linear)):
            print(f"  {title}: recoil length {result.max_barrel_displacement:.5f} m"
                  + ("" if result is comparison.designed else
                     f", c = {lin['recoil']:.0f} / {lin['counter_recoil']:.0f} N s/m"))
            for peak in peak_forces(result).values():
                print(f"    {peak.text()}")
        print(f"wrote designed.toml, design_brake.png, design_brake.json to {out} in "
              f"{time.perf_counter() - start:.1f} s")
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="recoil", description="Recoil mechanisms with impact absorbers (Exudyn).")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    add_plugin_argument(parser)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    run.add_parser(sub, ACCURACY_HELP)

    scenes = sub.add_parser("scenes", help="list the shipped scenes (names for run, validate, sweep, ...) with "
                                           "a one-line description each")
    scenes.add_argument("--path", action="store_true", help="also print each scene's file path (copy it to edit)")
    scenes.set_defaults(handler=_cmd_scenes)

    validate = sub.add_parser("validate", help="engine vs the independent scipy reference for one scene "
                                               "(exit code 1 if a tolerance is exceeded)")
    validate.add_argument("scene", help="scene TOML file, or the name of a shipped scene (model_i, model_ii, two_absorbers, ...: 'recoil scenes' lists them)")
    validate.add_argument("--end-time", type=float, default=10.0, help="simulated time in s (default 10)")
    validate.add_argument("--accuracy", default="standard", choices=("draft", "standard", "reference"),
                          help=ACCURACY_HELP)
    validate.add_argument("--impact-threshold", type=float, default=1000.0,
                          help=run.IMPACT_THRESHOLD_HELP)
    validate.add_argument("--json", action="store_true", help="print the comparison as JSON")
    add_set_argument(validate)
    validate.set_defaults(handler=_cmd_validate)

    paper = sub.add_parser("paper", help="reproduce the paper: Table 2 and the figures")
    paper.add_argument("--out", default="out", help="output directory (created; default ./out)")
    paper.add_argument("--quick", action="store_true",
                       help="a reduced but complete report (coarse gap sweeps, two readings of the paper)")
    paper.add_argument("--reproduce-only", action="store_true",
                       help="the paper's results only: Table 2 (with the reference), the full gap sweeps, Figs 4-11 "
                            "and the report, without the convention study, the calibration and the engine-vs-"
                            "reference cases at gaps 40/80 mm (measured ~4x faster than the full report)")
    paper.add_argument("--workers", type=int, default=None, help="worker processes (default: all CPUs)")
    paper.set_defaults(handler=_cmd_paper)

    precision = sub.add_parser("precision", help="work-precision study: error vs time of every solver and setting")
    precision.add_argument("scene", nargs="?", default="model_ii",
                           help="scene TOML file or shipped scene (default model_ii: m = 1000 kg, gap 0)")
    precision.add_argument("--out", default="precision", help="output directory (created; default ./precision)")
    precision.add_argument("--quick", action="store_true", help="a tiny grid (seconds instead of minutes)")
    precision.add_argument("--end-time", type=float, default=10.0, help="simulated time in s (default 10)")
    precision.add_argument("--repeats", type=int, default=3, help="timed runs per setting, median taken (default 3)")
    precision.add_argument("--presets", action="store_true",
                           help="also measure the accuracy presets on the 19 paper cases (presets.md/json)")
    precision.set_defaults(handler=_cmd_precision)

    laws = sub.add_parser("contact-laws", help="the contact-law family on a free impact: restitution achieved vs "
                                               "requested (closed form and engine) and force-penetration loops")
    laws.add_argument("--out", default="contact-laws", help="output directory (created; default ./contact-laws)")
    laws.add_argument("--accuracy", default="standard", choices=("draft", "standard", "reference"),
                      help=ACCURACY_HELP)
    laws.add_argument("--json", action="store_true", help="print the study as JSON")
    laws.set_defaults(handler=_cmd_contact_laws)

    design = sub.add_parser("design-brake", help="design the recoil brake's orifice for a constant resistance over "
                                                  "a recoil length, and compare it with a linear damper")
    design.add_argument("scene", help="scene TOML file or shipped scene (a barrel without absorbers, e.g. simplified)")
    design.add_argument("--recoil-length", type=float, default=None, metavar="L",
                        help="recoil length in m (required, but with --stable)")
    design.add_argument("--stable", action="store_true",
                        help="design a variable-recoil brake that keeps a carriage scene on the ground at every "
                             "elevation of --elevations: per band of --bands, the constant-resistance orifice for the "
                             "shortest stable recoil (at most --max-recoil) and a counter-recoil orifice narrowed "
                             "until the return keeps 1 - margin of every support's load")
    design.add_argument("--elevations", default="0:60:5", help="with --stable: elevations in degrees, "
                                                               "START:STOP:COUNT or a list (default 0:60:5)")
    design.add_argument("--bands", default="", help="with --stable: band edges (up_to) in degrees, e.g. 45 or "
                                                    "20,45 (default: one band)")
    design.add_argument("--margin", type=float, default=0.8,
                        help="with --stable: the fraction of the closed form's limit the resistance may reach "
                             "(default 0.8)")
    design.add_argument("--max-recoil", type=float, default=1.0, help="with --stable: the longest recoil in m the "
                                                                       "gun's clearance allows (default 1.0)")
    design.add_argument("--out", default="design-brake", help="output directory (created; default ./design-brake)")
    design.add_argument("--tolerance", type=float, default=None, metavar="TOL",
                        help="how close (m) the simulated recoil length must come to L: the design length is "
                             "iterated on the simulation until it does (default: 0.1 %% of L, at least 0.1 mm)")
    design.add_argument("--end-time", type=float, default=3.0,
                        help="simulated time in s of every run (default 3): the barrel must turn and return")
    design.add_argument("--accuracy", default="standard", choices=("draft", "standard", "reference"),
                        help=ACCURACY_HELP)
    design.add_argument("--json", action="store_true", help="print the comparison as JSON")
    design.set_defaults(handler=_cmd_design_brake)
    add_sweep_parser(sub)

    from .plot_sweep import add_parser as add_plot_sweep
    from .optimise import add_parser as add_optimise
    from .stability import add_parser as add_stability
    add_plot_sweep(sub)
    add_optimise(sub)
    add_stability(sub, ACCURACY_HELP)
    return parser


def _ours(category) -> bool:
    """Is ``category`` one of the project's warnings (UnitWarning, AccuracyWarning, UnreadableRowsWarning...)?"""
    return category.__module__.split(".")[0] in ("mbs_models", "validation")


def _one_line_warnings(show_other):
    """A ``warnings.showwarning`` that prints the project's own warnings (a :class:`UnitWarning`, an
    ``AccuracyWarning``, unreadable sweep rows) as one line on stderr (``recoil: warning: KEY = VALUE ...``) and
    passes every other warning to ``show_other``."""
    def show(message, category, filename, lineno, file=None, line=None):
        if _ours(category):
            text = " ".join(str(message).split())
            print(f"recoil: warning: {text}", file=sys.stderr, flush=True)
        else:
            show_other(message, category, filename, lineno, file, line)
    return show


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``recoil`` console script; returns the exit code."""
    with warnings.catch_warnings():
        warnings.simplefilter("default", UnitWarning)  # each distinct slip once, whatever the user's filters
        warnings.showwarning = _one_line_warnings(warnings.showwarning)
        return _main(argv)


def _main(argv: Sequence[str] | None) -> int:
    try:
        args = build_parser().parse_args(argv)
        load_plugins(args.plugin)
        return args.handler(args)
    except SceneError as exc:
        key = _ARGUMENT_NAMES.get(exc.key, exc.key)
        message = f"{key}: {exc.message}" if key else exc.message
        print(f"recoil: error: {message}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except SimulationError as exc:
        print(f"recoil: simulation failed: {exc}", file=sys.stderr)
        return EXIT_FAILED
    except ClusterError as exc:   # the Dask cluster failed the run (unreachable, lost, no workers)
        print(f"recoil: error: {exc}", file=sys.stderr)
        return EXIT_FAILED
    except BrokenPipeError:  # piped into a program that stopped reading (head): the run itself succeeded
        try:  # Python's documented recipe: the interpreter's final flush goes to /dev/null, not a traceback
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError, AttributeError):
            pass
        return EXIT_OK
    except KeyboardInterrupt:
        print("recoil: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
