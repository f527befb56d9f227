"""The install: the lock of tested versions covers every dependency within pyproject.toml's ranges, the
set-up script installs with it, and the test extra holds what the tests import."""

from __future__ import annotations

import ast
import re
import sys
import tomllib
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
LOCK = ROOT / "requirements" / "lock.txt"


def _locked() -> dict[str, str]:
    pins = {}
    for line in LOCK.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            name, version = line.split("==")
            pins[canonicalize_name(name)] = version
    return pins


def _requirements() -> list[Requirement]:
    project = PYPROJECT["project"]
    out = [Requirement(r) for r in project["dependencies"]]
    for extra in project["optional-dependencies"].values():
        out += [Requirement(r) for r in extra]
    return out


@pytest.mark.parametrize("requirement", _requirements(), ids=str)
def test_the_lock_pins_every_dependency_within_its_range(requirement):
    pins = _locked()
    name = canonicalize_name(requirement.name)
    assert name in pins, f"{requirement.name} is not in {LOCK.name}"
    assert requirement.specifier.contains(pins[name], prereleases=True), (requirement, pins[name])


def test_the_setup_script_installs_with_the_lock():
    setup = (ROOT / "scripts" / "_setup.sh").read_text()
    assert 'LOCK=requirements/lock.txt' in setup and '-c "$LOCK"' in setup
    assert re.search(r'-e "\.\[test,cluster,parquet\]"', setup)


def _imported_top_level(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", "") == "importorskip" and node.args \
                and isinstance(node.args[0], ast.Constant):
            names.add(node.args[0].value.split(".")[0])
    return names


def test_the_test_extra_holds_what_the_tests_import():
    """Every third-party module a test imports is the project's dependency or in its ``test`` extra."""
    project = PYPROJECT["project"]
    tested = project["dependencies"] + project["optional-dependencies"]["test"]
    provided = {canonicalize_name(Requirement(r).name) for r in tested}
    provided |= {"pytest", "packaging"}  # packaging comes with pytest
    ours = {"mbs_models", "validation", "recorded", "conftest", "extreme_values"}
    imported = set().union(*(_imported_top_level(p) for p in (ROOT / "tests").rglob("*.py")))
    third_party = {m for m in imported - ours if m not in sys.stdlib_module_names and not m.startswith("_")}
    modules = {"dask": "dask", "pyarrow": "pyarrow", "yaml": "pyyaml"}  # module name -> distribution
    missing = {m for m in third_party if canonicalize_name(modules.get(m, m)) not in provided}
    assert not missing, f"tests import {sorted(missing)}, which the test extra does not install"
