"""Engine vs independent reference on the 19 paper cases, and `recoil validate`."""

from __future__ import annotations

import json

import pytest

from mbs_models import load_scene, model_i, model_ii, simplified_model, simulate
from mbs_models.cli import main
from mbs_models.scenes import list_scenes, scene_path
from validation.reference import solve_reference
from validation.studies.compare import DEFAULT_TOLERANCES, QuantityCheck, compare
from validation.studies.guarantee import TOLERANCES, errors_against_reference

PAPER_CASES = [("simplified", simplified_model, None, None)] + [
    (f"{label}-m{mass:g}-gap{gap * 1000:g}mm", factory, mass, gap)
    for label, factory in (("model-i", model_i), ("model-ii", model_ii))
    for mass in (100.0, 500.0, 1000.0)
    for gap in (0.0, 0.04, 0.08)
]


def test_there_are_19_paper_cases():
    assert len(PAPER_CASES) == 19


@pytest.mark.parametrize("case", PAPER_CASES, ids=[c[0] for c in PAPER_CASES])
def test_engine_agrees_with_reference_on_paper_case(case):
    _, factory, mass, gap = case
    scene = factory() if mass is None else factory(mass, gap)
    comparison = compare(scene, 10.0, "standard")
    assert comparison.check("max_barrel_displacement").relative_error <= 1e-4
    if scene.has_absorber:
        assert comparison.check("peak_contact_force").relative_error <= 1e-3
        assert comparison.check("max_absorber_velocity").relative_error <= 1e-3
    assert comparison.impacts_match, (comparison.engine_impacts, comparison.reference_impacts)
    assert comparison.passed, comparison.table()


@pytest.mark.parametrize("name", list_scenes())
def test_engine_and_reference_find_the_same_impacts_on_every_contact(name):
    """Every shipped scene (a preload's hold at t = 0, struck stops, bursts, every contact law): each contact has
    the same impacts in both implementations (DESIGN.md: the peak rising above the force at rest the episode
    began with by more than the threshold, written independently on each side), with their start, end and peak
    within the ``standard`` guarantee."""
    scene = load_scene(scene_path(name))
    engine, reference = simulate(scene, 10.0, "standard"), solve_reference(scene, 10.0)
    assert {c: len(o.impacts) for c, o in engine.contacts.items()} == \
        {c: len(o.impacts) for c, o in reference.contacts.items()}
    errors = errors_against_reference(engine, reference, TOLERANCES["standard"]["time"])
    assert errors["impact_mismatch"] == 0
    assert errors["time"] <= TOLERANCES["standard"]["time"] and errors["peaks"] <= TOLERANCES["standard"]["impact_peak"]


def test_quantity_check_verdicts():
    assert QuantityCheck("x", 1.0, 1.0, 0.0, 1e-4).passed
    assert not QuantityCheck("x", 1.1, 1.0, 0.1, 1e-4).passed
    assert QuantityCheck("x", None, None, None, 1e-4).passed  # absent in this scene
    assert not QuantityCheck("x", 1.0, None, None, 1e-4).passed  # present in one only


def test_a_too_tight_tolerance_fails_the_comparison():
    comparison = compare(model_ii(1000.0, 0.0), 1.0, "draft",
                         tolerances={"max_barrel_displacement": 1e-15})
    assert not comparison.passed
    assert "max_barrel_displacement" in comparison.failures


