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


def test_public_names_resolve():
    import mbs_models

    for name in mbs_models.__all__:
        assert getattr(mbs_models, name) is not None, name
    assert isinstance(mbs_models.simulate, types.FunctionType)
