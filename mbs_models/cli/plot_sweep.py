"""``recoil plot-sweep FILE [--x KEY] [--y METRIC] [--hue KEY] [--kind KIND] --out PNG``.

Bad input (a missing or unreadable table, an unknown column, an output that is not ``.png``) is a
SceneError: one line on stderr and exit code 2, before anything is written.
"""

from __future__ import annotations

import sys
from pathlib import Path

from ..errors import SceneError


def _cmd_plot_sweep(args) -> int:
    from ..outputs import check_output_file, prepare_output_file
    from ..results.plotting import save_figure
    from ..results.sweep_plots import plot_sweep, read_sweep_table

    out = Path(args.out)
    if out.suffix.lower() != ".png":
        raise SceneError("--out", f"must be a .png file, got {args.out!r}")
    check_output_file(out, key="--out")
    table = read_sweep_table(args.file)
    drawn = plot_sweep(table, x=args.x, y=args.y, hue=args.hue, kind=args.kind)
    prepare_output_file(out, key="--out")
    save_figure(drawn.figure, out)
    for note in drawn.notes:
        print(f"[recoil] note: {note}", file=sys.stderr)
    if drawn.kind == "map":
        what = f"map of {drawn.y} over {drawn.x} and {drawn.hue}"
    else:
        hue = (f", one per {drawn.hue}" if drawn.kind == "lines" else f" coloured by {drawn.hue}") if drawn.hue else ""
        what = f"{drawn.kind} of {drawn.y} against {drawn.x}{hue}"
    print(f"wrote {out}: {what} ({drawn.rows_plotted} points)")
    return 0


def add_parser(sub) -> None:
    """Register the ``plot-sweep`` subcommand on the ``recoil`` parser's subparsers."""
    plot = sub.add_parser("plot-sweep", help="figures of a sweep table: a metric against a parameter per hue "
                                             "(Figs 4/5), a heat map over two parameters, or the trade-off of "
                                             "force on the mount against recoil length")
    plot.add_argument("file", help="sweep table written by 'recoil sweep' (.csv or .parquet)")
    plot.add_argument("--x", help="parameter on the horizontal axis (default: the varied one with most values)")
    plot.add_argument("--y", help="metric to plot (default max_barrel_displacement)")
    plot.add_argument("--hue", help="parameter drawn as one line per value, or the map's vertical axis, or the "
                                    "trade-off's colour (default: the other varied parameter)")
    plot.add_argument("--kind", default="auto", choices=("auto", "lines", "map", "tradeoff"),
                      help="auto (default): lines, or a map when the hue has more than 8 values")
    plot.add_argument("--out", required=True, help="PNG file to write (missing directories are created)")
    plot.set_defaults(handler=_cmd_plot_sweep)
