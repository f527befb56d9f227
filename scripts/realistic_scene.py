#!/usr/bin/env python
"""The "realistic" example: ``python scripts/realistic_scene.py`` writes ``mbs_models/scenes/realistic.toml``
and its figures ``docs/figures/realistic_*.png``, and prints the per-shot table.

The scene combines what a designer sizes: a breech-force pulse with the gas after-effect (7369 N s), a
recuperator whose 36 kN preload holds the 5.6 t barrel in battery at 30 degrees of elevation against
gravity and friction (mu = 0.05), a Kelvin-Voigt battery buffer, a hydraulic brake whose recoil orifice is
**designed** for a constant total resistance over a 0.30 m recoil (``recoil design-brake``, from
``scripts/realistic_base.toml``), and a 3-shot burst.  The base scene has every element but the designed
table and the burst; this script designs the table, adds ``[burst]`` and writes the ready scene.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from mbs_models import load_scene, scene_to_toml, simulate  # noqa: E402
from mbs_models.elements.firing import Burst  # noqa: E402
from mbs_models.results.plotting import save_figure  # noqa: E402
from mbs_models.studies.brake_design import compare_with_linear_damper, plot_comparison, recoil_stroke  # noqa: E402

RECOIL_LENGTH = 0.30  # m
BURST = Burst(shots=3, interval=2.5)  # s: the barrel is back in battery ~2.2 s after a shot
HEADER = """# A realistic recoil system (written by scripts/realistic_scene.py from scripts/realistic_base.toml):
# a 7369 N s breech-force pulse (projectile 6.86 kg at 564 m/s, 2.5 kg of charge at 1400 m/s), a 36 kN
# recuperator preload holding the barrel in battery at 30 degrees (it must exceed M g (sin + mu cos) =
# 29.9 kN), a Kelvin-Voigt battery buffer, a hydraulic brake whose recoil orifice is designed for a constant
# resistance over a 0.30 m recoil (recoil design-brake), and a 3-shot burst, one shot every 2.5 s.
"""


def build():
    base = load_scene(ROOT / "scripts" / "realistic_base.toml")
    comparison = compare_with_linear_damper(base, RECOIL_LENGTH)
    scene = comparison.design.scene.with_changes(
        burst=BURST, name="realistic: pulse, designed brake, recuperator, buffer, 3-shot burst at 30 degrees")
    return scene, comparison


def figures(scene, comparison, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    result = simulate(scene, 7.5)
    fig, axes = plt.subplots(2, 2, figsize=(11, 7))
    t = result.time
    axes[0, 0].plot(t, 1e3 * result.barrel_position)
    axes[0, 0].set_ylabel("barrel displacement (mm)")
    axes[0, 1].plot(t, result.barrel_velocity)
    axes[0, 1].set_ylabel("barrel velocity (m/s)")
    axes[1, 0].plot(t, result.support_force / 1e3)
    axes[1, 0].set_ylabel("support force (kN)")
    for ax in (axes[0, 0], axes[0, 1], axes[1, 0]):
        ax.set_xlabel("time (s)")
        for shot in result.shots:
            ax.axvline(shot["time"], color="grey", lw=0.6, ls=":")
    stroke, resistance = recoil_stroke(result, until=result.shots[0]["time_of_max_barrel_displacement"])
    after_pulse = t[:len(stroke)] > scene.firing.pulse.table[0][-1]  # the breech force accelerates, not resists
    axes[1, 1].plot(1e3 * stroke[after_pulse], resistance[after_pulse] / 1e3,
                    label="total resistance F_breech - M a (after the pulse)")
    axes[1, 1].axhline(comparison.design.resistance / 1e3, color="grey", ls=":", label="design: constant R")
    axes[1, 1].set_xlabel("barrel displacement (mm), first shot")
    axes[1, 1].set_ylabel("resistance to recoil (kN)")
    axes[1, 1].legend(fontsize=8)
    fig.suptitle(scene.name, fontsize=10)
    fig.tight_layout()
    save_figure(fig, out / "realistic.png")
    save_figure(plot_comparison(comparison), out / "realistic_design.png")
    return result


def main() -> int:
    scene, comparison = build()
    path = ROOT / "mbs_models" / "scenes" / "realistic.toml"
    path.write_text(HEADER + scene_to_toml(scene))
    print(f"wrote {path}")
    result = figures(scene, comparison, ROOT / "docs" / "figures")
    from mbs_models import simplified_model
    simple = compare_with_linear_damper(simplified_model(), 0.2215)  # the user guide's design-brake example
    save_figure(plot_comparison(simple), ROOT / "docs" / "figures" / "design_brake.png")
    d = comparison.to_dict()
    print(f"constant resistance {d['constant_resistance'] / 1e3:.2f} kN, flat to "
          f"{100 * d['resistance_flatness_over_90_percent']:.2f} % over 90 % of the stroke; peak support force "
          f"{d['designed']['peak_support_force'] / 1e3:.2f} kN, {d['designed']['peak_support_force_in_recoil'] / 1e3:.2f} "
          f"kN in recoil (linear damper at the same recoil length: {d['linear_damper']['peak_support_force'] / 1e3:.2f} "
          f"kN, {d['linear_damper']['peak_support_force_in_recoil'] / 1e3:.2f} kN in recoil)")
    print("| shot | fires at (s) | max displacement (mm) | in battery at the next shot | time to battery (s) |")
    print("|---|---|---|---|---|")
    for shot in result.shots:
        battery = "--" if shot["in_battery_at_next_shot"] is None else ("yes" if shot["in_battery_at_next_shot"] else "no")
        back = "--" if shot["time_to_battery"] is None else f"{shot['time_to_battery']:.3f}"
        print(f"| {shot['shot']} | {shot['time']:.1f} | {1e3 * shot['max_barrel_displacement']:.1f} | {battery} | {back} |")
    print(f"peak support force over the burst {result.peak_support_force / 1e3:.2f} kN; wall time "
          f"{result.wall_time:.2f} s ({result.steps} steps)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
