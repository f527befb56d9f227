"""The numbers the user guide (docs/guide/*.md) quotes, computed from the code (DOCS_LAYOUT.md's contract).

``NUMBERS[name] = {"compute": callable -> float, "format": str, "rel_tol": float, "why": str}``; a page quotes
``{{ name }}``.  Every computation is a short run of a shipped scene at the ``standard`` preset, a closed form or a
small study; runs shared by several numbers are cached, so that the whole module computes in seconds.

Tolerances: numbers of engine runs at ``standard`` hold to far better than 1e-6 relative between machines (the
preset's guarantee); ``rel_tol`` 1e-3 is well inside the last digit the format shows for all but the contact-law
difference, a difference of two restitutions near 1e-7 whose last bits depend on the CPU (``rel_tol`` 0.2 keeps
the quoted one significant digit honest).
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np

RUN_TOL = 1e-3        # relative: an engine run at ``standard`` (see the module docstring)
EXACT_TOL = 1e-9      # relative: a closed form or a count


@functools.lru_cache(maxsize=None)
def _shipped(name: str, end_time: float, **changes):
    from mbs_models import load_scene, simulate
    from mbs_models.scenes import scene_path

    scene = load_scene(scene_path(name))
    return simulate(scene.with_changes(**changes) if changes else scene, end_time, "standard")


def _run(name: str, end_time: float, changes: tuple = ()):
    return _shipped(name, end_time, **dict(changes))


def _stop(result, name: str) -> dict:
    return next(stop for stop in result.stops() if stop["name"] == name)


def _spade() -> dict:
    """towed_howitzer_45's spade: its static, least and largest normal force (N)."""
    return next(s for s in _run("towed_howitzer_45", 3.0).supports if s["name"] == "spade")


def _recoil_phase(result) -> np.ndarray:
    return result.time <= result.time_of_max_barrel_displacement


@functools.lru_cache(maxsize=None)
def _realistic_design():
    """The realistic system's brake design against the linear damper (scripts/realistic_scene.py's build)."""
    from mbs_models import load_scene
    from mbs_models.studies.brake_design import compare_with_linear_damper

    root = Path(__file__).resolve().parents[1]
    return compare_with_linear_damper(load_scene(root / "scripts" / "realistic_base.toml"), 0.30)


@functools.lru_cache(maxsize=None)
def _simplified_design(recoil_length: float):
    from mbs_models import simplified_model
    from mbs_models.studies.brake_design import compare_with_linear_damper

    return compare_with_linear_damper(simplified_model(), recoil_length)


@functools.lru_cache(maxsize=None)
def _contact_law_study():
    from validation.studies.contact_laws import run_study

    return run_study("standard")


def _restitution(law: str) -> float:
    from validation.reference.closed_form import achieved_restitution

    return achieved_restitution(law, 0.5)


