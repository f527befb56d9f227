"""The package's public API: one obvious entry point, stable whatever was imported first."""

from __future__ import annotations

import subprocess
import sys
import types


def _run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)


def test_simulate_stays_a_function_after_engine_modules_are_imported():
    code = ("import mbs_models.studies.sweep as s, mbs_models.engine.simulation, mbs_models; "
            "s.run_scenes([mbs_models.simplified_model()], end_time=0.1, workers=1); "
            "import types; assert isinstance(mbs_models.simulate, types.FunctionType), mbs_models.simulate; "
            "from mbs_models import simulate; assert callable(simulate)")
    proc = _run(code)
    assert proc.returncode == 0, proc.stderr


def test_scene_api_does_not_load_exudyn():
    proc = _run("import sys, mbs_models; mbs_models.load_scene; mbs_models.model_ii(); "
                "assert 'exudyn' not in sys.modules, 'scene handling must not need Exudyn'")
    assert proc.returncode == 0, proc.stderr


def test_a_run_imports_no_plotting_table_or_cluster_library():
    """``import mbs_models`` and a first ``simulate`` (what every CLI call and sweep worker pays) load none of
    matplotlib, pandas, dask, scipy, tqdm and pyarrow: each is imported where it is used."""
    heavy = ("matplotlib", "pandas", "dask", "scipy", "tqdm", "pyarrow")
    proc = _run("import sys, mbs_models; after_import = sorted(m for m in sys.modules if m.split('.')[0] in %r); "
                "mbs_models.simulate(mbs_models.model_ii(), 0.01); "
                "after_run = sorted(m for m in sys.modules if m.split('.')[0] in %r); "
                "assert not after_import and not after_run, (after_import, after_run)" % (heavy, heavy))
    assert proc.returncode == 0, proc.stderr


#: Modules a first result does not need (issue #24: import to the first result is paid by every CLI call and sweep
#: worker), each loaded where it is used: the studies, the CLI, the independent reference, plots, a carriage
#: scene's outputs and planar model, reading TOML or CSV files, misspelt-key suggestions, process pools.
NOT_FOR_A_FIRST_RESULT = (
    "mbs_models.studies", "mbs_models.cli", "validation", "mbs_models.results.plotting",
    "mbs_models.results.sweep_plots", "mbs_models.results.carriage_plots", "mbs_models.results.optimise_plots",
    "mbs_models.results.carriage", "mbs_models.engine.planar", "mbs_models.engine.reuse",
    "tomllib", "csv", "difflib", "importlib.metadata", "argparse", "logging", "multiprocessing",
    "concurrent.futures", "subprocess", "tempfile", "shutil", "statistics")
#: ... and ``import mbs_models`` alone loads no Exudyn and none of the engine and results (PEP 562 attributes).
NOT_FOR_AN_IMPORT = NOT_FOR_A_FIRST_RESULT + (
    "exudyn", "mbs_models.engine", "mbs_models.results.result", "mbs_models.results.postprocess")


def _loaded(names) -> str:
    """Code for a list of the modules of ``names`` (or their submodules) that the process has imported."""
    return "sorted(m for m in sys.modules if any(m == n or m.startswith(n + '.') for n in %r))" % (names,)


def test_import_and_a_first_run_load_only_what_a_run_needs():
    """Checked on the one scene every benchmark of the issue times (model (ii)) and on a plain ``import``."""
    proc = _run("import sys, mbs_models; after_import = %s; " % _loaded(NOT_FOR_AN_IMPORT)
                + "r = mbs_models.simulate(mbs_models.model_ii(1000.0, 0.0), 0.01); after_run = %s; "
                % _loaded(NOT_FOR_A_FIRST_RESULT)
                + "assert r.max_barrel_displacement > 0; "
                "assert not after_import and not after_run, (after_import, after_run)")
    assert proc.returncode == 0, proc.stderr