def test_validate_cli_prints_table_and_exit_code(capsys):
    assert main(["validate", "model_ii", "--end-time", "1"]) == 0
    out = capsys.readouterr().out
    assert "max_barrel_displacement" in out and "PASSED" in out
    assert main(["validate", "simplified", "--end-time", "1", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["passed"] is True and data["checks"]


def test_validate_cli_exit_1_on_exceeded_tolerance(capsys, monkeypatch):
    import validation.studies.compare as compare_module
    monkeypatch.setitem(compare_module.DEFAULT_TOLERANCES, "max_barrel_displacement", 0.0)
    assert main(["validate", "model_ii", "--end-time", "0.5", "--accuracy", "draft"]) == 1
    assert "FAILED" in capsys.readouterr().out
    assert DEFAULT_TOLERANCES["max_barrel_displacement"] == 0.0  # the patch was effective


def test_validate_bad_scene_is_exit_2(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text("[barrel]\nmass = -1\n")
    assert main(["validate", str(path)]) == 2


# ------------------------------------------------------------------ the carriage (planar model)
class _PlanarEngine:
    """An engine result of a carriage scene with the engine's interface (``Result.metrics()``, ``supports``,
    ``carriage_position`` (n, 2), ``carriage_pitch`` (n,) on ``time``), sampled from a reference result."""

    def __init__(self, reference, pitch_scale=1.0, supports=True, metrics=True):
        import numpy as np
        self.scene, self.end_time = reference.scene, reference.end_time
        self.time = np.linspace(0.0, reference.end_time, 4001)
        self.positions = {b: reference.position(b, self.time) for b in reference.bodies}
        self.velocities = {b: reference.velocity(b, self.time) for b in reference.bodies}
        self.contacts = {}
        for name in ("max_barrel_displacement", "time_of_max_barrel_displacement", "peak_support_force",
                     "peak_contact_force", "max_absorber_velocity", "time_of_max_absorber_velocity", "time_to_battery"):
            setattr(self, name, getattr(reference, name))
        self._metrics = reference.metrics() if metrics else {}
        self.supports = reference.supports() if supports else None
        self.carriage_position = reference.carriage_position(self.time).T
        phi0 = reference.carriage_pitch(0.0)
        self.carriage_pitch = phi0 + pitch_scale * (reference.carriage_pitch(self.time) - phi0)

    def metrics(self):
        return self._metrics


@pytest.fixture(scope="module")
def carriage_reference():
    from planar_scenes import carriage_scene
    return solve_reference(carriage_scene(), 0.1, method="LSODA")


def test_a_carriage_comparison_checks_the_carriages_quantities(carriage_reference):
    from validation.studies.compare import CARRIAGE_METRICS, compare_results
    comparison = compare_results(_PlanarEngine(carriage_reference), carriage_reference)
    names = [c.name for c in comparison.checks]
    assert set(CARRIAGE_METRICS) <= set(names)
    assert {"support.spade.min_normal_force", "support.wheels.max_normal_force", "carriage_pitch_history",
            "carriage_position_history"} <= set(names)
    assert comparison.passed, comparison.table()
    assert comparison.check("max_carriage_pitch").unit == "rad" and comparison.check("lift_off_time").unit == "s"
    assert comparison.check("stability_margin").unit == "1" and comparison.check("max_lift").unit == "m"
    assert "carriage_pitch_history" in comparison.table()


@pytest.mark.parametrize("change, failing", [({"pitch_scale": 1.01}, "carriage_pitch_history"),
                                             ({"supports": False}, "support.wheels.min_normal_force"),
                                             ({"metrics": False}, "stability_margin")])
def test_a_carriage_comparison_fails_on_a_wrong_or_missing_quantity(carriage_reference, change, failing):
    from validation.studies.compare import compare_results
    comparison = compare_results(_PlanarEngine(carriage_reference, **change), carriage_reference)
    assert not comparison.passed and failing in comparison.failures


# ------------------------------------------------------------------ engine = reference on the carriage scenes
#: The shipped carriage scenes over the time `recoil paper` shows them (the shot, the counter-recoil, the landing).
SHIPPED_CARRIAGE = {"towed_howitzer": 3.0, "towed_howitzer_45": 3.0}


@pytest.fixture(scope="module")
def shipped_carriage_references():
    """The reference of each shipped carriage scene, solved once (~1-2 s each) for the three presets."""
    return {}


@pytest.mark.parametrize("preset", ["draft", "standard", "reference"])
@pytest.mark.parametrize("name", list(SHIPPED_CARRIAGE))
def test_engine_agrees_with_reference_on_the_shipped_carriage_scenes(shipped_carriage_references, name, preset):
    """Every quantity within the preset's tolerances (CARRIAGE_TOLERANCES; the 1-D ones at DEFAULT_TOLERANCES), the
    same impacts, and the carriage's quantities compared at all: the supports, the histories, the metrics."""
    from validation.studies.compare import compare_results
    scene, end = load_scene(scene_path(name)), SHIPPED_CARRIAGE[name]
    if name not in shipped_carriage_references:
        shipped_carriage_references[name] = solve_reference(scene, end)
    comparison = compare_results(simulate(scene, end, preset), shipped_carriage_references[name], accuracy=preset)
    assert comparison.passed, comparison.table()
    names = {c.name for c in comparison.checks if c.relative_error is not None}
    assert {"stability_margin", "support.spade.min_normal_force", "support.wheels.max_normal_force",
            "carriage_pitch_history", "carriage_position_history"} <= names


def _hard_case(name):
    from carriage_scenes import grazing_scene, jump_scene, slipping_scene
    return {"grazing": (grazing_scene, 1.0), "jump": (jump_scene, 2.0), "slipping": (slipping_scene, 1.0)}[name]


@pytest.mark.parametrize("name", ["grazing", "slipping",
                                  pytest.param("jump", marks=pytest.mark.slow)])  # the jump's reference: ~13 s
def test_engine_agrees_with_reference_on_the_planar_hard_cases(name):
    """tests/engine/test_planar_hard_cases.py's scenes at ``standard``: a skid carrying nothing at rest that the
    pitching touches, a jump whose spade digs in where it lands (anchor = touchdown), a spade slipping by Coulomb
    friction."""
    from validation.studies.compare import compare_results
    make, end = _hard_case(name)
    scene = make()
    comparison = compare_results(simulate(scene, end, "standard"), solve_reference(scene, end), accuracy="standard")
    assert comparison.passed, comparison.table()
    if name == "grazing":  # the skid: no static load, touched, and not part of the margin
        skid = comparison.check("support.skid.max_normal_force")
        assert skid.reference > 10.0 and comparison.reference.supports()[2]["static_normal_force"] == 0.0
        assert comparison.reference.stability_margin > 0.5
    if name == "jump":    # it lands again: both see the lift and the landing loads
        assert comparison.check("max_lift").reference > 0.05
        assert comparison.check("support.spade.max_normal_force").reference > 100 * 3573.0


def test_the_carriage_tolerances_tighten_with_the_preset():
    from validation.studies.compare import CARRIAGE_TOLERANCES, tolerances_for
    draft, standard, reference = (tolerances_for(p) for p in ("draft", "standard", "reference"))
    for key in CARRIAGE_TOLERANCES["standard"]:
        assert draft[key] >= standard[key] >= reference[key] > 0.0, key
    assert tolerances_for("DOPRI5 rtol=1e-10") == DEFAULT_TOLERANCES == {**DEFAULT_TOLERANCES, **standard}
