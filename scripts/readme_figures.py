#!/usr/bin/env python
"""The documentation's figures of richer mechanisms: ``python scripts/readme_figures.py`` writes ``docs/figures/*.png``.

One figure per shipped version-2 example scene that is not a contact-law variant (``NAME.png``):
positions, contact forces, the force on the mount and velocities over the first 3 s, and a zoom on the first impact.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from mbs_models import load_scene, simulate  # noqa: E402
from mbs_models.results.plotting import plot_result, save_figure  # noqa: E402
from mbs_models.scenes import scene_path  # noqa: E402


def main() -> int:
    out = ROOT / "docs" / "figures"
    out.mkdir(parents=True, exist_ok=True)
    import tomllib

    from mbs_models.scenes import list_scenes

    for name in list_scenes():
        if name.startswith("contact_") or tomllib.loads(scene_path(name).read_text()).get("version", 1) < 2:
            continue
        result = simulate(load_scene(scene_path(name)), 3.0)
        save_figure(plot_result(result), out / f"{name}.png")
        print(f"wrote {out / f'{name}.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
