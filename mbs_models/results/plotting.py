"""Engineering plots of results: units on axes, legends, readable at 100 %.

Every plot of time histories draws the densified histories (:mod:`mbs_models.results.dense`: the step-end
samples and, in longer steps, times no more than ``interval`` s apart on the interpolant and the laws; 1 ms by
default, :func:`~mbs_models.results.dense.default_interval`) -- no straight chords across the solver's 20 ms
steps; ``step_ends=True`` draws the step-end samples alone.

Uses matplotlib's object-oriented API (``Figure`` + Agg canvas): no global pyplot state and no
display needed, so it is safe in scripts, tests and worker processes.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Sequence

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..errors import SceneError
from ..outputs import atomic_write_bytes
from . import element_outputs
from .dense import output_histories
from .carriage_plots import carriage_rows, plot_ground_reactions, sketch_gun
from .result import Result

#: One colour per model, used consistently in every figure.
MODEL_COLOURS = {"simplified": "#444444", "model (i)": "#1f77b4", "model (ii)": "#d62728"}
FIGURE_DPI = 110


def new_figure(rows: int = 1, cols: int = 1, *, width: float = 8.0, row_height: float = 3.0,
               sharex: bool = False) -> tuple[Figure, np.ndarray]:
    """A figure with a grid of axes (always returned as a 2-D array) and the house style."""
    fig = Figure(figsize=(width, row_height * rows), dpi=FIGURE_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axes = np.atleast_2d(fig.subplots(rows, cols, sharex=sharex, squeeze=False))
    for ax in axes.flat:
        ax.grid(True, alpha=0.35)
        ax.tick_params(labelsize=9)
    return fig, axes


#: The file formats a figure is written in, named by the file's extension.
FIGURE_FORMATS = ("png", "pdf", "svg")


def figure_format(path: str | Path, key: str = "path") -> str:
    """The format a figure file's extension names (``png``, ``pdf``, ``svg``; any case); SceneError naming
    ``key`` for any other extension or none."""
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in FIGURE_FORMATS:
        named = f"'.{suffix}'" if suffix else "no extension"
        raise SceneError(key, f"{Path(path).name} has {named}: a figure is written as "
                              f"{', '.join('.' + f for f in FIGURE_FORMATS)}")
    return suffix


def figure_bytes(fig: Figure, fmt: str = "png") -> bytes:
    """Render a figure to the bytes of a file in ``fmt`` (one of :data:`FIGURE_FORMATS`)."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format=fmt, dpi=FIGURE_DPI)
    return buffer.getvalue()


def figure_png(fig: Figure) -> bytes:
    """Render a figure to PNG bytes."""
    return figure_bytes(fig, "png")


def save_figure(fig: Figure, path: str | Path) -> Path:
    """Write a figure atomically (temporary name, then rename) in the format its extension names (png, pdf,
    svg); SceneError for another extension, before anything is rendered."""
    return atomic_write_bytes(path, figure_bytes(fig, figure_format(path)))


#: Colours of the absorbers and contacts, in order (the barrel is dark grey).
SERIES_COLOURS = ("#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf")


def _series_colour(i: int) -> str:
    return SERIES_COLOURS[i % len(SERIES_COLOURS)]


