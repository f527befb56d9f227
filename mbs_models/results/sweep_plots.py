"""Figures of a sweep table (one row per point, as written by ``recoil sweep``).

A sweep table has one column per swept parameter, named by its dotted scene key (``contact.gap``,
``absorber.mass``), one column per scalar metric (``max_barrel_displacement`` in m,
``peak_support_force`` in N, ...) and the bookkeeping columns ``wall_time``, ``status`` and ``error``.
Rows whose ``status`` is not ``ok``, or whose plotted value is missing (a failed solve; a metric an
early-stopped run did not prove final), are left out and counted in :attr:`SweepFigure.notes`.

Three figures:

* :func:`plot_lines` -- a metric against one parameter, one line per value of a second (the paper's
  Figs 4/5: barrel displacement against the gap, one line per absorber mass);
* :func:`plot_map` -- a metric over two parameters: a heat map of cells around the grid points, with labelled
  contour lines where the grid is fine enough (:data:`MIN_CONTOUR_VALUES`);
* :func:`plot_tradeoff` -- the designer's trade-off: peak force on the mount against the recoil length
  (max barrel displacement), every point coloured by a parameter, with the Pareto front (the points
  that no other point beats on both).

Values are drawn in engineering units (mm, kN) and the axis labels say which.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib import patheffects
from matplotlib.figure import Figure

from ..errors import SceneError
from . import element_outputs
from .plotting import new_figure

#: Columns of a sweep table that are neither parameters nor plottable metrics.
BOOKKEEPING_COLUMNS = ("status", "error", "stop_reason", "scene", "point", "index")

#: Metric -> (axis label, factor from SI to the plotted unit).
METRIC_UNITS = {
    "max_barrel_displacement": ("recoil length (max barrel displacement) [mm]", 1e3),
    "time_of_max_barrel_displacement": ("time of max barrel displacement [s]", 1.0),
    "peak_support_force": ("peak force on the mount [kN]", 1e-3),
    "time_of_peak_support_force": ("time of peak force on the mount [s]", 1.0),
    "peak_contact_force": ("peak contact force [kN]", 1e-3),
    "time_of_peak_contact_force": ("time of peak contact force [s]", 1.0),
    "max_absorber_velocity": ("max absorber velocity [m/s]", 1.0),
    "time_of_max_absorber_velocity": ("time of max absorber velocity [s]", 1.0),
    "impacts": ("impacts [count]", 1.0),
    "wall_time": ("wall time [s]", 1.0),
    "end_time": ("simulated time [s]", 1.0),
}

#: Last component of a dotted parameter key -> (unit, factor from SI to the plotted unit).
PARAMETER_UNITS = {
    "gap": ("mm", 1e3), "position": ("mm", 1e3), "mass": ("kg", 1.0), "projectile_mass": ("kg", 1.0),
    "charge_mass": ("kg", 1.0), "stiffness": ("N/m", 1.0), "damping": ("N s/m", 1.0),
    "recoil": ("N s/m", 1.0), "counter_recoil": ("N s/m", 1.0), "damping_factor": ("s/m", 1.0),
    "exponent": ("-", 1.0), "restitution": ("-", 1.0), "initial_velocity": ("m/s", 1.0),
    "muzzle_velocity": ("m/s", 1.0), "gas_velocity": ("m/s", 1.0), "orifice_area": ("mm$^2$", 1e6),
    "counter_recoil_orifice_area": ("mm$^2$", 1e6), "piston_area": ("cm$^2$", 1e4),
    "discharge_coefficient": ("-", 1.0), "fluid_density": ("kg/m$^3$", 1.0), "initial_pressure": ("MPa", 1e-6),
    "gas_volume": ("l", 1e3), "polytropic_exponent": ("-", 1.0), "elevation": ("deg", 1.0),
    "friction_coefficient": ("-", 1.0), "interval": ("s", 1.0), "shots": ("-", 1.0),
}

#: ``kind="auto"`` draws lines per hue value up to this many values, a map beyond.
MAX_HUE_LINES = 8

#: The metrics of the trade-off figure: recoil length (x) and peak force on the mount (y).
TRADEOFF_METRICS = ("max_barrel_displacement", "peak_support_force")


def metric_label(column: str) -> tuple[str, float]:
    """Axis label (with unit) and the factor from SI for a metric column (a declared metric in its declared unit)."""
    unit = element_outputs.declared_column_unit(column) or "SI"
    return METRIC_UNITS.get(column, (f"{column.replace('_', ' ')} [{unit}]", 1.0))


def parameter_label(column: str) -> tuple[str, float]:
    """Axis label (with unit) and the factor from SI for a parameter column (a dotted scene key)."""
    unit, factor = PARAMETER_UNITS.get(column.rsplit(".", 1)[-1], ("SI", 1.0))
    return f"{column} [{unit}]", factor


def read_sweep_table(path: str | Path, key: str = "FILE"):
    """A sweep table (``.csv``, or ``.parquet`` with pyarrow) as a DataFrame; SceneError naming ``key``."""
    import pandas as pd

    path = Path(path)
    if path.suffix.lower() not in (".csv", ".parquet"):
        raise SceneError(key, f"{path} must be a .csv or .parquet sweep table, got {path.suffix or 'no extension'!r}")
    if not path.is_file():
        raise SceneError(key, f"no such file: {path}")
    try:
        table = pd.read_csv(path) if path.suffix.lower() == ".csv" else pd.read_parquet(path)
    except ImportError as exc:
        raise SceneError(key, f"reading Parquet needs pyarrow ({exc})") from None
    except (ValueError, OSError) as exc:  # pandas' parser errors are ValueErrors
        raise SceneError(key, f"cannot read {path} as a sweep table: {str(exc).splitlines()[0]}") from None
    if table.empty:
        raise SceneError(key, f"{path} has no rows")
    return table


def is_metric_column(column: str) -> bool:
    """A metric or bookkeeping column of a sweep row (:mod:`mbs_models.studies.point`): a scalar metric,
    a per-absorber or per-stop metric (``absorber.0.impacts``, ``<stop>.dissipated_energy``), a metric an
    element declares (``progressive_spring.peak_force``), the
    run information or the status columns."""
    from ..studies.point import ABSORBER_METRICS, RUN_COLUMNS, SCALAR_METRICS, STATUS_COLUMNS, STOP_METRICS

    known = {*SCALAR_METRICS, *ABSORBER_METRICS, *STOP_METRICS, *RUN_COLUMNS, *STATUS_COLUMNS, *BOOKKEEPING_COLUMNS}
    return (column in known or column.rsplit(".", 1)[-1] in known
            or element_outputs.declared_column_unit(column) is not None)  # a metric an element declares


def parameter_columns(table) -> list[str]:
    """The swept parameters: the numeric columns named by a dotted scene key (every column that is not a
    metric, :func:`is_metric_column`), in table order."""
    import pandas as pd

    return [c for c in table.columns if "." in str(c) and not is_metric_column(str(c))
            and pd.api.types.is_numeric_dtype(table[c]) and not pd.api.types.is_bool_dtype(table[c])]


def metric_columns(table) -> list[str]:
    """The numeric metric columns (every numeric column that is not a parameter)."""
    import pandas as pd

    return [c for c in table.columns if is_metric_column(str(c)) and c not in BOOKKEEPING_COLUMNS
            and pd.api.types.is_numeric_dtype(table[c])]


def varied_parameters(table) -> list[str]:
    """The parameter columns that take more than one value, most values first (ties: table order)."""
    counts = {c: table[c].nunique(dropna=True) for c in parameter_columns(table)}
    return sorted((c for c, n in counts.items() if n > 1), key=lambda c: -counts[c])


def check_column(column: str, allowed: list[str], key: str, what: str = "column") -> str:
    """``column`` if it is one of ``allowed``; else a SceneError naming ``key``, with "did you mean"."""
    if column in allowed:
        return column
    close = difflib.get_close_matches(column, allowed, n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    raise SceneError(key, f"unknown {what} {column!r}{hint} (allowed: {', '.join(allowed) or 'none'})")


@dataclass
class SweepFigure:
    """A figure of a sweep table and what it left out (one note per reason, with the row count)."""

    figure: Figure
    kind: str
    x: str
    y: str
    hue: str | None
    rows_plotted: int
    notes: list[str] = field(default_factory=list)
    contours: object = None  #: the map's ContourSet (None without contour lines)


def usable_rows(table, columns: list[str]) -> tuple[object, list[str]]:
    """The rows with ``status == ok`` (when there is a status) and every named column present; notes."""
    notes = []
    rows = table
    if "status" in table.columns:
        ok = table["status"].astype(str) == "ok"
        if (~ok).any():
            notes.append(f"skipped {int((~ok).sum())} failed row(s) (status other than 'ok')")
        rows = table[ok]
    present = rows[columns].notna().all(axis=1)
    if (~present).any():
        missing = [c for c in columns if rows[c].isna().any()]
        notes.append(f"skipped {int((~present).sum())} row(s) without a value of {', '.join(missing)}")
    return rows[present], notes


def _check_others_fixed(rows, used: list[str]) -> None:
    """A figure of some parameters needs every other parameter fixed: one value per point drawn."""
    others = [c for c in parameter_columns(rows) if c not in used and rows[c].nunique(dropna=True) > 1]
    if others:
        raise SceneError("--hue" if len(used) == 1 else "--x",
                         f"the table also varies {', '.join(others)}; plot it with --x/--hue or filter the table first")


def _colours(count: int):
    from matplotlib import colormaps

    cmap = colormaps["viridis"]
    return [cmap(v) for v in (np.linspace(0.0, 0.9, count) if count > 1 else [0.0])]


def plot_lines(table, x: str, y: str = "max_barrel_displacement", hue: str | None = None, *,
               title: str | None = None) -> SweepFigure:
    """``y`` against the parameter ``x``, one line per value of the parameter ``hue`` (Figs 4/5)."""
    columns = [x, y] + ([hue] if hue else [])
    rows, notes = usable_rows(table, columns)
    if rows.empty:
        raise SceneError(y, "no row of the table has a value to plot (every point failed or is missing)")
    _check_others_fixed(rows, [x] + ([hue] if hue else []))
    x_label, x_factor = parameter_label(x)
    y_label, y_factor = metric_label(y)
    fig, axes = new_figure(1, 1, row_height=4.0)
    ax = axes[0, 0]
    groups = [(None, rows)] if hue is None else list(rows.groupby(hue, sort=True))
    hue_label, hue_factor = parameter_label(hue) if hue else ("", 1.0)
    hue_unit = hue_label.rsplit("[", 1)[-1].rstrip("]") if hue else ""
    for colour, (value, group) in zip(_colours(len(groups)), groups):
        group = group.sort_values(x)
        label = None if hue is None else f"{hue.rsplit('.', 1)[-1]} = {value * hue_factor:g} {hue_unit}"
        ax.plot(group[x] * x_factor, group[y] * y_factor, "o-", ms=3, lw=1.2, color=colour, label=label)
    ax.set_xlabel(x_label)
    ax.set_ylabel(y_label)
    if hue is not None:
        ax.legend(fontsize=8, title=hue, title_fontsize=8)
    ax.set_title(title or f"{y.replace('_', ' ')} against {x}", fontsize=11)
    return SweepFigure(fig, "lines", x, y, hue, len(rows), notes)


#: Contour lines are drawn only on a grid of at least this many values along each parameter: a contour
#: interpolates linearly between neighbouring points, and across a coarser grid (100/500/1000 kg) the lines
#: would show a shape the data do not have.  A coarser map shows its cells with the value written in each.
MIN_CONTOUR_VALUES = 5


def cell_edges(values: np.ndarray) -> np.ndarray:
    """The edges of the cells of a map around sorted grid ``values``: half-way between neighbours inside,
    the first and last values themselves outside (the map never reaches beyond the data).  A single value
    gets a cell of +-5 % of itself (+-0.5 for 0) so that it can be drawn."""
    values = np.asarray(values, dtype=float)
    if len(values) == 1:
        half = 0.05 * abs(values[0]) or 0.5
        return np.array([values[0] - half, values[0] + half])
    return np.concatenate([values[:1], (values[1:] + values[:-1]) / 2.0, values[-1:]])


def plot_map(table, x: str, hue: str, y: str = "max_barrel_displacement", *, levels: int = 8,
             title: str | None = None) -> SweepFigure:
    """``y`` over the parameters ``x`` (horizontal) and ``hue`` (vertical): one cell per grid point, with
    contour lines on a fine grid.

    The table must hold a grid (every combination of the two parameters' values at most once); a
    combination without a usable row is a blank cell.  Cells are bounded half-way between neighbouring
    values and by the first and last values (:func:`cell_edges`): the axes span the data, no more; each grid
    point is marked.  ``levels`` contour lines are drawn at evenly spaced values of ``y`` when each parameter
    has at least :data:`MIN_CONTOUR_VALUES` values; on a coarser grid each cell is labelled with its value
    instead (and a note says why there are no contour lines).
    """
    rows, notes = usable_rows(table, [x, hue, y])
    if rows.empty:
        raise SceneError(y, "no row of the table has a value to plot (every point failed or is missing)")
    _check_others_fixed(rows, [x, hue])
    if rows.duplicated([x, hue]).any():
        raise SceneError("--x", f"the table has several rows for one ({x}, {hue}) point; a map needs a grid")
    grid = rows.pivot(index=hue, columns=x, values=y).sort_index().sort_index(axis=1)
    x_label, x_factor = parameter_label(x)
    h_label, h_factor = parameter_label(hue)
    y_label, y_factor = metric_label(y)
    xs = grid.columns.to_numpy(dtype=float) * x_factor
    hs = grid.index.to_numpy(dtype=float) * h_factor
    values = np.ma.masked_invalid(grid.to_numpy(dtype=float) * y_factor)
    fig, axes = new_figure(1, 1, row_height=4.4)
    ax = axes[0, 0]
    ax.grid(False)
    x_edges, h_edges = cell_edges(xs), cell_edges(hs)
    mesh = ax.pcolormesh(x_edges, h_edges, values, shading="flat", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label=y_label)
    gx, gh = np.meshgrid(xs, hs)
    drawn = ~np.ma.getmaskarray(values)
    ax.plot(gx[drawn], gh[drawn], "o", color="white", mec="black", ms=3.5, mew=0.6, ls="none", clip_on=False)
    ax.set_xlim(x_edges[0], x_edges[-1])
    ax.set_ylim(h_edges[0], h_edges[-1])
    contours = None
    fine = len(xs) >= MIN_CONTOUR_VALUES and len(hs) >= MIN_CONTOUR_VALUES
    if fine and values.count() >= 4 and values.max() > values.min():
        contours = ax.contour(xs, hs, values, levels=np.linspace(values.min(), values.max(), levels + 2)[1:-1],
                              colors="white", linewidths=0.8)
        ax.clabel(contours, fontsize=7, fmt="%.4g")
    else:
        notes.append(f"no contour lines: drawn on a grid of at least {MIN_CONTOUR_VALUES} values of each "
                     f"parameter (this one has {len(xs)} x {len(hs)}); each cell shows its value")
        if values.count() <= 100:
            for (i, j), value in np.ndenumerate(values.filled(np.nan)):
                if np.isfinite(value):
                    # inside its cell: the label of a point on the map's edge points inwards
                    left, right = j == 0 and len(xs) > 1, j == len(xs) - 1 and len(xs) > 1
                    top = i == len(hs) - 1 and len(hs) > 1
                    ax.annotate(f"{value:.4g}", (xs[j], hs[i]), xytext=(4 * left - 4 * right, -5 if top else 5),
                                textcoords="offset points", ha="left" if left else "right" if right else "center",
                                va="top" if top else "bottom", fontsize=7, color="white",
                                path_effects=[patheffects.withStroke(linewidth=2, foreground="black")])
    ax.set_xlabel(x_label)
    ax.set_ylabel(h_label)
    ax.set_title(title or f"{y.replace('_', ' ')} over {x} and {hue}", fontsize=11)
    return SweepFigure(fig, "map", x, y, hue, len(rows), notes, contours)


def pareto_front(force: np.ndarray, length: np.ndarray) -> np.ndarray:
    """Indices of the points no other point beats on both (lower force and shorter recoil), by length."""
    order = np.lexsort((force, length))
    front, best = [], np.inf
    for i in order:
        if force[i] < best:
            front.append(i)
            best = force[i]
    return np.asarray(front, dtype=int)


def plot_tradeoff(table, hue: str | None = None, *, title: str | None = None) -> SweepFigure:
    """Peak force on the mount (kN) against the recoil length (mm): every point, coloured by ``hue``,
    and the Pareto front (the designs that cannot be improved in one without losing in the other)."""
    length, force = TRADEOFF_METRICS
    for metric in TRADEOFF_METRICS:
        check_column(metric, metric_columns(table), "--y")
    rows, notes = usable_rows(table, [length, force] + ([hue] if hue else []))
    if rows.empty:
        raise SceneError(force, "no row of the table has both the recoil length and the peak force on the mount")
    l_label, l_factor = metric_label(length)
    f_label, f_factor = metric_label(force)
    xs = rows[length].to_numpy(dtype=float) * l_factor
    ys = rows[force].to_numpy(dtype=float) * f_factor
    fig, axes = new_figure(1, 1, row_height=4.4)
    ax = axes[0, 0]
    if hue:
        h_label, h_factor = parameter_label(hue)
        points = ax.scatter(xs, ys, c=rows[hue].to_numpy(dtype=float) * h_factor, s=16, cmap="viridis")
        fig.colorbar(points, ax=ax, label=h_label)
    else:
        ax.scatter(xs, ys, s=16, color="#1f77b4")
    front = pareto_front(ys, xs)
    ax.plot(xs[front], ys[front], "-o", color="#d62728", lw=1.2, ms=8, mfc="none", mew=1.2,
            label=f"Pareto front ({len(front)} points)")
    ax.legend(fontsize=8)
    ax.set_xlabel(l_label)
    ax.set_ylabel(f_label)
    ax.set_title(title or "trade-off: force on the mount against recoil length", fontsize=11)
    return SweepFigure(fig, "tradeoff", length, force, hue, len(rows), notes)


def plot_sweep(table, x: str | None = None, y: str | None = None, hue: str | None = None,
               kind: str = "auto") -> SweepFigure:
    """The figure ``recoil plot-sweep`` draws, with its defaults.

    ``kind``: ``lines``, ``map``, ``tradeoff`` or ``auto``: lines for one varied parameter, or for two
    when the hue takes at most :data:`MAX_HUE_LINES` values (the paper's three masses); a map for two
    varied parameters with more values than that.  Defaults: ``x`` is the varied
    parameter with the most values, ``hue`` the other varied one (if any), ``y`` is
    ``max_barrel_displacement`` when the table has it, else its first metric.  Unknown names are
    SceneErrors naming the option, with the closest column.
    """
    if kind not in ("auto", "lines", "map", "tradeoff"):
        raise SceneError("--kind", f"must be one of auto, lines, map, tradeoff, got {kind!r}")
    parameters = parameter_columns(table)
    metrics = metric_columns(table)
    if not parameters:
        raise SceneError("FILE", "the table has no parameter column (columns named by a dotted scene key)")
    if x is not None:
        check_column(x, parameters, "--x")
    if hue is not None:
        check_column(hue, parameters, "--hue")
    if y is not None:
        check_column(y, metrics, "--y")
    varied = varied_parameters(table)
    if kind == "tradeoff":
        return plot_tradeoff(table, hue if hue is not None else (x or (varied[0] if varied else None)))
    if x is None:
        x = next((c for c in varied if c != hue), parameters[0])
    if x == hue:
        raise SceneError("--hue", f"must differ from --x ({x})")
    if y is None:
        y = "max_barrel_displacement" if "max_barrel_displacement" in metrics else metrics[0]
    if hue is None:
        hue = next((c for c in varied if c != x), None)
    many_hues = hue is not None and table[hue].nunique(dropna=True) > MAX_HUE_LINES
    if kind == "map" or (kind == "auto" and many_hues):
        if hue is None:
            raise SceneError("--hue", "a map needs a second varied parameter; the table varies only " + x)
        return plot_map(table, x, hue, y)
    return plot_lines(table, x, y, hue)