@functools.lru_cache(maxsize=None)
def _m109(convention: str, inches: float = 21.0) -> dict:
    import importlib.util

    path = Path(__file__).resolve().parents[1] / "scripts" / "m109_check.py"
    spec = importlib.util.spec_from_file_location("m109_check", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    gas = module.CONVENTIONS[convention]
    return module.check(gas, inches * module.INCH)


def _counter_recoil_peak(result) -> float:
    """|support force| (N) after the maximum displacement: the return."""
    return float(np.max(np.abs(result.support_force[~_recoil_phase(result)])))


def _entry(compute, fmt: str, why: str, rel_tol: float = RUN_TOL) -> dict:
    return {"compute": compute, "format": fmt, "rel_tol": rel_tol, "why": why}


def _mm(name, end_time, changes=()):
    return lambda: 1e3 * _run(name, end_time, changes).max_barrel_displacement


def _kn_mount(name, end_time, changes=()):
    return lambda: _run(name, end_time, changes).peak_support_force / 1e3


NO_STOPS = (("recoil_stop", None), ("battery_stop", None))

NUMBERS: dict[str, dict] = {
    # scene-format.md: the recuperator example
    "simplified_recoil_length": _entry(_mm("simplified", 10.0), "{:.1f} mm",
                                       "the paper's simplified model's recoil length (standard, 10 s)"),
    "recuperator_recoil_length": _entry(_mm("recuperator", 10.0), "{:.1f} mm",
                                        "the shipped recuperator scene's recoil length"),
    "recuperator_peak_support_force": _entry(_kn_mount("recuperator", 10.0), "{:.1f} kN",
                                             "the recuperator scene's peak force on the mount (the buffer stops the return)"),
    "recuperator_recoil_support_force": _entry(
        lambda: float(np.max(np.abs(_run("recuperator", 10.0).support_force[_recoil_phase(_run("recuperator", 10.0))])))
        / 1e3, "{:.1f} kN", "the recuperator scene's peak force on the mount while it recoils"),
    "recuperator_buffer_impacts": _entry(lambda: float(len(_stop(_run("recuperator", 10.0), "battery_stop")["impacts"])),
                                         "{:.0f}", "impacts on the recuperator scene's battery buffer in 10 s",
                                         EXACT_TOL),
    # firing.md has its console block checked by tests/docs/test_guide_pages.py
    # contact-laws.md
    "restitution_lankarani_nikravesh": _entry(lambda: _restitution("lankarani-nikravesh"), "{:.2f}",
                                              "restitution a free impact achieves for 0.5 asked (closed form)",
                                              EXACT_TOL),
    "restitution_flores": _entry(lambda: _restitution("flores"), "{:.2f}",
                                 "restitution a free impact achieves for 0.5 asked (closed form)", EXACT_TOL),
    "restitution_gonthier": _entry(lambda: _restitution("gonthier"), "{:.2f}",
                                   "restitution a free impact achieves for 0.5 asked (closed form)", EXACT_TOL),
    "contact_laws_worst_difference": _entry(lambda: _contact_law_study().worst_error, "{:.1e}",
                                            "recoil contact-laws: worst |engine e - closed form e| at standard", 0.2),
    # recoil-brake.md
    "recoil_brake_recoil_length": _entry(_mm("recoil_brake", 3.0), "{:.1f} mm",
                                         "the shipped recoil_brake scene's recoil length"),
    "recoil_brake_peak_support_force": _entry(_kn_mount("recoil_brake", 3.0), "{:.2f} kN",
                                              "the recoil_brake scene's peak force on the mount"),
    "recoil_brake_peak_support_time": _entry(lambda: _run("recoil_brake", 3.0).time_of_peak_support_force, "{:.2f} s",
                                             "when the recoil_brake scene's force on the mount peaks"),
    # tabulated.md
    "tabulated_spring_recoil_length": _entry(_mm("tabulated_spring", 10.0), "{:.1f} mm",
                                             "the tabulated_spring scene's recoil length"),
    "tabulated_spring_peak_support_force": _entry(_kn_mount("tabulated_spring", 10.0), "{:.2f} kN",
                                                  "the tabulated_spring scene's peak force on the mount"),
    "tabulated_damper_recoil_length": _entry(_mm("tabulated_damper", 10.0), "{:.1f} mm",
                                             "the tabulated_damper scene's recoil length"),
    "tabulated_damper_peak_support_force": _entry(_kn_mount("tabulated_damper", 10.0), "{:.2f} kN",
                                                  "the tabulated_damper scene's peak force on the mount"),
    # mount-force.md
    "end_stops_recoil_length": _entry(_mm("end_stops", 3.0), "{:.0f} mm", "the end_stops scene's recoil length"),
    "end_stops_peak_support_force": _entry(_kn_mount("end_stops", 3.0), "{:.0f} kN",
                                           "the end_stops scene's peak force on the mount"),
    "no_stops_recoil_length": _entry(_mm("end_stops", 3.0, NO_STOPS), "{:.0f} mm",
                                     "the end_stops scene without its stops: recoil length"),
    "no_stops_peak_support_force": _entry(_kn_mount("end_stops", 3.0, NO_STOPS), "{:.1f} kN",
                                          "the end_stops scene without its stops: peak force on the mount"),
    # cradle.md
    "cradle_gravity_force": _entry(lambda: 5600.0 * 9.81 * math.sin(math.radians(30.0)) / 1e3, "{:.1f} kN",
                                   "M g sin(30 deg) of the cradle scene's 5600 kg barrel (closed form)", EXACT_TOL),
    "cradle_max_displacement": _entry(lambda: _run("cradle", 10.0).max_barrel_displacement, "{:.2f} m",
                                      "how far gravity carries the cradle scene's barrel"),
    "cradle_rest_position": _entry(lambda: float(_run("cradle", 10.0).barrel_position[-1]), "{:.2f} m",
                                   "where the cradle scene's barrel sticks (its position at 10 s)", 1e-2),
    # realistic.md
    "realistic_resistance": _entry(lambda: _realistic_design().design.resistance / 1e3, "{:.2f} kN",
                                   "the realistic system's constant resistance to recoil"),
    "realistic_flatness": _entry(lambda: 100 * _realistic_design().flatness, "{:.1f} %",
                                 "how flat its resistance is over 90 % of the stroke", 2e-2),
    "realistic_design_length": _entry(lambda: 1e3 * _realistic_design().length.design_length, "{:.1f} mm",
                                      "the length the realistic brake's table is designed for"),
    "realistic_mount_in_recoil": _entry(lambda: _realistic_design().designed.peak_support_force / 1e3, "{:.1f} kN",
                                        "designed brake: peak force on the mount (during recoil)"),
    "realistic_mount_on_return": _entry(lambda: _counter_recoil_peak(_realistic_design().designed) / 1e3, "{:.1f} kN",
                                        "designed brake: peak force on the mount on counter-recoil"),
    "realistic_buffer_force": _entry(lambda: _stop(_realistic_design().designed, "battery_stop")["peak_contact_force"]
                                     / 1e3, "{:.1f} kN", "designed brake: peak force on the battery buffer"),
    "realistic_linear_mount_in_recoil": _entry(
        lambda: float(np.max(np.abs(_realistic_design().linear.support_force[_recoil_phase(_realistic_design().linear)])))
        / 1e3, "{:.1f} kN", "linear damper at the same recoil length: peak force on the mount during recoil"),
    "realistic_linear_mount_on_return": _entry(lambda: _realistic_design().linear.peak_support_force / 1e3, "{:.0f} kN",
                                               "linear damper: peak force on the mount into the buffer"),
    "realistic_time_to_battery": _entry(lambda: _run("realistic", 7.5).shots[0]["time_to_battery"], "{:.1f} s",
                                        "the realistic burst: a shot's time back to battery"),
    "realistic_second_landing": _entry(lambda: _stop(_run("realistic", 7.5), "battery_stop")["impacts"][1]["peak_force"]
                                       / 1e3, "{:.0f} kN", "the realistic burst: the second landing on the buffer"),
    "realistic_buffer_impacts": _entry(lambda: float(len(_stop(_run("realistic", 10.0), "battery_stop")["impacts"])),
                                       "{:.0f}", "impacts on the realistic scene's buffer in recoil run's 10 s",
                                       EXACT_TOL),
    # carriage.md
    "howitzer45_stability_margin": _entry(lambda: 100 * _run("towed_howitzer_45", 3.0).stability_margin, "{:.0f} %",
                                          "towed_howitzer_45: the spade's least load over its static load"),
    "howitzer45_spade_static": _entry(lambda: _spade()["static_normal_force"] / 1e3,
                                      "{:.1f} kN", "towed_howitzer_45: the spade's static load"),
    "howitzer45_spade_least": _entry(lambda: _spade()["min_normal_force"] / 1e3,
                                     "{:.1f} kN", "towed_howitzer_45: the spade's least load"),
    "howitzer_recoil_length": _entry(_mm("towed_howitzer", 3.0), "{:.0f} mm", "towed_howitzer (level): recoil length"),
    "howitzer_buffer_force": _entry(lambda: _stop(_run("towed_howitzer", 3.0), "battery_stop")["peak_contact_force"]
                                    / 1e3, "{:.0f} kN", "towed_howitzer (level): peak force on the buffer"),
    "howitzer_lift_off_time": _entry(lambda: _run("towed_howitzer", 3.0).lift_off_time, "{:.3f} s",
                                     "towed_howitzer (level): when the spade leaves the ground"),
    "howitzer_max_lift": _entry(lambda: 1e3 * _run("towed_howitzer", 3.0).max_lift, "{:.1f} mm",
                                "towed_howitzer (level): how high the spade lifts", 2e-2),
    # python.md
    "model_i_rest_time": _entry(lambda: _model_i_at_rest().rest_time, "{:.1f} s",
                                "model (i) asked for 10 000 s comes to rest at this time"),
}


@functools.lru_cache(maxsize=None)
def _model_i_at_rest():
    from mbs_models import model_i, simulate

    return simulate(model_i(), 10000.0, "standard")


def _design_brake_entries() -> dict[str, dict]:
    """design-brake.md: the simplified model at its own recoil length, and asked 0.05 m."""
    own, short = (lambda: _simplified_design(0.2215)), (lambda: _simplified_design(0.05))
    return {
        "design_brake_mount_reduction": _entry(
            lambda: 100 * (1 - own().designed.peak_support_force / own().linear.peak_support_force), "{:.0f} %",
            "design-brake on the simplified model: the designed brake's peak force on the mount below the damper's"),
        "design_brake_short_design_length": _entry(lambda: 1e3 * short().length.design_length, "{:.2f} mm",
                                                   "asked 0.05 m: the length the table is designed for"),
        "design_brake_short_recoil": _entry(lambda: 1e3 * short().length.recoil_length, "{:.2f} mm",
                                            "asked 0.05 m: the designed scene's simulated recoil"),
        "design_brake_spring_limit": _entry(lambda: 0.6909 * math.sqrt(5600.0 / 27500.0), "{:.3f} m",
                                            "v0 sqrt(M/k): where the simplified model's spring alone stops the barrel",
                                            1e-4),
    }


def _m109_entries() -> dict[str, dict]:
    """m109.md's table: one row per gas after-effect convention, and the M109A1's two lengths."""
    rows = {"inbore": "in-bore only (v_gas = v_p / 2)", "gas15": "1.5 v_p", "gas4700": "4,700 ft/s"}
    columns = {"momentum": ("momentum", 1.0, "{:,.0f} N s"), "v0": ("v0", 1.0, "{:.2f} m/s"),
               "energy": ("energy", 1e-3, "{:.1f} kJ"), "implied": ("implied_resistance", 1e-3, "{:,.1f} kN"),
               "designed": ("designed_resistance", 1e-3, "{:,.1f} kN"),
               "area": ("area_at_6000_psi", 1e4, "{:.0f} cm^2")}
    entries = {}
    for row, convention in rows.items():
        for column, (key, scale, fmt) in columns.items():
            exact = key in ("momentum", "v0", "energy", "implied_resistance")
            entries[f"m109_{row}_{column}"] = _entry(
                (lambda c=convention, k=key, s=scale: _m109(c)[k] * s), fmt,
                f"M109, gas after-effect {convention}: {key} (scripts/m109_check.py)",
                EXACT_TOL if exact else RUN_TOL)
    for inches in (36, 24):
        entries[f"m109a1_{inches}in_designed"] = _entry(
            (lambda i=inches: _m109("4,700 ft/s", float(i))["designed_resistance"] / 1e3), "{:,.1f} kN",
            f"M109A1 over {inches} in, 4,700 ft/s: the designed constant resistance")
    return entries


NUMBERS.update(_design_brake_entries())
NUMBERS.update(_m109_entries())


@functools.lru_cache(maxsize=None)
def _optimised() -> dict:
    """docs/optimise_absorbers.json: what scripts/optimise_absorbers.py wrote (tests/docs/test_guide_pages.py checks
    its table against the engine)."""
    import json

    return json.loads((Path(__file__).resolve().parent / "optimise_absorbers.json").read_text())


def _design(mount: str, which: str, metric: str) -> float:
    mounts = _optimised()["mounts"][mount]
    if which in ("A", "B"):
        return mounts[which]["full_run"]["standard"][metric]
    if which.startswith("gap"):           # "gap1000A"
        return mounts["gap_only"][which[3:-1]][which[-1]]["full_run"][metric]
    return mounts["paper_designs"][which][metric]


def _less(mount, which, than_mount, than, metric="max_barrel_displacement"):
    """100 (1 - a / b) %: how much less design ``which`` gives than ``than``."""
    def compute():
        other = (_optimised()["simplified"][metric] if than == "simplified" else _design(than_mount, than, metric))
        return 100 * (1 - _design(mount, which, metric) / other)
    return compute


_X, _S = "max_barrel_displacement", "peak_support_force"
NUMBERS.update({
    "opt_i_A_vs_paper": _entry(_less("model (i)", "A", "model (i)", "1000"), "{:.1f} %",
                               "model (i), A: recoil below the paper's 1000 kg, gap 0 (optimise_absorbers.json)"),
    "opt_i_A_vs_simplified": _entry(_less("model (i)", "A", None, "simplified"), "{:.1f} %",
                                    "model (i), A: recoil below the simplified model's"),
    "opt_i_B_vs_paper": _entry(_less("model (i)", "B", "model (i)", "1000", _S), "{:.1f} %",
                               "model (i), B: force on the mount below the paper's 1000 kg, gap 0"),
    "opt_i_B_vs_simplified": _entry(_less("model (i)", "B", None, "simplified", _S), "{:.1f} %",
                                    "model (i), B: force on the mount below the simplified model's"),
    "opt_i_gap_length_gain": _entry(_less("model (i)", "gap1000A", "model (i)", "1000"), "{:.1f} %",
                                    "model (i), 1000 kg: recoil gained by the gap alone"),
    "opt_i_gap_force_gain": _entry(_less("model (i)", "gap1000B", "model (i)", "1000", _S), "{:.1f} %",
                                   "model (i), 1000 kg: force gained by the gap alone"),
    "opt_ii_A_vs_1000": _entry(_less("model (ii)", "A", "model (ii)", "1000"), "{:.1f} %",
                               "model (ii), A (2000 kg): recoil below 1000 kg"),
    "opt_ii_B_force_gain": _entry(_less("model (ii)", "B", "model (ii)", "1000", _S), "{:.1f} %",
                                  "model (ii), B: force below the paper's 1000 kg case"),
    "opt_ii_B_above_simplified": _entry(lambda: -_less("model (ii)", "B", None, "simplified", _S)(), "{:.1f} %",
                                        "model (ii), B: force above the simplified model's"),
    "opt_ii_500_longer": _entry(lambda: 1e3 * (_design("model (ii)", "gap500B", _X) - _design("model (ii)", "500", _X)),
                                "{:.0f} mm", "model (ii), 500 kg: the force-optimal gap's longer recoil"),
})
