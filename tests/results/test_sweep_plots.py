"""Figures of sweep tables: the lines, contours and points drawn, and bad input as one-line errors."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from matplotlib.collections import PathCollection, QuadMesh

from mbs_models.errors import SceneError
from mbs_models.results.plotting import figure_png
from mbs_models.results.sweep_plots import (pareto_front, parameter_columns, metric_columns, plot_lines, plot_map,
                                            plot_sweep, plot_tradeoff, read_sweep_table, varied_parameters)

GAPS = np.linspace(0.0, 0.12, 7)
MASSES = (100.0, 500.0, 1000.0)


def _table(gaps=GAPS, masses=MASSES, failed: int = 0) -> pd.DataFrame:
    """A synthetic sweep table (values made up from a known formula, not by the code under test)."""
    rows = []
    for m in masses:
        for g in gaps:
            rows.append({"absorber.mass": m, "contact.gap": g,
                         "max_barrel_displacement": 0.22 - 1e-5 * m * (1 + np.cos(30 * g)),
                         "peak_support_force": 7000.0 - 2.0 * m + 10000.0 * g,
                         "impacts": 2, "wall_time": 0.05, "status": "ok", "error": ""})
    for row in rows[:failed]:
        row.update(status="SimulationError", error="step size too small",
                   max_barrel_displacement=np.nan, peak_support_force=np.nan)
    return pd.DataFrame(rows)


def _png_ok(fig) -> None:
    """The figure renders to a PNG that decodes to the figure's size in pixels, not blank."""
    import io

    from matplotlib.image import imread

    data = figure_png(fig)
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pixels = imread(io.BytesIO(data), format="png")
    width, height = fig.get_size_inches() * fig.dpi
    assert pixels.shape[:2] == (round(height), round(width))
    assert pixels[..., :3].std() > 0.05


def test_columns_are_told_apart():
    table = _table()
    assert parameter_columns(table) == ["absorber.mass", "contact.gap"]
    assert metric_columns(table) == ["max_barrel_displacement", "peak_support_force", "impacts", "wall_time"]
    assert varied_parameters(table) == ["contact.gap", "absorber.mass"]  # most values first
    # dotted metric columns (several absorbers, end stops) and run columns are no parameters
    table["absorber.0.impacts"] = 1
    table["any_stop.dissipated_energy"] = 2.0e4
    table["steps"] = 100
    assert parameter_columns(table) == ["absorber.mass", "contact.gap"]
    assert metric_columns(table)[-3:] == ["absorber.0.impacts", "any_stop.dissipated_energy", "steps"]


def test_lines_one_per_hue_in_engineering_units():
    drawn = plot_lines(_table(), "contact.gap", "max_barrel_displacement", "absorber.mass")
    ax = drawn.figure.axes[0]
    lines = ax.get_lines()
    assert len(lines) == len(MASSES)
    np.testing.assert_allclose(lines[0].get_xdata(), GAPS * 1e3)  # mm
    expected = 0.22 - 1e-5 * 100.0 * (1 + np.cos(30 * GAPS))
    np.testing.assert_allclose(lines[0].get_ydata(), expected * 1e3)
    assert "[mm]" in ax.get_xlabel() and "[mm]" in ax.get_ylabel()
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [f"mass = {m:g} kg" for m in MASSES]
    _png_ok(drawn.figure)


def test_failed_rows_are_skipped_with_a_note():
    drawn = plot_lines(_table(failed=2), "contact.gap", "max_barrel_displacement", "absorber.mass")
    assert drawn.rows_plotted == len(GAPS) * len(MASSES) - 2
    assert drawn.notes == ["skipped 2 failed row(s) (status other than 'ok')"]
    assert len(drawn.figure.axes[0].get_lines()[0].get_xdata()) == len(GAPS) - 2


def test_map_has_heat_map_and_the_requested_contours():
    drawn = plot_map(_table(masses=np.linspace(100, 2000, 5)), "contact.gap", "absorber.mass",
                     "peak_support_force", levels=6)
    ax = drawn.figure.axes[0]
    assert any(isinstance(c, QuadMesh) for c in ax.collections)
    assert len(drawn.contours.levels) == 6
    # force = 7000 - 2 m + 10000 g: planar, so every level is one straight contour line inside the grid
    lo, hi = 7000 - 2 * 2000, 7000 - 2 * 100 + 10000 * 0.12
    np.testing.assert_allclose(drawn.contours.levels, np.linspace(lo, hi, 8)[1:-1] * 1e-3)
    assert "[kN]" in drawn.figure.axes[1].get_ylabel()  # the colour bar
    _png_ok(drawn.figure)


