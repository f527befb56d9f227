"""The reference's variable-recoil brake (terms/recoil_brake.py ``areas_at``) against the engine on a banded scene."""

from __future__ import annotations

from mbs_models.scene.io import load_scene, scene_from_dict, scene_to_dict
from mbs_models.scenes import scene_path
from validation.studies.compare import compare


def test_engine_and_reference_agree_on_a_banded_brake_at_45_degrees():
    data = scene_to_dict(load_scene(scene_path("towed_howitzer_45")))
    data["recoil_brake"]["band"] = [{"up_to": 30.0, "orifice_area": 4e-4}, {"up_to": 60.0, "orifice_area": 2e-4}]
    comparison = compare(scene_from_dict(data), end_time=1.0)
    assert comparison.passed, comparison.table()
