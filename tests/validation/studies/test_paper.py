"""The paper's published numbers (validation.studies.paper) and how the scipy reference compares with them."""

import functools

import pytest

from mbs_models.scene import models
from validation import PublishedValue, published_values, qualitative_claims, solve_reference, table2
from validation.studies.paper import MODEL_I, MODEL_II, SIMPLIFIED, TABLE2_MASSES, published


def test_table2_has_every_cell():
    t = table2()
    assert len(t) == 9
    expected = {SIMPLIFIED: (0.2215, 0.2215, 0.2215), MODEL_I: (0.2163, 0.2151, 0.2072),
                MODEL_II: (0.2215, 0.1826, 0.1504)}
    for model, values in expected.items():
        for mass, value in zip((100.0, 500.0, 1000.0), values):
            pv = t[(model, mass)]
            assert isinstance(pv, PublishedValue)
            assert pv.value == value and pv.unit == "m" and pv.source == "Table 2"
            assert pv.quantity == "max_barrel_displacement" and pv.absorber_mass == mass


def test_published_values_are_sourced_and_unique():
    values = published_values()
    keys = [(v.quantity, v.model, v.absorber_mass) for v in values]
    assert len(keys) == len(set(keys))
    for v in values:
        assert v.source and v.unit is not None and isinstance(v.value, float)
        assert any(word in v.source for word in ("Table", "Section", "Eq.", "Fig"))


def test_section_2_2_values():
    assert published("peak_contact_force", MODEL_I, 1000.0).value == 114.4e3
    assert published("peak_contact_force", MODEL_II, 1000.0).value == 116.7e3
    assert published("max_absorber_velocity", MODEL_I, 1000.0).value == 1.082
    assert published("max_absorber_velocity", MODEL_II, 1000.0).value == 1.079
    assert published("time_of_max_absorber_velocity", MODEL_I, 1000.0).value == 0.01484
    assert published("time_of_max_absorber_velocity", MODEL_II, 1000.0).value == 0.01495
    assert published("initial_velocity").value == 0.7
    with pytest.raises(KeyError):
        published("peak_contact_force", SIMPLIFIED)


def test_parameters_agree_with_the_shipped_models():
    pairs = {"barrel_mass": models.PAPER_BARREL_MASS, "projectile_mass": models.PAPER_PROJECTILE_MASS,
             "muzzle_velocity": models.PAPER_MUZZLE_VELOCITY, "recoil_stiffness": models.PAPER_RECOIL_STIFFNESS,
             "recoil_damping": models.PAPER_RECOIL_DAMPING,
             "counter_recoil_damping": models.PAPER_COUNTER_RECOIL_DAMPING,
             "contact_stiffness": models.PAPER_CONTACT_STIFFNESS, "contact_exponent": models.PAPER_CONTACT_EXPONENT,
             "contact_damping_factor": models.PAPER_CONTACT_DAMPING_FACTOR,
             "absorber_stiffness": models.PAPER_ABSORBER_STIFFNESS,
             "absorber_damping": models.PAPER_ABSORBER_DAMPING}
    for quantity, value in pairs.items():
        assert published(quantity).value == value, quantity
    assert TABLE2_MASSES == models.PAPER_ABSORBER_MASSES


def test_qualitative_claims_are_well_formed():
    claims = qualitative_claims()
    keys = [c.key for c in claims]
    assert len(keys) == len(set(keys))
    for c in claims:
        assert c.text and c.predicate and c.source.startswith("Section")
    for key in ("ii_max_at_gap_zero", "i_second_impact_late", "ii_second_impact_early",
                "i_m100_close_to_simplified", "first_peaks_similar", "max_velocities_same"):
        assert key in keys


# ------------------------------------------------------------------ the reference against the paper
@functools.lru_cache(maxsize=None)
def ref(model: str, mass: float = 1000.0):
    scene = {SIMPLIFIED: lambda m: models.simplified_model(), MODEL_I: models.model_i,
             MODEL_II: models.model_ii}[model](mass)
    return solve_reference(scene, 10.0)


def test_table2_reference_values():
    print("\nTable 2 (gap 0, 10 s): model, m, reference, paper")
    for (model, mass), pv in table2().items():
        x = ref(model, mass).max_barrel_displacement
        print(f"  {model:11s} {mass:6.0f} kg  {x:.5f} m  {pv.value:.4f} m  ({(x / pv.value - 1) * 100:+.2f} %)")
    # the cells where the equations as written reproduce the paper to within 0.5 %
    for key in ((SIMPLIFIED, 1000.0), (MODEL_I, 500.0), (MODEL_I, 1000.0), (MODEL_II, 1000.0)):
        assert ref(*key).max_barrel_displacement == pytest.approx(table2()[key].value, rel=5e-3), key


def test_contact_claims_hold_for_the_reference():
    ri, rii = ref(MODEL_I), ref(MODEL_II)
    # first peaks similar (Section 2.2): 114.4 vs 116.7 kN in the paper
    assert abs(ri.peak_contact_force / rii.peak_contact_force - 1) < 0.05
    # maximum absorber velocities practically the same (Section 2.2)
    assert abs(ri.max_absorber_velocity / rii.max_absorber_velocity - 1) < 0.01
    # time of max velocity ~ duration of the first contact (Section 2.2)
    for r in (ri, rii):
        first = r.impacts[0]
        assert abs(r.time_of_max_absorber_velocity - first.end) < 0.1 * first.duration
    # second impact: model (i) > 1.5 s after the first, model (ii) < 0.5 s (Section 3)
    assert ri.impacts[1].start - ri.impacts[0].start > 1.5
    assert rii.impacts[1].start - rii.impacts[0].start < 0.5
    # later peaks of model (i) much smaller (Section 2.2) and model (ii) absorbs more (Section 3)
    assert ri.impacts[1].peak_force < 0.5 * rii.impacts[1].peak_force
    absorbed = {k: r.dissipated_energy["absorber_damper"] + r.dissipated_energy["contact"]
                for k, r in (("i", ri), ("ii", rii))}
    assert absorbed["ii"] > absorbed["i"]
    # the absorber reduces the maximum displacement, more so as m grows (Section 3)
    simplified = ref(SIMPLIFIED).max_barrel_displacement
    for model in (MODEL_I, MODEL_II):
        xs = [ref(model, m).max_barrel_displacement for m in TABLE2_MASSES]
        assert all(x < simplified for x in xs)
        assert xs[0] > xs[1] > xs[2]