def plot_result(result: Result, *, title: str | None = None, impact_padding: float = 0.25,
                interval: float | None = None, step_ends: bool = False) -> Figure:
    """Time histories of one run: positions; contact forces (one line per contact); the force on the
    mount; velocities; and, with an impact, a zoom on the first one (its contact's force and the force on
    the mount over the impact's duration plus ``impact_padding`` of it either side, time in ms).  Every
    body and contact the scene has, none it lacks; after the velocities, a panel per ``panel`` of the histories
    elements declare (:func:`~mbs_models.results.element_outputs.plot_panels`).  Histories densified at
    ``interval`` (s; None: the default), or the step-end samples with ``step_ends`` (module docstring)."""
    result = output_histories(result, interval, step_ends)
    contacts = list(result.contacts.values())
    first_impact = result.impacts[0] if result.impacts else None
    declared = element_outputs.plot_panels(result)
    extra = carriage_rows(result)
    rows = 3 + bool(contacts) + len(declared) + extra + (first_impact is not None)
    fig, axes = new_figure(rows, 1, row_height=2.4)
    full = [axes[i, 0] for i in range(rows - (first_impact is not None) - (1 if extra else 0))]
    for ax in full[1:]:
        ax.sharex(full[0])
    for ax in full[:-1]:
        ax.tick_params(labelbottom=False)
    ax = axes[0, 0]
    ax.plot(result.time, result.barrel_position * 1e3, color=MODEL_COLOURS["simplified"], label="barrel $x_M$")
    for i, name in enumerate(result.absorber_names):
        ax.plot(result.time, result.positions[name] * 1e3, color=_series_colour(i), lw=1.0, label=f"{name} $x_m$")
    if result.max_barrel_displacement is not None:  # None: an early-stopped run that did not prove it final
        ax.plot([result.time_of_max_barrel_displacement], [result.max_barrel_displacement * 1e3], "ko", ms=4,
                label=f"max {result.max_barrel_displacement * 1e3:.2f} mm")
    ax.set_ylabel("position [mm]")
    ax.legend(fontsize=8, loc="upper right")
    row = 1
    if contacts:
        ax = axes[row, 0]
        for i, contact in enumerate(contacts):
            peak = "" if not contact.peak_force else f", peak {contact.peak_force / 1e3:.1f} kN"
            ax.plot(result.time, contact.force / 1e3, color=_series_colour(i), lw=1.0,
                    label=f"{contact.name.replace('_', ' ')}{peak}")
        ax.set_ylabel("contact force [kN]")
        ax.legend(fontsize=8, loc="upper right")
        row += 1
    ax = axes[row, 0]
    ax.plot(result.time, result.support_force / 1e3, color="#444444", lw=1.0)
    if result.peak_support_force is not None:
        i = int(np.argmin(np.abs(result.time - result.time_of_peak_support_force)))
        ax.plot([result.time_of_peak_support_force], [np.sign(result.support_force[i]) * result.peak_support_force / 1e3],
                "ko", ms=4, label=f"peak |S| {result.peak_support_force / 1e3:.2f} kN")
        ax.legend(fontsize=8, loc="upper right")
    ax.axhline(0.0, color="#999999", lw=0.6)
    ax.set_ylabel("force on the mount [kN]")
    ax = axes[row + 1, 0]
    ax.plot(result.time, result.barrel_velocity, color=MODEL_COLOURS["simplified"], lw=1.0, label="barrel $\\dot x_M$")
    for i, name in enumerate(result.absorber_names):
        ax.plot(result.time, result.velocities[name], color=_series_colour(i), lw=1.0, label=f"{name} $\\dot x_m$")
    ax.set_ylabel("velocity [m/s]")
    ax.legend(fontsize=8, loc="upper right")
    for k, (label, lines) in enumerate(declared):
        ax = axes[row + 2 + k, 0]
        for i, (name, values) in enumerate(lines):
            ax.plot(result.time, values, color=_series_colour(i), lw=1.0, label=name)
        ax.set_ylabel(label)
        ax.legend(fontsize=8, loc="upper right")
    if extra:  # a carriage: its ground reactions (on the time axis) and a sketch of the gun
        plot_ground_reactions(axes[row + 2 + len(declared), 0], result)
        sketch_gun(axes[row + 3 + len(declared), 0], result)
    full[-1].set_xlabel("time [s]")
    if first_impact is not None:
        _plot_impact_zoom(axes[-1, 0], result, first_impact, impact_padding)
    fig.suptitle(title or result.scene.name, fontsize=11)
    return fig


def _plot_impact_zoom(ax, result: Result, impact, padding: float) -> None:
    """The first impact: its contact's force and the force on the mount (kN) against time (ms)."""
    margin = padding * impact.duration
    mask = (result.time >= impact.start - margin) & (result.time <= impact.end + margin)
    index = list(result.contacts).index(impact.contact)
    force = result.contacts[impact.contact].force
    ax.plot(result.time[mask] * 1e3, force[mask] / 1e3, ".-", color=_series_colour(index), lw=1.0, ms=3,
            label=f"{impact.contact.replace('_', ' ')}: peak {impact.peak_force / 1e3:.1f} kN, "
                  f"{impact.duration * 1e3:.2f} ms long")
    ax.plot([impact.time_of_peak_force * 1e3], [impact.peak_force / 1e3], "ko", ms=4)
    ax.plot(result.time[mask] * 1e3, result.support_force[mask] / 1e3, "-", color="#444444", lw=1.0,
            label="force on the mount")
    ax.axhline(0.0, color="#999999", lw=0.6)
    ax.set_title(f"first impact (from {impact.start:.4g} s)", fontsize=9)
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("force [kN]")
    ax.legend(fontsize=8, loc="upper right")


def plot_barrel_displacements(results: Sequence[Result], *, title: str,
                              interval: float | None = None, step_ends: bool = False) -> Figure:
    """Barrel displacement of several models over time, as the paper's Figs 6-8 (histories densified at
    ``interval``, s, or the step-end samples with ``step_ends``)."""
    fig, axes = new_figure(1, 1, row_height=3.6)
    ax = axes[0, 0]
    for result in (output_histories(r, interval, step_ends) for r in results):
        colour = MODEL_COLOURS.get(result.scene.model_label)
        ax.plot(result.time, result.barrel_position * 1e3, color=colour,
                label=f"{result.scene.model_label}: max {result.max_barrel_displacement * 1e3:.1f} mm")
        ax.plot([result.time_of_max_barrel_displacement], [result.max_barrel_displacement * 1e3], "o",
                color=colour, ms=4)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("barrel displacement $x_M$ [mm]")
    ax.set_title(title, fontsize=11)
    ax.legend(fontsize=9)
    return fig


