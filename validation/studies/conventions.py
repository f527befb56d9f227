"""Convention study: what each literal reading of the paper gives against its published numbers.

Each reading is a flag of :class:`mbs_models.scene.Conventions` (all off by default).  For each one
alone (and the default), Table 2 (gap 0), the Section 2.2 first-impact numbers (m = 1000 kg) and
the Fig. 5 trend (model (ii), m = 1000 kg, gaps 0 / 40 / 80 mm) are computed with the independent
reference; the engine runs the same scenes so that its agreement is shown for every case (a reading
the engine cannot integrate -- a sticking contact -- is reported as such, not hidden).  Every run
stops as soon as its energy bounds prove the studied peak metrics final (the values are those of
the full 10 s run; see :mod:`validation.reference.finality` and :mod:`mbs_models.engine.final_metrics`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

from mbs_models import Conventions, model_i, model_ii, simplified_model, simulate
from mbs_models.errors import SimulationError
from mbs_models.scene import Scene
from mbs_models.studies.sweep import parallel_map

from .paper import MODEL_I, MODEL_II, SIMPLIFIED, TABLE2_MASSES, published, table2
from .progress import named
from ..reference import solve_reference

#: (label, conventions) of the readings studied: the default and each flag alone.
CONVENTION_CASES: tuple[tuple[str, Conventions], ...] = (("default", Conventions()),) + tuple(
    (f.name, Conventions(**{f.name: True})) for f in fields(Conventions))

#: Section 2.2 quantities compared: (metric name, published quantity name).
SECTION22 = (("peak_contact_force", "peak_contact_force"), ("max_absorber_velocity", "max_absorber_velocity"),
             ("time_of_max_absorber_velocity", "time_of_max_absorber_velocity"))
TREND_GAPS = (0.0, 0.04, 0.08)


def _cases(conventions: Conventions) -> dict[tuple, Scene]:
    scenes: dict[tuple, Scene] = {("table2", SIMPLIFIED, 0.0): simplified_model(conventions)}
    for label, factory in ((MODEL_I, model_i), (MODEL_II, model_ii)):
        for mass in TABLE2_MASSES:
            scenes[("table2", label, mass)] = factory(mass, 0.0, conventions)
    for gap in TREND_GAPS[1:]:
        scenes[("trend", MODEL_II, gap)] = model_ii(1000.0, gap, conventions)
    return scenes


def _metrics(source) -> dict:
    return {"max_barrel_displacement": source.max_barrel_displacement,
            "peak_contact_force": source.peak_contact_force,
            "max_absorber_velocity": source.max_absorber_velocity,
            "time_of_max_absorber_velocity": source.time_of_max_absorber_velocity}


#: What the study needs; both solvers stop once these are proven final (the time of the maximum absorber
#: velocity comes with it).  Scenes without an energy bound (literal_lambda_sign) run the full 10 s.
STUDIED_METRICS = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity")


def _reference_job(scene: Scene) -> dict:
    return _metrics(solve_reference(scene, 10.0, stop_when_final=STUDIED_METRICS))


def _engine_job(scene: Scene) -> dict:
    try:
        return _metrics(simulate(scene, 10.0, "standard", stop_when_final=STUDIED_METRICS))
    except SimulationError as exc:
        return {"error": str(exc)}


@dataclass
class ConventionRow:
    """One reading: reference values per case, engine agreement, and errors against the paper."""

    label: str
    conventions: Conventions
    reference: dict[tuple, dict] = field(repr=False)
    engine: dict[tuple, dict] = field(repr=False)

    def value(self, key: tuple, metric: str = "max_barrel_displacement") -> float | None:
        return self.reference[key][metric]

    def table2_errors(self) -> dict[tuple[str, float], float]:
        """Relative error against every Table 2 cell with an absorber (model, mass) -> (ours - paper)/paper."""
        published_table = table2()
        return {(model, mass): (self.value(("table2", model, mass)) - published_table[(model, mass)].value)
                / published_table[(model, mass)].value
                for model in (MODEL_I, MODEL_II) for mass in TABLE2_MASSES}

    def section22_errors(self) -> dict[tuple[str, str], float]:
        """Relative error of the Section 2.2 numbers (m = 1000 kg): (model, quantity) -> (ours - paper)/paper."""
        out = {}
        for model in (MODEL_I, MODEL_II):
            for metric, quantity in SECTION22:
                paper = published(quantity, model, 1000.0).value
                out[(model, metric)] = (self.value(("table2", model, 1000.0), metric) - paper) / paper
        return out

    def rms_error(self) -> float:
        """Root-mean-square relative error over the 6 Table 2 cells and the 6 Section 2.2 numbers."""
        errors = list(self.table2_errors().values()) + list(self.section22_errors().values())
        return math.sqrt(sum(e * e for e in errors) / len(errors))

    def trend(self) -> list[float]:
        """Model (ii), m = 1000 kg: max barrel displacement at gaps 0, 40, 80 mm (Fig. 5's claim)."""
        return [self.value(("table2", MODEL_II, 1000.0))] + [self.value(("trend", MODEL_II, g)) for g in TREND_GAPS[1:]]

    def engine_errors(self) -> dict[tuple, float | str]:
        """Engine vs reference, relative error of max barrel displacement per case (or the engine's failure)."""
        out: dict[tuple, float | str] = {}
        for key, ref in self.reference.items():
            eng = self.engine[key]
            if "error" in eng:
                out[key] = eng["error"]
            else:
                out[key] = abs(eng["max_barrel_displacement"] - ref["max_barrel_displacement"]) / \
                    ref["max_barrel_displacement"]
        return out

    def to_dict(self) -> dict:
        key_name = lambda k: f"{k[0]}:{k[1]}:{k[2]:g}"  # noqa: E731
        return {
            "label": self.label, "flags": list(self.conventions.active),
            "reference": {key_name(k): v for k, v in self.reference.items()},
            "engine": {key_name(k): v for k, v in self.engine.items()},
            "table2_relative_errors": {f"{m}:{mass:g}": e for (m, mass), e in self.table2_errors().items()},
            "section22_relative_errors": {f"{m}:{q}": e for (m, q), e in self.section22_errors().items()},
            "rms_relative_error": self.rms_error(), "fig5_trend_model_ii_m1000": self.trend(),
        }


def convention_jobs(cases=CONVENTION_CASES) -> list[tuple[int, tuple, Scene]]:
    """``(reading index, case key, scene)`` of every run of the study: each scene is run by the reference
    (:func:`reference_job`) and by the engine (:func:`engine_job`)."""
    jobs: list[tuple[int, tuple, Scene]] = []
    for index, (_, conventions) in enumerate(cases):
        jobs += [(index, key, scene) for key, scene in _cases(conventions).items()]
    return jobs


reference_job, engine_job = _reference_job, _engine_job


def convention_rows(cases, jobs, reference: list[dict], engine: list[dict]) -> list[ConventionRow]:
    """One row per reading from the results of :func:`convention_jobs` (``reference`` and ``engine`` in
    the jobs' order)."""
    rows = []
    for index, (label, conventions) in enumerate(cases):
        mine = [(key, ref, eng) for (i, key, _), ref, eng in zip(jobs, reference, engine) if i == index]
        rows.append(ConventionRow(label, conventions, {k: r for k, r, _ in mine}, {k: e for k, _, e in mine}))
    return rows


def study_conventions(cases=CONVENTION_CASES, *, workers: int | None = None, progress=None) -> list[ConventionRow]:
    """Run every reading (reference and engine, in parallel) and return one row each."""
    jobs = convention_jobs(cases)
    scenes = [scene for _, _, scene in jobs]
    reference = parallel_map(_reference_job, scenes, workers=workers, progress=named(progress, "reference pass"))
    engine = parallel_map(_engine_job, scenes, workers=workers, progress=named(progress, "engine pass"))
    return convention_rows(cases, jobs, reference, engine)
