"""The reference is independent of the engine: what it imports (statically and at run time)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from imports import REPO, imports_of
from mbs_models.scene import Absorber, Barrel, Contact, Firing, RecoilDamper, RecoilSpring, Scene, scene_to_toml

PACKAGE = REPO / "validation" / "reference"
#: third-party distributions the reference may use; besides these only the standard library and itself
ALLOWED_THIRD_PARTY = {"numpy", "scipy"}
OWN = "validation.reference"


def allowed(module: str) -> bool:
    top = module.split(".")[0]
    return (module == OWN or module.startswith(OWN + ".") or top in ALLOWED_THIRD_PARTY
            or top in sys.stdlib_module_names or top == "__future__")


def test_the_allow_list_check_can_fail():
    assert not allowed("mbs_models.scene") and not allowed("exudyn") and not allowed("validation.studies.paper")
    assert not allowed("validation") and not allowed("matplotlib.pyplot")
    assert allowed("numpy.linalg") and allowed("math") and allowed("validation.reference.terms.absorber")


def test_relative_imports_are_resolved():
    modules = [m for _, m in imports_of(PACKAGE / "terms" / "absorber.py")]
    assert "validation.reference.model" in modules and "validation.reference.terms.contact_laws" in modules


def test_every_import_of_the_reference_is_allowed():
    files = sorted(PACKAGE.rglob("*.py"))
    assert len(files) >= 10 and PACKAGE / "terms" / "absorber.py" in files
    bad = [f"{path.relative_to(REPO)}:{line}: {module}" for path in files for line, module in imports_of(path)
           if not allowed(module)]
    assert not bad, "the reference imports outside its allow-list:\n" + "\n".join(bad)


def _run(code: str) -> dict:
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_importing_the_reference_loads_neither_the_engine_nor_exudyn():
    modules = _run("import sys, json, validation.reference, validation.reference.closed_form\n"
                   "print(json.dumps(sorted(sys.modules)))\n")
    assert "validation.reference.terms.absorber" in modules  # the terms are found and loaded
    bad = [m for m in modules if m.split(".")[0] in ("mbs_models", "exudyn")]
    assert not bad, bad


def test_solving_a_scene_file_loads_no_engine(tmp_path, every_element, design_connectors):
    """A scene file of every element (two absorbers of their own and every other shipped table) is solved
    without the engine: the reference reads the scene as data."""
    front = Absorber(500.0, "ground", 6750.0, 1837.5, name="front",
                     contact=Contact(gap=0.0, stiffness=1.05e8, exponent=1.3, damping_factor=0.6))
    rear = Absorber(300.0, "barrel", 5000.0, 1000.0, name="rear",
                    contact=Contact(gap=0.01, law="lankarani-nikravesh", stiffness=1e8, exponent=1.5, restitution=0.6))
    scene = every_element(Scene(barrel=Barrel(5600.0), firing=Firing(6.86, 564.0), recoil_spring=RecoilSpring(27500.0),
                                recoil_damper=RecoilDamper(6239.0, 14050.0), absorbers=(front, rear)))
    path = tmp_path / "scene.toml"
    path.write_text(scene_to_toml(scene))
    result = _run("import sys, json\n"
                  "from mbs_models import load_scene\n"
                  "from validation.reference import solve_reference\n"
                  f"r = solve_reference(load_scene({str(path)!r}), 0.2)\n"
                  "print(json.dumps({'modules': sorted(sys.modules), 'x': r.max_barrel_displacement,\n"
                  "                  'connectors': list(r.connectors)}))\n")
    assert result["x"] > 0
    assert result["connectors"] == list(design_connectors(scene))
    assert result["connectors"][:6] == ["recoil_spring", "recoil_damper", "front_damper", "front_contact",
                                        "rear_damper", "rear_contact"] and len(result["connectors"]) > 6
    bad = [m for m in result["modules"] if m == "exudyn" or m.startswith(("exudyn.", "mbs_models.engine"))
           or m in ("mbs_models.simulation", "mbs_models.assembly", "mbs_models.final_metrics")]
    assert not bad, bad


def test_solving_a_carriage_scene_loads_no_engine(tmp_path):
    """The planar reference (a scene with [carriage]) reads the scene as data too: no engine, no Exudyn, and
    nothing of the engine's carriage or contact laws beyond the scene's own tables."""
    from planar_scenes import carriage_scene

    path = tmp_path / "gun.toml"
    path.write_text(scene_to_toml(carriage_scene()))
    result = _run("import sys, json\n"
                  "from mbs_models import load_scene\n"
                  "from validation.reference import solve_reference\n"
                  f"r = solve_reference(load_scene({str(path)!r}), 0.05, method='LSODA')\n"
                  "print(json.dumps({'modules': sorted(sys.modules), 'type': type(r).__name__,\n"
                  "                  'margin': r.stability_margin}))\n")
    assert result["type"] == "PlanarResult" and 0.0 <= result["margin"] <= 1.0
    assert "validation.reference.planar.kinematics" in result["modules"]
    bad = [m for m in result["modules"] if m == "exudyn" or m.startswith(("exudyn.", "mbs_models.engine"))
           or m in ("mbs_models.simulation", "mbs_models.assembly", "mbs_models.final_metrics")]
    assert not bad, bad
