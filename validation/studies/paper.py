"""Every number the paper publishes, and its qualitative claims, as data with their sources.

Model labels follow :attr:`mbs_models.scene.Scene.model_label`: ``"simplified"``, ``"model (i)"``,
``"model (ii)"``; ``"all"`` for parameters shared by the three models.  SI units (m, s, kg, N).
"""

from __future__ import annotations

from dataclasses import dataclass

#: The title of the paper replicated (its authors are not given in the copy studied).
PAPER_TITLE = "Analysis of a dynamic system subjected to an impulsive and internal contact force"

SIMPLIFIED, MODEL_I, MODEL_II, ALL = "simplified", "model (i)", "model (ii)", "all"
#: Absorber masses of Table 2 and Figs. 6-8, kg.
TABLE2_MASSES = (100.0, 500.0, 1000.0)


@dataclass(frozen=True)
class PublishedValue:
    """One published number: ``value`` in ``unit`` for ``quantity`` of ``model`` (absorber mass in kg)."""

    quantity: str
    model: str
    absorber_mass: float | None
    value: float
    unit: str
    source: str
    note: str = ""


@dataclass(frozen=True)
class QualitativeClaim:
    """A statement of the paper; ``predicate`` says how to check it on computed metrics (m = 1000 kg,
    gap 0, 10 s, impact threshold 1 kN unless it says otherwise)."""

    key: str
    text: str
    source: str
    predicate: str
    note: str = ""


def _parameters() -> list[PublishedValue]:
    s21, t1 = "Section 2.1", "Table 1"
    return [
        PublishedValue("barrel_mass", ALL, None, 5600.0, "kg", s21, "mass of the tube M"),
        PublishedValue("projectile_mass", ALL, None, 6.86, "kg", s21),
        PublishedValue("muzzle_velocity", ALL, None, 564.0, "m/s", s21, "projectile velocity after firing"),
        PublishedValue("initial_velocity", ALL, None, 0.7, "m/s", s21,
                       "printed, rounded; momentum balance gives 6.86*564/5600 = 0.6909 m/s"),
        PublishedValue("recoil_stiffness", ALL, None, 27500.0, "N/m", s21, "k"),
        PublishedValue("recoil_damping", ALL, None, 6239.0, "N s/m", "Eq. (2), Section 2.1", "c while x_M' > 0"),
        PublishedValue("counter_recoil_damping", ALL, None, 14050.0, "N s/m", "Eq. (3), Section 2.1",
                       "c while x_M' < 0"),
        PublishedValue("contact_stiffness", ALL, None, 2.1e8, "N/m^1.3", t1, "k_c; the paper prints N/m"),
        PublishedValue("contact_exponent", ALL, None, 1.3, "", t1, "n_c"),
        PublishedValue("contact_damping_factor", ALL, None, 0.6, "s/m", t1, "lambda_c = c_c / k_c"),
        PublishedValue("absorber_stiffness", ALL, None, 13500.0, "N/m", t1, "k_r"),
        PublishedValue("absorber_damping", ALL, None, 3675.0, "N s/m", t1, "c_r"),
        PublishedValue("gap_sweep_max", MODEL_I, None, 0.12, "m", "Section 2.1 (Fig. 4)", "gap swept from 0 to 120 mm"),
        PublishedValue("end_time", ALL, 1000.0, 10.0, "s", "Figs. 9-10 captions", "simulated time"),
        PublishedValue("detail_window", MODEL_I, 1000.0, 3.25, "s", "Fig. 9b caption",
                       "window showing the main effective impacts"),
        PublishedValue("detail_window", MODEL_II, 1000.0, 1.15, "s", "Fig. 9d caption",
                       "window showing the main effective impacts"),
    ]


_TABLE2 = {SIMPLIFIED: (0.2215, 0.2215, 0.2215), MODEL_I: (0.2163, 0.2151, 0.2072),
           MODEL_II: (0.2215, 0.1826, 0.1504)}


def table2() -> dict[tuple[str, float], PublishedValue]:
    """Table 2: maximum barrel displacement (m) keyed by ``(model label, absorber mass in kg)``, gap 0."""
    out = {}
    for model, values in _TABLE2.items():
        for mass, value in zip(TABLE2_MASSES, values):
            note = "gap 0 (Figs. 6-8)" + ("; no absorber, repeated per column" if model == SIMPLIFIED else "")
            out[(model, mass)] = PublishedValue("max_barrel_displacement", model, mass, value, "m", "Table 2", note)
    return out


def published_values() -> tuple[PublishedValue, ...]:
    """All published numbers: parameters, Table 2, Section 2.2 contact results (m = 1000 kg, gap 0)."""
    s22 = "Section 2.2"
    results = [
        PublishedValue("peak_contact_force", MODEL_I, 1000.0, 114.4e3, "N", s22 + " (Fig. 9, Fig. 11a)"),
        PublishedValue("peak_contact_force", MODEL_II, 1000.0, 116.7e3, "N", s22 + " (Fig. 9, Fig. 11b)"),
        PublishedValue("max_absorber_velocity", MODEL_I, 1000.0, 1.082, "m/s", s22 + " (Fig. 10)"),
        PublishedValue("max_absorber_velocity", MODEL_II, 1000.0, 1.079, "m/s", s22 + " (Fig. 10)"),
        PublishedValue("time_of_max_absorber_velocity", MODEL_I, 1000.0, 0.01484, "s", s22,
                       "'practically the same as the duration of contact force' (Fig. 11)"),
        PublishedValue("time_of_max_absorber_velocity", MODEL_II, 1000.0, 0.01495, "s", s22,
                       "'practically the same as the duration of contact force' (Fig. 11)"),
    ]
    return tuple(_parameters()) + tuple(table2().values()) + tuple(results)