def test_the_lazy_loading_check_sees_an_eager_import():
    """The check above fails when one of the modules is imported: here the carriage's outputs and csv."""
    proc = _run("import sys, mbs_models, csv, mbs_models.results.carriage; loaded = %s; print(loaded)"
                % _loaded(NOT_FOR_A_FIRST_RESULT))
    assert proc.returncode == 0, proc.stderr
    assert "'csv'" in proc.stdout and "'mbs_models.results.carriage'" in proc.stdout


def test_a_carriage_metric_of_a_one_dimensional_run_is_none():
    """``Result`` looks the carriage's metric names up on first use (the module is no longer imported with it)."""
    import mbs_models
    from mbs_models.results.carriage import CARRIAGE_METRICS

    result = mbs_models.simulate(mbs_models.model_ii(1000.0, 0.0), 0.01)
    assert all(getattr(result, name) is None for name in CARRIAGE_METRICS)


def test_public_names_resolve():
    import mbs_models

    for name in mbs_models.__all__:
        assert getattr(mbs_models, name) is not None, name
    assert isinstance(mbs_models.simulate, types.FunctionType)
    assert set(mbs_models.__all__) <= set(dir(mbs_models))


def test_public_names_resolve_in_a_fresh_interpreter():
    """Every name of ``__all__`` resolves with nothing imported before (the lazy ones load their modules then),
    and ``dir()`` lists them all before any is used."""
    proc = _run("import mbs_models; listed = set(dir(mbs_models)); "
                "missing = [n for n in mbs_models.__all__ if getattr(mbs_models, n, None) is None]; "
                "assert not missing and set(mbs_models.__all__) <= listed, (missing, set(mbs_models.__all__) - listed)")
    assert proc.returncode == 0, proc.stderr


# ------------------------------------------------------------------ who imports what (issue #21)
def _effect_modules() -> set[str]:
    """The element modules that hold an effect: those defining a table of the registry, but the barrel's (every
    scene's reference body, which the engine and the results name as ``BARREL``) and the carriage's (not an effect
    along the axis but the frame the axis sits on: the planar model, which the engine assembles and the results
    read out as a whole, DESIGN.md "The recoil axis on a carriage")."""
    from mbs_models.elements import TABLES
    from mbs_models.elements.barrel import Barrel
    from mbs_models.elements.carriage import Carriage

    return {table.__module__ for table in TABLES.values()} - {Barrel.__module__, Carriage.__module__}


def _effects_imported(path, source: str | None = None) -> list[str]:
    """``line: module`` of every import in ``path`` (or ``source`` read as that file) of an effect's module."""
    from imports import imports_of

    effects = _effect_modules()
    return [f"{line}: {module}" for line, module in imports_of(path, source) if module in effects]


def test_the_effect_import_check_can_fail():
    """Each way of importing an effect's module is found, relative or absolute; the infrastructure is not one."""
    from imports import REPO

    path = REPO / "mbs_models" / "engine" / "mechanism.py"
    for source in ("from ..elements.end_stops import RecoilStop", "from ..elements import end_stops",
                   "import mbs_models.elements.cradle", "def f():\n    from mbs_models.elements.recuperator import X"):
        assert len(_effects_imported(path, source)) == 1, source
    assert not _effects_imported(path, "from ..elements.connector import GROUND\nfrom ..elements import TABLES\n"
                                       "from ..elements.barrel import BARREL")
    assert "mbs_models.elements.absorber" in _effect_modules() and len(_effect_modules()) >= 8


def test_the_engine_and_the_results_import_no_effect():
    """Adding an effect touches no engine or results module (README, "Adding an effect"): they import the elements'
    infrastructure (connector, table, the registry) and the barrel, never an effect's own module."""
    from imports import REPO

    files = sorted((REPO / "mbs_models" / "engine").rglob("*.py")) + sorted((REPO / "mbs_models" / "results").rglob("*.py"))
    assert len(files) >= 20
    bad = [f"{path.relative_to(REPO)}:{found}" for path in files for found in _effects_imported(path)]
    assert not bad, "modules of the engine or the results import an effect's module:\n" + "\n".join(bad)
