"""The figure of an optimisation (:func:`mbs_models.studies.optimise.optimise`).

Left: convergence -- the minimised metric of every evaluated point against its evaluation number
(feasible points coloured, infeasible ones grey crosses; failed solves have no value and are counted in
the title) and the best feasible value so far as a step line.  Right: the evaluated points over the
design space -- for one parameter, the metric against it; for two or more, the points in the plane of
the first two parameters coloured by the metric -- with the optimum as a red star.  Engineering units.
"""

from __future__ import annotations

import textwrap

import numpy as np
from matplotlib.figure import Figure

from .plotting import new_figure
from .sweep_plots import metric_label, parameter_label

OPTIMUM_STYLE = dict(marker="*", color="#d62728", ms=14, mec="black", mew=0.6, ls="none", clip_on=False, zorder=5)


def best_so_far(values: np.ndarray, feasible: np.ndarray) -> np.ndarray:
    """The running minimum of ``values`` over the feasible points (NaN before the first feasible one)."""
    out = np.full(len(values), np.nan)
    best = np.inf
    for i, (value, ok) in enumerate(zip(values, feasible)):
        if ok and value < best:
            best = value
        out[i] = best if np.isfinite(best) else np.nan
    return out


def plot_optimisation(result) -> Figure:
    """Convergence and the evaluated points over the design space of an :class:`OptimisationResult`."""
    history = result.history
    keys = list(result.bounds)
    label, factor = metric_label(result.minimise)
    values = history[result.minimise].to_numpy(dtype=float) * factor
    feasible = history["feasible"].to_numpy(dtype=bool)
    solved = history["status"].to_numpy() == "ok"
    evaluation = history["evaluation"].to_numpy()
    fig, axes = new_figure(1, 2, width=11.0, row_height=4.4)
    ax = axes[0, 0]
    ax.plot(evaluation[feasible], values[feasible], "o", ms=3, color="#1f77b4", alpha=0.6, label="feasible")
    infeasible = solved & ~feasible
    if infeasible.any():
        ax.plot(evaluation[infeasible], values[infeasible], "x", ms=4, color="#999999", label="infeasible")
    ax.step(evaluation, best_so_far(values, feasible), where="post", color="#d62728", lw=1.5,
            label="best feasible so far")
    ax.set_xlabel("evaluation")
    ax.set_ylabel(label)
    failed = int((~solved).sum())
    ax.set_title(f"convergence: {len(history)} evaluations, {result.generations} generations"
                 + (f", {failed} failed" if failed else ""), fontsize=10)
    ax.legend(fontsize=8)

    draw_design_space(axes[0, 1], result)
    state = "" if result.feasible else " -- NO FEASIBLE DESIGN FOUND"
    title = f"minimise {result.minimise} over {', '.join(keys)} (base scene: {result.scene.name}){state}"
    fig.suptitle(wrap_to_figure(title, fig, fontsize=11), fontsize=11)
    return fig


def wrap_to_figure(text: str, fig: Figure, fontsize: float) -> str:
    """``text`` broken into lines that fit the width of ``fig``: at most ``width / (0.6 fontsize)`` characters
    a line (an average character of the sans-serif font is about 0.55 of its size; the figure's width in
    points over that), so that a long title is wrapped instead of clipped at the figure's edges."""
    characters = int(fig.get_figwidth() * 72.0 / (0.6 * fontsize))
    return "\n".join(textwrap.wrap(text, width=max(characters, 20)))


def draw_design_space(ax, result, *, colorbar: bool = True) -> None:
    """The evaluated points of ``result`` over its design space on ``ax``: for one parameter the
    minimised metric against it, for two or more the plane of the first two parameters with the points
    coloured by the metric (a colour bar beside ``ax`` if ``colorbar``); infeasible points as grey crosses,
    the optimum as a red star; the title names the constraints."""
    history = result.history
    keys = list(result.bounds)
    label, factor = metric_label(result.minimise)
    values = history[result.minimise].to_numpy(dtype=float) * factor
    feasible = history["feasible"].to_numpy(dtype=bool)
    infeasible = (history["status"].to_numpy() == "ok") & ~feasible
    x_label, x_factor = parameter_label(keys[0])
    xs = history[keys[0]].to_numpy(dtype=float) * x_factor
    best_x = result.parameters[keys[0]] * x_factor
    if len(keys) == 1:
        ax.plot(xs[feasible], values[feasible], "o", ms=3, color="#1f77b4", alpha=0.6, label="feasible")
        if infeasible.any():
            ax.plot(xs[infeasible], values[infeasible], "x", ms=4, color="#999999", label="infeasible")
        if result.objective is not None:
            ax.plot([best_x], [result.objective * factor], label="optimum", **OPTIMUM_STYLE)
        ax.set_ylabel(label)
    else:
        y_label, y_factor = parameter_label(keys[1])
        ys = history[keys[1]].to_numpy(dtype=float) * y_factor
        points = ax.scatter(xs[feasible], ys[feasible], c=values[feasible], s=14, cmap="viridis", label="feasible")
        if colorbar:
            ax.figure.colorbar(points, ax=ax, label=label)
        if (~feasible).any():
            ax.plot(xs[~feasible], ys[~feasible], "x", ms=4, color="#999999", label="infeasible or failed")
        ax.plot([best_x], [result.parameters[keys[1]] * y_factor], label="optimum", **OPTIMUM_STYLE)
        ax.set_ylabel(y_label)
        ax.set_xlim(*(np.array(result.bounds[keys[0]]) * x_factor))
        ax.set_ylim(*(np.array(result.bounds[keys[1]]) * y_factor))
    ax.set_xlabel(x_label)
    ax.legend(fontsize=8)
    constraints = ", ".join(str(c) for c in result.constraints) or "no constraints"
    ax.set_title(f"evaluated designs ({constraints})", fontsize=10)
