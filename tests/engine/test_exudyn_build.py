"""The engine runs on Exudyn's fast compiled module (mbs_models/engine/exudyn_build.py): the same numbers as the
range-checked one on every shipped scene, and nothing printed."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from mbs_models.scenes import list_scenes

_RUN = """
import json, sys
from mbs_models import load_scene, simulate
from mbs_models.engine.exudyn_build import exudyn_build
from mbs_models.scenes import scene_path
out = {"build": exudyn_build(), "runs": {}}
for name in sys.argv[1:]:
    r = simulate(load_scene(scene_path(name)), 0.5)
    out["runs"][name] = [r.steps, float(r.max_barrel_displacement), float(r.peak_support_force),
                         [float(v) for v in r.barrel_position[::50]]]
print(json.dumps(out))
"""


def _runs(build: str) -> dict:
    env = {**os.environ, "RECOIL_EXUDYN_BUILD": build}
    done = subprocess.run([sys.executable, "-c", _RUN, *list_scenes()], capture_output=True, text=True, env=env,
                          timeout=600, check=True)
    return json.loads(done.stdout)  # stdout is the JSON alone: the fast module's banner is swallowed


def test_the_fast_and_the_checked_module_give_the_same_runs():
    """Every shipped scene, 0.5 s at standard, on both modules.  The 1-D scenes: the same steps and the same numbers
    (the modules differ in range checks and vector code; their arithmetic on 1-D bodies is the same: measured
    bit-identical, compared within 1e-12 in case another CPU reorders a sum).  The carriage's kinematic tree is
    computed by vector code in the fast module: other round-off, other step sizes (measured: 1450 vs 1434 steps,
    the recoil 5e-13 apart): within the standard preset's guarantee (1e-7 of the max displacement and peak force,
    1e-6 of the largest position on the history)."""
    from mbs_models import load_scene
    from mbs_models.scenes import scene_path

    fast, checked = _runs("fast"), _runs("checked")
    assert fast["build"] in ("fast", "checked")  # checked on a CPU without AVX2: Exudyn's own fallback
    assert checked["build"] == "checked"
    for name, (steps, x, force, history) in checked["runs"].items():
        f_steps, f_x, f_force, f_history = fast["runs"][name]
        planar = load_scene(scene_path(name)).carriage is not None
        if not planar:
            assert f_steps == steps, name
        metric = 1e-7 if planar else 1e-12
        assert abs(f_x - x) <= metric * abs(x), (name, f_x, x)
        assert abs(f_force - force) <= metric * abs(force), (name, f_force, force)
        scale = max(abs(v) for v in history)
        assert len(f_history) == len(history) or planar
        if not planar:
            assert all(abs(a - b) <= 1e-12 * scale for a, b in zip(f_history, history)), name
