"""The element registry (mbs_models/elements/__init__.py): register_element's refusals and its idempotence.

A successful registration from outside the package changes the registry of the process: it is tested in a
fresh process with the out-of-tree example (tests/examples/test_progressive_spring.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import pytest

import mbs_models
from mbs_models.elements import ELEMENT_TABLES, TABLES, Table, register_element
from mbs_models.elements.recoil_spring import RecoilSpring
from validation.reference.terms import TERMS, register_term


def test_register_element_is_public_and_idempotent():
    before = dict(TABLES), dict(ELEMENT_TABLES)
    assert mbs_models.register_element is register_element
    assert register_element(RecoilSpring) is RecoilSpring
    assert (dict(TABLES), dict(ELEMENT_TABLES)) == before
    assert list(TABLES) == list(before[0])  # the order too


def test_a_taken_table_name_is_refused():
    @dataclass(frozen=True)
    class OtherSpring(Table):
        stiffness: float
        TABLE: ClassVar[str] = "recoil_spring"

    with pytest.raises(TypeError, match="'recoil_spring' of OtherSpring is taken"):
        register_element(OtherSpring)
    assert TABLES["recoil_spring"] is RecoilSpring


@pytest.mark.parametrize("name", ["conventions", "contact", "version", "name"])
def test_a_scene_key_is_no_table_name(name):
    table = dataclass(frozen=True)(type("Clash", (Table,), {"__annotations__": {"x": float}, "TABLE": name}))
    with pytest.raises(TypeError, match="taken"):
        register_element(table)


@pytest.mark.parametrize("thing", [int, RecoilSpring(1.0), type("NotADataclass", (Table,), {"TABLE": "x"})])
def test_register_element_needs_a_table_dataclass(thing):
    with pytest.raises(TypeError, match="dataclass subclass"):
        register_element(thing)


def test_register_term_refusals_and_idempotence():
    shipped = TERMS["recoil_spring"]
    assert register_term(shipped) is shipped
    with pytest.raises(TypeError, match="already has a reference term"):
        register_term(type("Clash", (), {"TABLES": ("recoil_spring",), "build": staticmethod(lambda b, k, t: None)}))
    with pytest.raises(TypeError, match="needs TABLES"):
        register_term(type("NoBuild", (), {"TABLES": ("something",)}))
    assert TERMS["recoil_spring"] is shipped and "something" not in TERMS


# ------------------------------------------------------------------ the manifest and the deferred imports (#24)
import subprocess  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

from mbs_models.elements import registry  # noqa: E402

#: The element modules a run of the paper's model (ii) needs: its tables' (and the absorber's contact's).
MODEL_II_MODULES = {"barrel", "firing", "recoil_spring", "recoil_damper", "absorber", "contact_laws"}


def _fresh(code: str) -> str:
    process = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert process.returncode == 0, process.stderr
    return process.stdout


def test_the_manifest_is_what_the_modules_define():
    """Every table the manifest lists is the one its module defines (module, class name, ORDER, MANY, nesting), every
    module it lists exists, and a listed module defines no table it does not list.  A module it does not list is
    allowed: a new element works without regenerating it (DESIGN.md: "a new effect touches one engine element
    module, ..."), only its import is not deferred."""
    from mbs_models.elements._manifest import MODULES, SHIPPED

    discovered, modules = registry.discover(), registry._package_modules()
    hint = f"mbs_models/elements/_manifest.py is out of date: run {registry.REGENERATE}"
    assert set(MODULES) <= set(modules), hint
    assert {name: discovered.get(name) for name in SHIPPED} == SHIPPED, hint
    assert {name for name, (module, *_) in discovered.items() if module in MODULES} == set(SHIPPED), hint
    assert list(SHIPPED) == [name for name in TABLES if name in SHIPPED]  # the element order
    assert {"carriage", "characteristic", "cradle"} <= set(MODULES)  # a module without a table is listed too


def test_the_manifest_script_writes_what_the_registry_reads(tmp_path):
    """``scripts/element_manifest.py`` prints the source the registry's manifest module is (parsed back equal)."""
    script = Path(registry.__file__).resolve().parents[2] / "scripts" / "element_manifest.py"
    printed = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, check=True).stdout
    namespace: dict = {}
    exec(compile(printed, "manifest", "exec"), namespace)
    assert namespace["SHIPPED"] == registry.discover() and list(namespace["MODULES"]) == registry._package_modules()


