"""mbs_models/results/optimise_plots.py: the optimisation figure's title stays inside the figure."""

from __future__ import annotations

from mbs_models import model_i
from mbs_models.results.optimise_plots import plot_optimisation, wrap_to_figure
from mbs_models.results.plotting import new_figure
from mbs_models.studies.optimise import optimise


def _inside(fig, text) -> bool:
    """Whether the drawn ``text``'s bounding box lies within ``fig``'s (display pixels)."""
    fig.canvas.draw()
    box, frame = text.get_window_extent(), fig.bbox
    return box.x0 >= frame.x0 and box.x1 <= frame.x1 and box.y0 >= frame.y0 and box.y1 <= frame.y1


def test_the_title_of_a_two_parameter_optimisation_lies_inside_the_figure():
    scene = model_i(1000.0, 0.0).with_changes(name="model (i) with a long descriptive name, m = 1000 kg, gap 0 mm")
    result = optimise(scene, {"contact.gap": (0.0, 0.12), "absorber.mass": (100.0, 2000.0)},
                      "max_barrel_displacement", ["peak_support_force<=6020"], seed=1, popsize=2, maxiter=1,
                      workers=1)
    fig = plot_optimisation(result)
    assert "\n" in fig._suptitle.get_text()          # too long for one line: wrapped
    assert _inside(fig, fig._suptitle)


def test_a_short_title_stays_on_one_line():
    fig, _ = new_figure(1, 2, width=11.0)
    assert wrap_to_figure("minimise x over y", fig, 11) == "minimise x over y"
