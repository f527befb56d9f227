"""mbs_models/results/plotting.py: figures in the format the file names; the run plot's panels."""

from __future__ import annotations

import pytest

from mbs_models import SceneError, model_ii, simplified_model, simulate
from mbs_models.results.plotting import figure_format, new_figure, plot_result, save_figure


@pytest.mark.parametrize("name, fmt", [("a.png", "png"), ("a.PDF", "pdf"), ("dir.x/a.svg", "svg")])
def test_the_extension_names_the_format(name, fmt):
    assert figure_format(name) == fmt


@pytest.mark.parametrize("name", ["a.jpg", "a", "a.png.gz", "a.eps"])
def test_other_extensions_are_refused_naming_the_key(name):
    with pytest.raises(SceneError) as error:
        figure_format(name, key="--plot")
    assert error.value.key == "--plot" and ".png, .pdf, .svg" in error.value.message


@pytest.mark.parametrize("name, magic", [("f.png", b"\x89PNG"), ("f.pdf", b"%PDF-"), ("f.svg", b"<?xml")])
def test_save_figure_writes_that_format(tmp_path, name, magic):
    fig, axes = new_figure()
    axes[0, 0].plot([0, 1], [0, 1])
    assert save_figure(fig, tmp_path / name).read_bytes().startswith(magic)


def test_save_figure_refuses_before_writing(tmp_path):
    fig, _ = new_figure()
    with pytest.raises(SceneError):
        save_figure(fig, tmp_path / "f.jpg")
    assert list(tmp_path.iterdir()) == []


def test_the_run_plot_zooms_on_the_first_impact():
    result = simulate(model_ii(), 1.0, "draft")
    impact = result.impacts[0]
    axes = plot_result(result).axes
    # positions, contact forces, force on the mount, velocities, first impact
    assert len(axes) == 5
    zoom = axes[-1]
    assert zoom.get_xlabel() == "time [ms]" and "first impact" in zoom.get_title()
    low, high = zoom.get_xlim()
    assert low < impact.start * 1e3 < impact.end * 1e3 < high < 2 * impact.end * 1e3
    labels = [line.get_label() for line in zoom.get_lines()]
    assert "force on the mount" in labels and any("peak" in label for label in labels)
    assert axes[2].get_ylabel() == "force on the mount [kN]"


def test_without_impacts_there_is_no_zoom():
    axes = plot_result(simulate(simplified_model(), 1.0, "draft")).axes
    assert len(axes) == 3 and axes[-1].get_xlabel() == "time [s]"


def test_a_declared_history_with_a_panel_gets_one_after_the_velocities(monkeypatch):
    """The recoil spring given (for this test) a declared force history F = k x_M on a panel in kN: a fourth panel
    after the velocities, holding k x_M / 1000 (on the densified histories drawn), with the time axis label moved
    to it."""
    import numpy as np

    from mbs_models.elements.declaration import History, Outputs
    from mbs_models.elements.recoil_spring import RecoilSpring

    monkeypatch.setattr(RecoilSpring, "OUTPUTS", Outputs(histories=(
        History("force", "N", lambda run: run.force(), panel="spring force [kN]", scale=1e-3),)))
    scene = simplified_model()
    result = simulate(scene, 1.0, "draft")
    axes = plot_result(result).axes
    assert len(axes) == 4 and axes[2].get_ylabel() == "velocity [m/s]" and axes[3].get_ylabel() == "spring force [kN]"
    (line,) = axes[3].get_lines()
    assert line.get_label() == "recoil spring force"
    expected = scene.recoil_spring.stiffness * result.densified().barrel_position / 1e3
    assert np.asarray(line.get_ydata()) == pytest.approx(expected, rel=1e-12, abs=1e-12)
    assert axes[3].get_xlabel() == "time [s]" and axes[2].get_xlabel() == ""


def test_the_barrel_displacement_legends_are_in_the_axis_unit():
    """Figs 6-8: the y axis is in mm, so the legend's maximum is too (it once gave metres)."""
    import re

    from mbs_models.results.plotting import plot_barrel_displacements

    results = [simulate(simplified_model(), 0.6, "draft"), simulate(model_ii(), 0.6, "draft")]
    ax = plot_barrel_displacements(results, title="t").axes[0]
    assert ax.get_ylabel().endswith("[mm]")
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert len(labels) == 2
    for label, result in zip(labels, results):
        value, unit = re.search(r"max ([\d.]+) (\w+)", label).groups()
        assert unit == "mm", label
        # printed to 0.1 mm: within half of that of the result's maximum in mm
        assert abs(float(value) - result.max_barrel_displacement * 1e3) <= 0.05 + 1e-9, label


def _history_lines(fig):
    """The lines of every time-history panel (x in s), the impact zoom's (x in ms) apart, and the markers."""
    return [line for ax in fig.axes if ax.get_xlabel() != "time [ms]" for line in ax.get_lines()
            if len(line.get_xdata()) > 2]


def test_the_run_plot_draws_dense_histories_or_the_solver_s_points():
    """A 10 s ``standard`` run (steps up to 20 ms): every history line is drawn through times at most 1 ms apart,
    the step-end samples among them; ``step_ends=True`` draws the solver's points themselves."""
    import numpy as np

    result = simulate(model_ii(1000.0, 0.0), 10.0)
    assert np.max(np.diff(result.time)) > 1.9e-2
    lines = _history_lines(plot_result(result))
    assert len(lines) >= 5
    for line in lines:
        x = np.asarray(line.get_xdata())
        assert np.max(np.diff(x)) <= 1e-3 + 1e-14 and np.all(np.isin(result.time, x))
    for line in _history_lines(plot_result(result, step_ends=True)):
        np.testing.assert_array_equal(line.get_xdata(), result.time)


def test_the_paper_figures_draw_dense_histories():
    import numpy as np

    from mbs_models.results.plotting import plot_barrel_displacements, plot_contact_histories, plot_first_impact

    results = [simulate(model_ii(1000.0, 0.0), 4.0)]
    for fig in (plot_barrel_displacements(results, title="x"), plot_contact_histories(results, "absorber_velocity",
                                                                                      title="v"),
                plot_first_impact(results, title="F", interval=2e-4)):
        lines = [line for ax in fig.axes for line in ax.get_lines() if len(line.get_xdata()) > 2]
        assert lines
        for line in lines:
            x = np.asarray(line.get_xdata())
            gap = 2e-4 * 1e3 if "ms" in line.axes.get_xlabel() else 1e-3
            assert np.max(np.diff(x)) <= gap * (1 + 1e-9)