def test_a_coarse_map_keeps_its_axes_on_the_grid_and_draws_no_contours():
    """Masses 100/500/1000 kg once gave an axis from -100 to 1250 kg and contours interpolated across the cells."""
    drawn = plot_map(_table(), "contact.gap", "absorber.mass", "peak_support_force")
    ax = drawn.figure.axes[0]
    # the cells' edges: half-way between the values, the outer ones at the first and last value
    assert ax.get_ylim() == pytest.approx((100.0, 1000.0))
    assert ax.get_xlim() == pytest.approx((0.0, 120.0))  # gaps 0 ... 0.12 m, in mm
    (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
    corners = mesh.get_coordinates()
    np.testing.assert_allclose(corners[:, 0, 1], [100.0, 300.0, 750.0, 1000.0])
    assert drawn.contours is None and "no contour lines" in drawn.notes[-1]
    # each cell says its value (force = 7000 - 2 m + 10000 g N, in kN)
    texts = {t.get_text() for t in ax.texts}
    assert f"{(7000 - 2 * 500 + 10000 * 0.04) * 1e-3:.4g}" in texts and len(texts) <= len(GAPS) * len(MASSES)
    _png_ok(drawn.figure)


def test_the_axes_of_a_fine_map_lie_within_the_cell_edges():
    drawn = plot_map(_table(masses=np.linspace(100, 2000, 5)), "contact.gap", "absorber.mass")
    ax = drawn.figure.axes[0]
    assert 100.0 <= ax.get_ylim()[0] < ax.get_ylim()[1] <= 2000.0
    assert 0.0 <= ax.get_xlim()[0] < ax.get_xlim()[1] <= 120.0
    assert drawn.contours is not None


def test_tradeoff_front_is_the_non_dominated_points():
    force = np.array([5.0, 4.0, 6.0, 3.0, 3.5])
    length = np.array([1.0, 2.0, 2.5, 3.0, 4.0])
    assert list(pareto_front(force, length)) == [0, 1, 3]
    drawn = plot_tradeoff(_table(), "absorber.mass")
    ax = drawn.figure.axes[0]
    assert sum(isinstance(c, PathCollection) for c in ax.collections) == 1
    assert len(ax.collections[0].get_offsets()) == len(GAPS) * len(MASSES)
    assert "[kN]" in ax.get_ylabel() and "[mm]" in ax.get_xlabel()
    _png_ok(drawn.figure)


def test_defaults_pick_gap_as_x_and_mass_as_hue():
    drawn = plot_sweep(_table())
    assert (drawn.kind, drawn.x, drawn.hue, drawn.y) == ("lines", "contact.gap", "absorber.mass",
                                                         "max_barrel_displacement")
    many = plot_sweep(_table(gaps=np.linspace(0.0, 0.12, 13), masses=np.linspace(100, 2000, 10)))
    assert (many.kind, many.x, many.hue) == ("map", "contact.gap", "absorber.mass") and many.contours is not None


@pytest.mark.parametrize("kwargs, key, text", [
    (dict(x="contact.gaps"), "--x", "did you mean 'contact.gap'"),
    (dict(y="max_barrel_displacment"), "--y", "did you mean 'max_barrel_displacement'"),
    (dict(hue="absorber.mas"), "--hue", "did you mean 'absorber.mass'"),
    (dict(kind="pie"), "--kind", "pie"),
    (dict(x="contact.gap", hue="contact.gap"), "--hue", "must differ"),
])
def test_bad_names(kwargs, key, text):
    with pytest.raises(SceneError) as info:
        plot_sweep(_table(), **kwargs)
    assert info.value.key == key and text in info.value.message


def test_read_sweep_table_errors(tmp_path):
    with pytest.raises(SceneError, match="no such file"):
        read_sweep_table(tmp_path / "missing.csv")
    (tmp_path / "t.txt").write_text("a,b\n")
    with pytest.raises(SceneError, match=r"\.csv or \.parquet"):
        read_sweep_table(tmp_path / "t.txt")
    (tmp_path / "empty.csv").write_text("contact.gap,max_barrel_displacement\n")
    with pytest.raises(SceneError, match="no rows"):
        read_sweep_table(tmp_path / "empty.csv")


def test_a_real_sweep_table_from_its_file(tmp_path):
    """The table recoil sweep writes (run_sweep, read back from CSV): lines per mass, one per mass value."""
    from mbs_models import model_i
    from mbs_models.studies.sweep import run_sweep

    out = tmp_path / "sweep.csv"
    run_sweep(model_i(), {"absorber.mass": [500.0, 1000.0], "contact.gap": "0:0.12:4"}, end_time=2.0,
              workers=1, out=out, progress=False, stop_when_final=("max_barrel_displacement", "peak_support_force"))
    table = read_sweep_table(out)
    assert parameter_columns(table) == ["absorber.mass", "contact.gap"]
    drawn = plot_sweep(table)
    assert (drawn.kind, drawn.x, drawn.hue, drawn.rows_plotted) == ("lines", "contact.gap", "absorber.mass", 8)
    assert len(drawn.figure.axes[0].get_lines()) == 2
    np.testing.assert_allclose(drawn.figure.axes[0].get_lines()[1].get_ydata(),
                               table[table["absorber.mass"] == 1000.0]["max_barrel_displacement"] * 1e3)
    tradeoff = plot_sweep(table, kind="tradeoff", hue="absorber.mass")
    assert tradeoff.rows_plotted == 8 and tradeoff.hue == "absorber.mass"
