"""Declarations of an element (mbs_models/elements/declaration.py): roles, and the run its outputs are computed from."""

from __future__ import annotations

import numpy as np
import pytest

from mbs_models import load_scene, simplified_model
from mbs_models.elements.declaration import ABSORBER, END_STOP, ElementRun, elements_with
from mbs_models.engine.mechanism import Mechanism
from mbs_models.results.samples import Samples
from mbs_models.scenes import scene_path


def test_roles_are_what_the_tables_declare():
    """Model (ii) has one absorber and no stop; the end-stops scene (model (ii) with stops) has its absorber and its two stops."""
    model_ii = load_scene(scene_path("model_ii"))
    assert elements_with(model_ii, ABSORBER) == ["absorber"] and elements_with(model_ii, END_STOP) == []
    stops = load_scene(scene_path("end_stops"))
    assert elements_with(stops, ABSORBER) == ["absorber"]  # model (ii) with stops
    assert sorted(elements_with(stops, END_STOP)) == ["battery_stop", "recoil_stop"]


def test_the_mechanisms_absorbers_and_stops_follow_the_roles():
    mechanism = Mechanism(load_scene(scene_path("two_absorbers")))
    assert [b.name for b in mechanism.absorber_bodies] == [b.name for b in mechanism.bodies[1:]]
    assert len(mechanism.absorber_contacts) == 2 and mechanism.stop_contacts == []


def _run(scene, element: str, x: np.ndarray, v: np.ndarray) -> ElementRun:
    mechanism = Mechanism(scene)
    t = np.linspace(0.0, 1.0, len(x))
    samples = Samples(t, {"barrel": x}, {"barrel": v}, {"barrel": np.zeros_like(x)})
    table = dict(scene.elements())[element]
    return ElementRun(table, element, scene, mechanism, samples, None, {"twice": 2.0 * x})


def test_an_element_run_gives_its_connectors_force_on_the_samples():
    """The simplified model's recoil spring, F = k x_M (k from the scene), on given positions; the damper,
    F = c v (recoil: v > 0)."""
    scene = simplified_model()
    x, v = np.array([0.0, 0.1, 0.2]), np.array([0.5, 0.25, 0.1])
    run = _run(scene, "recoil_spring", x, v)
    assert run.force() == pytest.approx(scene.recoil_spring.stiffness * x, rel=1e-15)
    assert run.history("twice") is run.histories["twice"] and run.time[-1] == 1.0
    damper = _run(scene, "recoil_damper", x, v)
    assert damper.force() == pytest.approx(scene.recoil_damper.recoil * v, rel=1e-15)


def test_an_element_of_several_connectors_must_name_one():
    scene = load_scene(scene_path("model_ii"))
    run = _run(scene, "absorber", np.zeros(2), np.zeros(2))
    assert len(run.connectors()) == 2  # its damper and its contact
    with pytest.raises(ValueError, match="absorber has 2 connectors: name one"):
        run.force()
