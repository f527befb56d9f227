"""A variable-recoil brake: ``[[recoil_brake.band]]`` orifices switched with the elevation (elements/recoil_brake.py
and the reference's term)."""

from __future__ import annotations

import pytest

import mbs_models as m
from mbs_models import SceneError
from mbs_models.elements.recoil_brake import RecoilBrake
from mbs_models.scene.io import load_scene, scene_from_dict, scene_to_dict, scene_to_toml
from mbs_models.scene.overrides import apply_overrides
from mbs_models.scenes import scene_path
from validation.reference.terms.recoil_brake import areas_at

BANDS = [{"up_to": 30.0, "orifice_area": 4e-4}, {"up_to": 60.0, "orifice_area": [[0.0, 2e-4], [0.3, 1e-4]],
                                                 "counter_recoil_orifice_area": 5e-5}]


def _brake(**changes):
    data = dict(piston_area=0.012, orifice_area=3e-4, discharge_coefficient=0.7, fluid_density=870.0,
                counter_recoil_orifice_area=8e-5)
    data.update(changes)
    return RecoilBrake.from_mapping(data, "recoil_brake", 2)


@pytest.mark.parametrize("elevation, recoil, counter", [(-5.0, 4e-4, 8e-5), (30.0, 4e-4, 8e-5),
                                                        (30.5, ((0.0, 2e-4), (0.3, 1e-4)), 5e-5),
                                                        (60.0, ((0.0, 2e-4), (0.3, 1e-4)), 5e-5),
                                                        (75.0, 3e-4, 8e-5)])
def test_the_band_of_the_elevation_gives_the_areas(elevation, recoil, counter):
    """The first band with up_to >= elevation; its counter-recoil area or the brake's; above the last band the
    brake's own.  The engine's table and the reference's term choose alike (written apart)."""
    brake = _brake(band=BANDS)
    acting = brake.at_elevation(elevation)
    assert acting.orifice_area == recoil and acting.counter_recoil_orifice_area == counter and acting.band == ()
    assert areas_at(brake, elevation) == (recoil, counter)
    assert _brake().at_elevation(elevation) == _brake()  # no band: the brake itself


@pytest.mark.parametrize("bands, key", [
    ([{"up_to": 45.0, "orifice_area": 3e-4}, {"up_to": 45.0, "orifice_area": 2e-4}], "recoil_brake.band.1.up_to"),
    ([{"up_to": 100.0, "orifice_area": 3e-4}], "recoil_brake.band.0.up_to"),
    ([{"up_to": 45.0, "orifice_area": -3e-4}], "recoil_brake.band.0.orifice_area"),
    ([{"up_to": 45.0}], "recoil_brake.band.0.orifice_area"),
])
def test_bad_bands_name_the_key(bands, key):
    with pytest.raises(SceneError) as error:
        _brake(band=bands)
    assert error.value.key == key


def test_bands_in_a_scene_file_overrides_and_the_engine(tmp_path):
    data = scene_to_dict(load_scene(scene_path("towed_howitzer_45")))
    data["recoil_brake"]["band"] = BANDS
    scene = scene_from_dict(data)
    path = tmp_path / "banded.toml"
    path.write_text(scene_to_toml(scene))
    assert "[[recoil_brake.band]]" in path.read_text() and load_scene(path) == scene
    wider = apply_overrides(scene, {"recoil_brake.band.1.orifice_area": 4e-4})
    assert wider.recoil_brake.band[1].orifice_area == 4e-4
    # at 45 degrees the second band acts: the run is that of a brake with its areas
    plain = apply_overrides(load_scene(scene_path("towed_howitzer_45")),
                            {"recoil_brake.orifice_area": [[0.0, 2e-4], [0.3, 1e-4]],
                             "recoil_brake.counter_recoil_orifice_area": 5e-5})
    banded_run, plain_run = m.simulate(scene, 1.0), m.simulate(plain, 1.0)
    assert banded_run.max_barrel_displacement == plain_run.max_barrel_displacement
    assert banded_run.max_barrel_displacement < 0.2  # narrower than the scene's own orifice: a shorter recoil
