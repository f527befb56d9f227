"""``recoil stability``: the stability chart of a carriage scene over elevation (:mod:`mbs_models.studies.stability_chart`)."""

from __future__ import annotations

import json
import sys


def add_parser(sub, accuracy_help: str) -> None:
    chart = sub.add_parser("stability", help="the stability chart of a carriage scene: the resistance the carriage "
                                             "allows and the shortest stable recoil at each elevation, and the scene "
                                             "simulated there")
    chart.add_argument("scene", help="scene TOML file with a [carriage], or a shipped scene (towed_howitzer)")
    chart.add_argument("--elevations", default="0:70:15",
                       help="elevations in degrees: START:STOP:COUNT (both ends included) or a list 0,15,30 "
                            "(default 0:70:15)")
    chart.add_argument("--margin", type=float, default=0.8,
                       help="the fraction of the closed form's limit the resistance may reach (default 0.8)")
    chart.add_argument("--end-time", type=float, default=3.0, help="simulated time per elevation in s (default 3)")
    chart.add_argument("--accuracy", default="standard", choices=("draft", "standard", "reference"),
                       help=accuracy_help)
    chart.add_argument("--out", default="stability", help="output directory (created; default ./stability)")
    chart.add_argument("--json", action="store_true", help="print the chart as JSON instead of the summary")
    chart.set_defaults(handler=command)


def command(args) -> int:
    from ..errors import SceneError
    from ..outputs import atomic_write_json, atomic_write_text, check_output_dir, prepare_output_dir
    from ..results.plotting import save_figure
    from ..scene.overrides import parse_spec
    from ..studies.stability_chart import chart_figure, stability_chart, summary_lines
    from . import EXIT_OK, _progress, _resolve_scene

    scene = _resolve_scene(args.scene)
    if scene.carriage is None:
        raise SceneError("scene", "the stability chart needs a scene with a [carriage] table "
                                  "(e.g. the shipped towed_howitzer)")
    elevations = parse_spec(args.elevations, "--elevations")
    if any(isinstance(e, bool) or not isinstance(e, (int, float)) for e in elevations):
        raise SceneError("--elevations", f"must be numbers of degrees, got {args.elevations!r}")
    if not 0.0 < args.end_time <= 1e4:
        raise SceneError("--end-time", f"must be a number of seconds in (0, 10000], got {args.end_time!r}")
    check_output_dir(args.out)  # bad --out: exit 2 before any work; created once the chart is computed
    points = stability_chart(scene, [float(e) for e in elevations], args.margin, end_time=args.end_time,
                             accuracy=args.accuracy, progress=_progress())
    out = prepare_output_dir(args.out)
    rows = [p.to_dict() for p in points]
    header = list(rows[0])
    csv_text = ",".join(header) + "\n" + "\n".join(
        ",".join("" if r[k] is None else repr(r[k]) if isinstance(r[k], float) else str(r[k]).replace(",", ";")
                 for k in header) for r in rows) + "\n"
    atomic_write_text(out / "stability.csv", csv_text)
    atomic_write_json(out / "stability.json", {"scene": scene.name, "margin": args.margin, "points": rows})
    save_figure(chart_figure(points, f"stability chart: {scene.name}", args.margin), out / "stability.png")
    if args.json:
        print(json.dumps({"scene": scene.name, "margin": args.margin, "points": rows}, indent=2, allow_nan=False))
    else:
        print(f"stability chart of {scene.name} (margin {args.margin:g}; limits: the front-most support unloads "
              "about the rearmost, closed form)")
        print("\n".join(summary_lines(points)))
        print(f"wrote stability.csv, stability.json and stability.png to {out}", file=sys.stdout)
    return EXIT_OK
