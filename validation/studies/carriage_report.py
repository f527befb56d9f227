"""The report's section on the gun on its carriage: the shipped ``towed_howitzer`` at 0 and 45 degrees.

:func:`carriage_job` runs one scene (engine, and the independent planar reference for the comparison);
:func:`carriage_rows` turns the runs into the section's table; :func:`carriage_figure` draws each scene's ground
reactions; :func:`carriage_html` writes the section.  ``recoil paper`` runs the jobs beside its other stages.
"""

from __future__ import annotations

import html
import math

import numpy as np

#: The shipped carriage scenes of the report, with their elevation (degrees).
CARRIAGE_SCENES = (("towed_howitzer", 0.0), ("towed_howitzer_45", 45.0))
#: The window (s): the recoil, the return to battery and the buffer.
CARRIAGE_END_TIME = 3.0


def carriage_job(name: str, end_time: float = CARRIAGE_END_TIME, accuracy: str = "standard"):
    """``(name, engine Result, comparison dict or None)`` of one shipped carriage scene: the engine run, and the
    engine against the planar reference (:func:`validation.studies.compare.compare`)."""
    from mbs_models import load_scene, simulate
    from mbs_models.scenes import scene_path

    scene = load_scene(scene_path(name))
    result = simulate(scene, end_time, accuracy)
    try:
        from .compare import compare

        comparison = compare(scene, end_time=end_time, accuracy=accuracy).to_dict()
    except Exception as exc:  # the report shows the failure rather than hiding the section
        comparison = {"error": " ".join(str(exc).split())[:300]}
    return name, result, comparison


def carriage_rows(runs) -> list[dict]:
    """One row per scene: elevation, recoil, peak resistance, stability margin, lift-off, each support's loads,
    and the engine-vs-reference verdict."""
    rows = []
    for (name, elevation), (_, result, comparison) in zip(CARRIAGE_SCENES, runs):
        carriage = result.carriage
        rows.append({
            "scene": name, "elevation": elevation, "recoil": result.max_barrel_displacement,
            "resistance": result.peak_support_force, "margin": carriage.stability_margin,
            "lift_off_time": carriage.lift_off_time, "max_lift": carriage.max_lift,
            "pitch": carriage.max_carriage_pitch,
            "supports": {s.name: (s.static_normal_force, s.min_normal_force, s.max_normal_force)
                         for s in carriage.supports.values()},
            "validated": None if comparison is None or "error" in comparison else comparison.get("passed"),
            "validation_error": None if comparison is None else comparison.get("error"),
        })
    return rows


def carriage_figure(runs):
    """Each scene's support loads (kN) over time, one panel per elevation, the lift-off marked."""
    from mbs_models.results.plotting import new_figure

    fig, axes = new_figure(len(runs), 1, width=9.0, row_height=2.8)
    for k, ((name, elevation), (_, result, _)) in enumerate(zip(CARRIAGE_SCENES, runs)):
        ax = axes[k, 0]
        result = result.densified()  # the histories 1 ms apart at most (the solver's steps reach 20 ms)
        carriage = result.carriage
        for support in carriage.supports.values():
            ax.plot(result.time, support.normal_force / 1e3, lw=1.0,
                    label=f"{support.name}: static {support.static_normal_force / 1e3:.1f} kN, least "
                          f"{support.min_normal_force / 1e3:.1f} kN")
        if carriage.lift_off_time is not None:
            ax.axvline(carriage.lift_off_time, color="k", ls=":", lw=0.8, label="a support leaves the ground")
        ax.axhline(0.0, color="#999999", lw=0.6)
        verdict = "stays down" if carriage.lift_off_time is None else "lifts"
        ax.set_title(f"{name}: elevation {elevation:g} deg, {verdict} (stability margin "
                     f"{carriage.stability_margin:.2f})", fontsize=9)
        ax.set_ylabel("normal force [kN]")
        ax.legend(fontsize=7, loc="upper right")
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle("The gun on its carriage: ground reactions", fontsize=11)
    return fig


def _f(value, scale: float = 1.0, digits: int = 3) -> str:
    return "-" if value is None or (isinstance(value, float) and not math.isfinite(value)) else \
        f"{value * scale:.{digits}g}"


def carriage_table(rows: list[dict]) -> tuple[list[str], list[list[str]]]:
    """The section's table: headers and cells (HTML-escaped text)."""
    e = html.escape
    headers = ["scene", "elevation [deg]", "recoil [mm]", "peak resistance [kN]", "stability margin", "lift-off [s]",
               "supports: static / least / largest [kN]", "engine vs reference"]
    cells = []
    for r in rows:
        loads = "; ".join(f"{e(n)} {a / 1e3:.1f} / {b / 1e3:.1f} / {c / 1e3:.1f}" for n, (a, b, c) in r["supports"].items())
        check = ("passed" if r["validated"] else "FAILED" if r["validated"] is False else
                 e(f"not run: {r['validation_error']}"))
        cells.append([e(r["scene"]), f"{r['elevation']:g}", _f(r["recoil"], 1e3, 4), _f(r["resistance"], 1e-3, 4),
                      _f(r["margin"], 1, 3), _f(r["lift_off_time"], 1, 4), loads, check])
    return headers, cells


def carriage_html(rows: list[dict], table: str, image: str) -> str:
    """The section's body (after its heading): what is modelled, the ``table`` and the figure (``image``), HTML."""
    sentences = []
    for r in rows:
        if r["lift_off_time"] is None:
            sentences.append(f"At {r['elevation']:g} degrees the gun stays on the ground: every support keeps at least "
                             f"{r['margin']:.0%} of its static load.")
        else:
            sentences.append(f"At {r['elevation']:g} degrees a support leaves the ground at {r['lift_off_time']:.4g} s "
                             f"(it rises {r['max_lift'] * 1e3:.2f} mm).")
    return ("<p>The recoil axis on a planar carriage that may pitch, lift and slide on its supports (a spade dug in "
            "at the trail's end, the wheels 5.2 m ahead): the realistic scene's recoil hardware on a 4.4 t carriage, "
            "and the question a recoil designer asks after the recoil force: does the gun stay on the ground? "
            "Stability margin: the least load of any support over its static load (1: none unloads; 0: a support "
            "leaves the ground). Engine: one Exudyn kinematic tree; reference: the independent planar equations "
            "(<code>validation.reference.planar</code>).</p>"
            + table + f"<p id='carriage-verdict'>{html.escape(' '.join(sentences))}</p>" + image)


__all__ = ["CARRIAGE_SCENES", "CARRIAGE_END_TIME", "carriage_job", "carriage_rows", "carriage_figure",
           "carriage_table", "carriage_html"]