def published(quantity: str, model: str = ALL, absorber_mass: float | None = None) -> PublishedValue:
    """The one published value matching ``quantity``, ``model`` and ``absorber_mass`` (KeyError if none)."""
    for pv in published_values():
        if pv.quantity == quantity and pv.model == model and (absorber_mass is None or pv.absorber_mass == absorber_mass):
            return pv
    raise KeyError(f"no published {quantity!r} for {model!r}, m = {absorber_mass}")


def qualitative_claims() -> tuple[QualitativeClaim, ...]:
    """The qualitative statements of Sections 2.1, 2.2 and 3 with checkable predicates."""
    C = QualitativeClaim
    return (
        C("ii_max_at_gap_zero", "Model (ii): the maximum displacement of mass M takes place when the gap is zero.",
          "Section 2.1 (Fig. 5)",
          "for m in (100, 500, 1000): argmax over gap in [0, 0.12] m of max_barrel_displacement(model (ii), m, gap)"
          " == 0"),
        C("i_m100_close_to_simplified", "m = 100 kg, gap 0: the difference between the Simplified Model and "
          "model (i) is negligible.", "Section 2.1 (Fig. 6); Section 3",
          "abs(x_max(model (i), 100) - x_max(simplified)) / x_max(simplified) < 0.03",
          "the paper's own numbers differ by 2.3 % (0.2163 vs 0.2215 m)"),
        C("ii_m100_lower_than_simplified", "m = 100 kg, gap 0: a relatively lower maximum displacement for "
          "model (ii) is observed.", "Section 2.1 (Fig. 6)",
          "x_max(model (ii), 100) < x_max(simplified)",
          "contradicts Table 2 and Section 3 (model (ii) at 100 kg is 0.2215 m, 'absolutely the same')"),
        C("ii_m100_equals_simplified", "m = 100 kg: the maximum displacement of mass M in model (ii) is "
          "absolutely the same as in the simplified model.", "Section 3; Table 2",
          "abs(x_max(model (ii), 100) - x_max(simplified)) < 5e-5 m (Table 2's rounding)",
          "contradicts the Fig. 6 sentence of Section 2.1"),
        C("i_difference_grows_with_m", "As mass m increases, the difference between the Simplified Model and "
          "model (i) increases.", "Section 2.1 (Figs. 7-8); Section 3",
          "x_max(model (i), m) strictly decreasing over m = 100, 500, 1000 (gap 0)"),
        C("ii_decreases_with_m", "The maximum displacement of mass M in model (ii) suffers considerable "
          "reduction when mass m is increased.", "Section 2.1 (Figs. 7-8); Section 3",
          "x_max(model (ii), m) strictly decreasing over m = 100, 500, 1000 and "
          "x_max(model (ii), 1000) < 0.8 * x_max(simplified)"),
        C("absorber_reduces_displacement", "The new models reduce the maximum displacement of mass M.",
          "Section 3", "x_max(model, m) <= x_max(simplified) for model in (i), (ii), m in (100, 500, 1000), gap 0"),
        C("first_peaks_similar", "The first peak contact forces of models (i) and (ii) are very similar "
          "(114.4 vs 116.7 kN).", "Section 2.2 (Figs. 9, 11); Section 3",
          "abs(peak_contact_force(i) - peak_contact_force(ii)) / peak_contact_force(ii) < 0.05"),
        C("i_later_peaks_smaller", "The following impact peaks of model (i) are substantially smaller than "
          "those of model (ii).", "Section 2.2 (Fig. 9); Section 3",
          "impacts(i)[1].peak_force < 0.5 * impacts(ii)[1].peak_force (missing second impact counts as 0)"),
        C("max_velocities_same", "Both models yield practically the same maximum absorber velocity "
          "(1.082 vs 1.079 m/s).", "Section 2.2 (Fig. 10)",
          "abs(max_absorber_velocity(i) - max_absorber_velocity(ii)) / max_absorber_velocity(ii) < 0.01"),
        C("vmax_time_is_contact_duration", "The times of maximum absorber velocity are practically the same as "
          "the duration of the contact force.", "Section 2.2 (Fig. 11)",
          "for each model: abs(time_of_max_absorber_velocity - impacts[0].end) / impacts[0].duration < 0.1"),
        C("i_second_impact_late", "Model (i): the next impacts happen more than 1.5 s after the initial impact.",
          "Section 3 (Fig. 9a-b)", "impacts(i)[1].start - impacts(i)[0].start > 1.5 s (or no second impact)"),
        C("ii_second_impact_early", "Model (ii): the next impact happens less than 0.5 s after the first impact.",
          "Section 3 (Fig. 9c-d)", "impacts(ii)[1].start - impacts(ii)[0].start < 0.5 s"),
        C("ii_absorbs_more", "Mass m 'works' much more in model (ii): its absorption of energy is higher than "
          "in model (i).", "Section 3 (Fig. 10)",
          "dissipated_energy['absorber_damper'] + dissipated_energy['contact'] larger for model (ii) than (i)"),
    )
