"""Reproducing the paper with the engine: Table 2 beside the published values, and Figs 6-11.

This module *uses* the Exudyn engine (``mbs_models.simulate``) and the independent reference
(:mod:`validation.reference`); it is the comparison layer, not part of the independent
implementation.  ``recoil paper --out DIR`` calls :func:`write_paper_outputs`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable

from mbs_models import model_i, model_ii, simplified_model, simulate
from mbs_models.outputs import atomic_write_json, atomic_write_text, prepare_output_dir
from mbs_models.plotting import (plot_barrel_displacements, plot_contact_histories, plot_first_impact,
                                 save_figure)
from mbs_models.result import Result
from mbs_models.scene import Scene

from .paper import MODEL_I, MODEL_II, SIMPLIFIED, TABLE2_MASSES, table2
from .reference import solve_reference

#: Simulated time of every paper case, s (Figs 9-10 captions).
PAPER_END_TIME = 10.0

Progress = Callable[[str], None]


def _silent(message: str) -> None:
    pass


def table2_scene(model: str, absorber_mass: float, gap: float = 0.0) -> Scene:
    """The scene of one Table 2 cell (``model`` is a label of :mod:`validation.paper`)."""
    if model == SIMPLIFIED:
        return simplified_model()
    return (model_i if model == MODEL_I else model_ii)(absorber_mass, gap)


@dataclass(frozen=True)
class Table2Row:
    """One cell of Table 2: our engine value, the independent reference, and the paper's value (m)."""

    model: str
    absorber_mass: float
    engine: float
    reference: float
    paper: float

    @property
    def engine_vs_reference(self) -> float:
        """Relative difference engine - reference."""
        return (self.engine - self.reference) / self.reference

    @property
    def difference(self) -> float:
        """Ours minus the paper's value, m."""
        return self.engine - self.paper

    @property
    def relative_difference(self) -> float:
        """(ours - paper) / paper."""
        return self.difference / self.paper

    def to_dict(self) -> dict:
        data = asdict(self)
        data.update(engine_vs_reference=self.engine_vs_reference, difference=self.difference,
                    relative_difference=self.relative_difference)
        return data


def compute_table2(accuracy: str = "standard", end_time: float = PAPER_END_TIME,
                   progress: Progress = _silent) -> list[Table2Row]:
    """Every Table 2 cell at gap 0 with the engine and the reference, beside the paper's value."""
    published = table2()
    rows = []
    simplified_engine = simplified_reference = None
    for model in (SIMPLIFIED, MODEL_I, MODEL_II):
        for mass in TABLE2_MASSES:
            if model == SIMPLIFIED and simplified_engine is not None:
                engine, reference = simplified_engine, simplified_reference
            else:
                progress(f"Table 2: {model}, m = {mass:g} kg")
                scene = table2_scene(model, mass)
                engine = simulate(scene, end_time, accuracy).max_barrel_displacement
                reference = solve_reference(scene, end_time).max_barrel_displacement
                if model == SIMPLIFIED:
                    simplified_engine, simplified_reference = engine, reference
            rows.append(Table2Row(model, mass, engine, reference, published[(model, mass)].value))
    return rows


def table2_markdown(rows: list[Table2Row]) -> str:
    """Table 2 as Markdown: ours, the paper's, the difference, and the engine-vs-reference check."""
    lines = ["| model | m [kg] | ours [m] | paper [m] | ours - paper [mm] | rel. diff. | engine vs reference |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r.model} | {r.absorber_mass:g} | {r.engine:.4f} | {r.paper:.4f} | "
                     f"{r.difference * 1e3:+.2f} | {r.relative_difference * 100:+.2f} % | "
                     f"{r.engine_vs_reference:+.1e} |")
    return "\n".join(lines) + "\n"


def paper_figures(out: Path, masses=TABLE2_MASSES, accuracy: str = "standard", end_time: float = PAPER_END_TIME,
                  progress: Progress = _silent) -> dict[str, list[Path]]:
    """Figs 6-8 (barrel displacement), 9 (contact force), 10 (absorber velocity), 11 (first impact), per mass."""
    written: dict[str, list[Path]] = {"barrel_displacement": [], "contact_force": [], "absorber_velocity": [],
                                      "first_impact": []}
    simplified = simulate(simplified_model(), end_time, accuracy)
    for mass in masses:
        progress(f"figures: m = {mass:g} kg")
        results: list[Result] = [simulate(factory(mass, 0.0), end_time, accuracy) for factory in (model_i, model_ii)]
        tag = f"m{mass:g}"
        figs = {
            "barrel_displacement": plot_barrel_displacements(
                [simplified, *results], title=f"Maximum barrel displacement, m = {mass:g} kg, gap 0 (Figs 6-8)"),
            "contact_force": plot_contact_histories(
                results, "contact_force", title=f"Contact force between absorber and wall A, m = {mass:g} kg (Fig. 9)"),
            "absorber_velocity": plot_contact_histories(
                results, "absorber_velocity", title=f"Absorber velocity, m = {mass:g} kg (Fig. 10)"),
            "first_impact": plot_first_impact(results, title=f"First impact, m = {mass:g} kg (Fig. 11)"),
        }
        for name, fig in figs.items():
            written[name].append(save_figure(fig, out / f"{name}_{tag}.png"))
    return written


def write_paper_outputs(out: str | Path, accuracy: str = "standard", end_time: float = PAPER_END_TIME,
                        progress: Progress = _silent) -> dict[str, object]:
    """Write ``table2.md``, ``table2.json`` and the PNG figures to ``out``; return what was written."""
    out = prepare_output_dir(out)
    rows = compute_table2(accuracy, end_time, progress)
    header = (f"# Table 2: maximum barrel displacement, gap 0, {end_time:g} s, accuracy '{accuracy}'\n\n"
              "Ours = Exudyn engine; the reference is the independent scipy solution of the same equations.\n"
              "Differences to the paper are reported, not tuned away (see the validation report).\n\n")
    atomic_write_text(out / "table2.md", header + table2_markdown(rows))
    atomic_write_json(out / "table2.json", {"accuracy": accuracy, "end_time": end_time,
                                            "rows": [row.to_dict() for row in rows]})
    figures = paper_figures(out, accuracy=accuracy, end_time=end_time, progress=progress)
    return {"table2": rows, "figures": figures, "out": out}
