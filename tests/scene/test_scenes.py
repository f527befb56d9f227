"""The shipped scenes (mbs_models/scenes): names, descriptions, and a "did you mean" for a name that is none."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

import mbs_models.scenes
from mbs_models import SceneError, load_scene
from mbs_models.scenes import closest_scene, describe_scenes, list_scenes, scene_path

_FILES = sorted(Path(mbs_models.scenes.__file__).parent.glob("*.toml"), key=lambda p: p.stem)


def test_describe_scenes_gives_every_file_with_its_name():
    assert describe_scenes() == [(p.stem, tomllib.loads(p.read_text())["name"]) for p in _FILES]
    assert all(description for _, description in describe_scenes())  # every shipped scene has a name


@pytest.mark.parametrize("typed, meant", [("two_absorber", "two_absorbers"), ("model_iii", "model_ii"),
                                          ("recuperater", "recuperator"), ("simplfied", "simplified")])
def test_a_misspelt_name_gets_the_closest_shipped_one(typed, meant):
    assert closest_scene(typed) == meant
    with pytest.raises(SceneError) as info:
        scene_path(typed)
    assert info.value.key == "scene" and f"did you mean {meant!r}?" in info.value.message


def test_a_name_far_from_all_lists_them():
    assert closest_scene("xyzzy") is None
    with pytest.raises(SceneError) as info:
        scene_path("xyzzy")
    assert info.value.message.endswith(", ".join(p.stem for p in _FILES))


def test_every_listed_name_loads():
    assert list_scenes() == [p.stem for p in _FILES]
    for name in list_scenes():
        load_scene(scene_path(name))
