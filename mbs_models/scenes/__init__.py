"""TOML scenes shipped with the package: the paper's three models (m = 1000 kg, gap 0).

``scene_path("model_ii")`` gives the file path; ``list_scenes()`` the names.
"""

from __future__ import annotations

from pathlib import Path

_HERE = Path(__file__).resolve().parent


def list_scenes() -> list[str]:
    """Names of the shipped scenes (file stems)."""
    return sorted(p.stem for p in _HERE.glob("*.toml"))


def scene_path(name: str) -> Path:
    """Path of a shipped scene file, e.g. ``scene_path("simplified")``."""
    path = _HERE / f"{name}.toml"
    if not path.is_file():
        from ..errors import SceneError
        raise SceneError("scene", f"no shipped scene {name!r}; available: {', '.join(list_scenes())}")
    return path
