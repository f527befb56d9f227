"""TOML scenes shipped with the package: the paper's three models (m = 1000 kg, gap 0) and examples of
every element.

``scene_path("model_ii")`` gives the file path; ``list_scenes()`` the names; ``describe_scenes()`` each
name with its one-line description (the file's ``name``: what ``recoil scenes`` lists);
``closest_scene(name)`` and ``unknown_scene(name)`` the "did you mean" for a name that is none of them.
"""

from __future__ import annotations

import difflib
import tomllib
from pathlib import Path

_HERE = Path(__file__).resolve().parent


def list_scenes() -> list[str]:
    """Names of the shipped scenes (file stems)."""
    return sorted(p.stem for p in _HERE.glob("*.toml"))


def describe_scenes() -> list[tuple[str, str]]:
    """``(name, description)`` of every shipped scene, by name: the description is the file's ``name``."""
    out = []
    for name in list_scenes():
        data = tomllib.loads((_HERE / f"{name}.toml").read_text(encoding="utf-8"))
        out.append((name, str(data.get("name", ""))))
    return out


def closest_scene(name: str) -> str | None:
    """The shipped scene's name closest to ``name`` (difflib, ratio >= 0.6; ``name`` itself if shipped), or None."""
    close = difflib.get_close_matches(name, list_scenes(), n=1, cutoff=0.6)
    return close[0] if close else None


def unknown_scene(name: str) -> str:
    """Why ``name`` is no shipped scene: the closest name as a "did you mean", else every name."""
    close = closest_scene(name)
    if close is not None:
        return f"no shipped scene {name!r}; did you mean {close!r}? ('recoil scenes' lists them)"
    return f"no shipped scene {name!r}; the shipped scenes are {', '.join(list_scenes())}"


def scene_path(name: str) -> Path:
    """Path of a shipped scene file, e.g. ``scene_path("simplified")``; SceneError with a "did you mean"."""
    path = _HERE / f"{name}.toml"
    if not path.is_file():
        from ..errors import SceneError
        raise SceneError("scene", unknown_scene(name))
    return path