#: The paper's detail windows of Figs 9b/9d and 10b/10d, in s ("main effective impacts").
PAPER_ZOOM_WINDOWS = {"model (i)": 3.25, "model (ii)": 1.15}


def plot_contact_histories(results: Sequence[Result], quantity: str, *, title: str,
                           zoom_windows: dict[str, float] | None = None,
                           interval: float | None = None, step_ends: bool = False) -> Figure:
    """Contact force or absorber velocity of models (i) and (ii), full run and zoom (Figs 9-10).

    ``quantity`` is ``"contact_force"`` (kN) or ``"absorber_velocity"`` (m/s).  With zoom windows,
    ``zoom_windows`` maps a model label to a window (s): the right-hand panels then show the first
    seconds of that model's run (the main effective impacts; the paper's windows by default).  Histories
    densified at ``interval`` (s), or the step-end samples with ``step_ends``.
    """
    scale, label = (1e-3, "contact force $F_{ct}$ [kN]") if quantity == "contact_force" else \
        (1.0, "absorber velocity $\\dot x_m$ [m/s]")
    zoom_windows = PAPER_ZOOM_WINDOWS if zoom_windows is None else zoom_windows
    cols = 2 if zoom_windows else 1
    fig, axes = new_figure(len(results), cols, width=10.0 if cols == 2 else 8.0, row_height=2.8)
    for row, result in enumerate(output_histories(r, interval, step_ends) for r in results):
        values = getattr(result, quantity) * scale
        colour = MODEL_COLOURS.get(result.scene.model_label)
        zoom_window = zoom_windows.get(result.scene.model_label, 1.0) if zoom_windows else None
        for col in range(cols):
            ax = axes[row, col]
            if col == 1:
                mask = result.time <= zoom_window
                ax.plot(result.time[mask], values[mask], color=colour, lw=1.0)
                ax.set_title(f"{result.scene.model_label}: first {zoom_window:g} s", fontsize=10)
            else:
                ax.plot(result.time, values, color=colour, lw=1.0)
                ax.set_title(f"{result.scene.model_label}: {result.end_time:g} s", fontsize=10)
            if quantity == "contact_force" and result.peak_contact_force:
                ax.plot([result.time_of_peak_contact_force], [result.peak_contact_force * scale], "ko", ms=4,
                        label=f"peak {result.peak_contact_force / 1e3:.1f} kN")
                ax.legend(fontsize=8, loc="upper right")
            if quantity == "absorber_velocity" and result.max_absorber_velocity is not None:
                ax.plot([result.time_of_max_absorber_velocity], [result.max_absorber_velocity], "ko", ms=4,
                        label=f"max {result.max_absorber_velocity:.3f} m/s at "
                              f"{result.time_of_max_absorber_velocity:.4f} s")
                ax.legend(fontsize=8, loc="upper right")
            ax.set_ylabel(label, fontsize=9)
            ax.set_xlabel("time [s]")
    fig.suptitle(title, fontsize=11)
    return fig


def plot_first_impact(results: Sequence[Result], *, title: str, padding: float = 0.25,
                      interval: float | None = None, step_ends: bool = False) -> Figure:
    """Contact force over the first impact of each model, zoomed to its duration (Fig. 11; histories densified at
    ``interval``, s, or the step-end samples with ``step_ends``)."""
    fig, axes = new_figure(1, len(results), width=5.0 * len(results), row_height=3.4)
    for col, result in enumerate(output_histories(r, interval, step_ends) for r in results):
        ax = axes[0, col]
        colour = MODEL_COLOURS.get(result.scene.model_label)
        if not result.impacts:
            ax.text(0.5, 0.5, "no impact", ha="center", transform=ax.transAxes)
            continue
        impact = result.impacts[0]
        margin = padding * impact.duration
        mask = (result.time >= impact.start - margin) & (result.time <= impact.end + margin)
        ax.plot(result.time[mask] * 1e3, result.contact_force[mask] / 1e3, ".-", color=colour, lw=1.0, ms=3)
        ax.plot([impact.time_of_peak_force * 1e3], [impact.peak_force / 1e3], "ko", ms=4,
                label=f"peak {impact.peak_force / 1e3:.1f} kN, {impact.duration * 1e3:.2f} ms long")
        ax.set_title(result.scene.model_label, fontsize=10)
        ax.set_xlabel("time [ms]")
        ax.set_ylabel("contact force [kN]")
        ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=11)
    return fig
