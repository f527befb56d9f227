"""Reading and writing scenes: the version-1 TOML format of DESIGN.md.

``load_scene(path)`` is the one entry point for files; ``scene_from_dict`` does the checking of keys
(unknown keys with a "did you mean", missing keys, wrong table types) before the dataclasses of
:mod:`mbs_models.scene` check the values.  Every problem is a :class:`SceneError` naming the key.
"""

from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import fields
from pathlib import Path
from typing import Any

from .errors import SceneError
from .scene import Absorber, Barrel, Contact, Conventions, Firing, RecoilDamper, RecoilSpring, Scene

#: The scene format version this library reads and writes.
FORMAT_VERSION = 1

# table name -> (dataclass, required keys); optional keys are the dataclass's other fields.
_TABLES: dict[str, tuple[type, tuple[str, ...]]] = {
    "barrel": (Barrel, ("mass",)),
    "firing": (Firing, ("projectile_mass", "muzzle_velocity")),
    "recoil_spring": (RecoilSpring, ("stiffness",)),
    "recoil_damper": (RecoilDamper, ("recoil", "counter_recoil")),
    "absorber": (Absorber, ("mass", "mount", "stiffness", "damping")),
    "contact": (Contact, ("gap", "stiffness", "exponent", "damping_factor")),
    "conventions": (Conventions, ()),
}
_REQUIRED_TABLES = ("barrel", "recoil_spring", "recoil_damper")
_TOP_LEVEL_SCALARS = ("name", "version")


def _unknown(key: str, allowed: list[str]) -> SceneError:
    leaf = key.rsplit(".", 1)[-1]
    close = difflib.get_close_matches(leaf, allowed, n=1, cutoff=0.6)
    hint = f"; did you mean {close[0]!r}?" if close else f"; allowed: {', '.join(sorted(allowed))}"
    return SceneError(key, f"unknown key{hint}")


def _field_names(cls: type) -> list[str]:
    return [f.name for f in fields(cls)]


def scene_from_dict(data: dict[str, Any]) -> Scene:
    """Build a validated :class:`Scene` from the parsed TOML mapping (version 1)."""
    if not isinstance(data, dict):
        raise SceneError("", "a scene must be a table of tables")
    allowed_top = list(_TABLES) + list(_TOP_LEVEL_SCALARS)
    for key in data:
        if key not in allowed_top:
            raise _unknown(key, allowed_top)
    version = data.get("version", FORMAT_VERSION)
    if isinstance(version, bool) or version != FORMAT_VERSION:
        raise SceneError("version", f"unsupported scene format version {version!r}; this library reads {FORMAT_VERSION}")
    for table in _REQUIRED_TABLES:
        if table not in data:
            raise SceneError(table, f"missing required table [{table}]")

    parts: dict[str, Any] = {}
    for table, (cls, required) in _TABLES.items():
        if table not in data:
            continue
        content = data[table]
        if not isinstance(content, dict):
            raise SceneError(table, f"must be a table [{table}], got {type(content).__name__}")
        names = _field_names(cls)
        for key in content:
            if key not in names:
                raise _unknown(f"{table}.{key}", names)
        for key in required:
            if key not in content:
                raise SceneError(f"{table}.{key}", "missing required key")
        parts[table] = cls(**content)

    name = data.get("name", "unnamed scene")
    return Scene(name=name, **parts)


def load_scene(path: str | Path) -> Scene:
    """Read a scene TOML file; raise :class:`SceneError` for unreadable, malformed or invalid files."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SceneError("", f"scene file not found: {path}") from None
    except IsADirectoryError:
        raise SceneError("", f"scene path is a directory, not a file: {path}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError("", f"cannot read scene file {path}: {exc}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError("", f"malformed TOML in {path}: {exc}") from None
    return scene_from_dict(data)


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """The TOML mapping of a scene (inverse of :func:`scene_from_dict`); omits absent tables."""
    out: dict[str, Any] = {"version": FORMAT_VERSION, "name": scene.name}
    for table in _TABLES:
        part = getattr(scene, table)
        if part is None:
            continue
        values = {f.name: getattr(part, f.name) for f in fields(part)}
        values = {k: v for k, v in values.items() if v is not None}
        if table == "conventions":
            values = {k: v for k, v in values.items() if v}
            if not values:
                continue
        out[table] = values
    return out


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if not math.isfinite(value):
            raise SceneError("", f"cannot write non-finite number {value}")
        return repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    raise TypeError(f"cannot write {type(value).__name__} to TOML")


def scene_to_toml(scene: Scene) -> str:
    """Serialise a scene to version-1 TOML text (round-trips through :func:`load_scene`)."""
    data = scene_to_dict(scene)
    lines = [f"version = {data.pop('version')}", f"name = {_toml_value(data.pop('name'))}"]
    for table, values in data.items():
        lines.append("")
        lines.append(f"[{table}]")
        lines.extend(f"{key} = {_toml_value(value)}" for key, value in values.items())
    return "\n".join(lines) + "\n"