def test_a_run_imports_only_the_element_modules_its_scene_uses():
    """Import to the first result (issue #24): simulating model (ii) imports its own tables' element modules and the
    infrastructure, none of the others; the others' classes still resolve afterwards, through the registry and the
    package's re-exports."""
    out = _fresh("import sys, mbs_models; from mbs_models import model_ii, simulate; simulate(model_ii(), 0.01); "
                 "print(' '.join(sorted(m.rpartition('.')[2] for m in sys.modules "
                 "if m.startswith('mbs_models.elements.')))); "
                 "from mbs_models.elements import TABLES; from mbs_models.scene import Carriage; "
                 "assert mbs_models.Cradle is TABLES['cradle'] and Carriage is TABLES['carriage']; "
                 "assert 'mbs_models.elements.cradle' in sys.modules; print('resolved')")
    imported, resolved = out.split("\n")[:2]
    from mbs_models.elements._manifest import MODULES

    assert set(imported.split()) & set(MODULES) == MODEL_II_MODULES
    assert resolved == "resolved"


def test_a_scene_file_imports_the_modules_of_its_tables():
    """Reading a scene file imports the element modules of the tables it has (the cradle's), not the others'."""
    path = Path(mbs_models.__file__).with_name("scenes") / "cradle.toml"
    assert "[carriage]" not in path.read_text(encoding="utf-8")
    out = _fresh(f"import sys, mbs_models; s = mbs_models.load_scene({str(path)!r}); "
                 "print(s.cradle is not None, 'mbs_models.elements.cradle' in sys.modules, "
                 "'mbs_models.elements.carriage' in sys.modules)")
    assert out.split() == ["True", "True", "False"]


def test_every_shipped_table_class_is_reexported_by_its_name():
    import mbs_models.scene

    assert set(mbs_models.scene.TABLE_CLASSES) == {cls.__name__ for cls in TABLES.values()}
    for name, cls in mbs_models.scene.TABLE_CLASSES.items():
        assert getattr(mbs_models, name) is cls and getattr(mbs_models.scene, name) is cls
        assert name in mbs_models.__all__ and name in dir(mbs_models)
    with pytest.raises(AttributeError, match="NoSuchTable"):
        mbs_models.scene.NoSuchTable  # noqa: B018


def test_a_stale_manifest_entry_is_an_error_naming_the_command(monkeypatch):
    """A manifest entry that differs from its module's table (here its ORDER), or names a table the module no longer
    defines, is a RuntimeError when the module is loaded, never a silently wrong element order."""
    right = registry._ENTRIES["recuperator"]
    stale = registry._Entry("recuperator", right.module, right.class_name, right.order + 1, right.many, right.element)
    monkeypatch.setitem(registry._ENTRIES, "recuperator", stale)
    with pytest.raises(RuntimeError, match=r"out of date for the table 'recuperator'.*scripts/element_manifest.py"):
        TABLES["recuperator"]  # noqa: B018
    ghost = registry._Entry("ghost", right.module, "Ghost", 50, False, True)
    monkeypatch.setitem(registry._ENTRIES, "recuperator", right)
    monkeypatch.setitem(registry._ENTRIES, "ghost", ghost)
    with pytest.raises(RuntimeError, match="no longer defines the table 'ghost'"):
        TABLES["ghost"]  # noqa: B018


def test_a_module_the_manifest_does_not_list_is_imported_at_start():
    """An element module added without regenerating the manifest (here: the cradle's, left out of it) is imported
    with the package and its table registered in its place: the element works, only its import is not deferred."""
    out = _fresh("import sys, types; from mbs_models.elements._manifest import MODULES, SHIPPED\n"
                 "import mbs_models.elements.registry as r\n"
                 "full = list(r.TABLES)\n"
                 "for name in [m for m in sys.modules if m.startswith('mbs_models')]: del sys.modules[name]\n"
                 "m = types.ModuleType('mbs_models.elements._manifest')\n"
                 "m.SHIPPED = {k: v for k, v in SHIPPED.items() if v[0] != 'cradle'}\n"
                 "m.MODULES = tuple(x for x in MODULES if x != 'cradle')\n"
                 "sys.modules['mbs_models.elements._manifest'] = m\n"
                 "import mbs_models\nfrom mbs_models.elements import TABLES, ELEMENT_TABLES\n"
                 "assert 'mbs_models.elements.cradle' in sys.modules and 'mbs_models.elements.carriage' not in sys.modules\n"
                 "assert list(TABLES) == full, (list(TABLES), full)\n"
                 "assert ELEMENT_TABLES['cradle'] is sys.modules['mbs_models.elements.cradle'].Cradle\n"
                 "print('ok')")
    assert out.strip() == "ok"


def test_the_registry_names_and_flags_need_no_import():
    """What the scene needs of every table (its name, ``MANY``, ``ORDER``) equals the classes' own declarations."""
    for name, cls in TABLES.items():
        assert (TABLES.many(name), TABLES.order(name), TABLES.class_name(name)) == (cls.MANY, cls.ORDER, cls.__name__)
    assert set(ELEMENT_TABLES) == set(TABLES) - {"contact", "pulse", "band", "support"}
