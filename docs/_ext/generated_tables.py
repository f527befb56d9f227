"""Tables generated at build time from the code and from the benchmark's JSON (never typed into a page):

* ``validation/_guarantee.md``: the tolerances of every accuracy preset,
  :data:`validation.studies.guarantee.TOLERANCES` (what the hard cases and property tests check);
* ``performance/_bench.md``: the ratios ``python scripts/bench.py --json docs/_generated/bench.json`` measured, with
  the date, the machine and its load.

Both are included by their pages (``{include}``) and git-ignored."""

from __future__ import annotations

import json
from pathlib import Path

from _write import write_if_changed

#: the guarantee's error kinds, in the order of the table, and how each is stated
GUARANTEE_COLUMNS = {
    "energy": "energy balance (relative to the initial energy)",
    "metric": "max displacement, absorber velocities, dissipated energies (relative)",
    "force": "peak contact forces, peak force on the mount (relative)",
    "impact_peak": "each impact's peak (relative)",
    "time": "impact start and end",
}


def _seconds(value: float) -> str:
    if value >= 1e-3:
        return f"{value * 1e3:g} ms"
    return f"{value * 1e6:g} µs"


def guarantee_table() -> str:
    from validation.studies.guarantee import TOLERANCES

    header = "| preset | " + " | ".join(GUARANTEE_COLUMNS.values()) + " |"
    rows = [header, "|" + "---|" * (len(GUARANTEE_COLUMNS) + 1)]
    for preset, tolerances in TOLERANCES.items():
        cells = [_seconds(tolerances[key]) if key == "time" else f"{tolerances[key]:.0e}".replace("e-0", "e-")
                 for key in GUARANTEE_COLUMNS]
        rows.append(f"| `{preset}` | " + " | ".join(cells) + " |")
    return "\n".join(rows) + "\n"


def _ratio_rows(mapping: dict, fmt: str = "{:.2f}x") -> list[str]:
    return [f"| {name} | {fmt.format(value)} |" for name, value in mapping.items()]


def _scipy_tables(section: dict) -> list[str]:
    """Issue #24's comparison (``scripts/bench_scipy.py``): the plain scipy script, how it was searched, the
    product's runs and, per variant, preset and metric, the fastest script at equal accuracy.  Keys a benchmark
    written before they existed did not record are left out."""
    script = section.get("script")
    search = ""
    if script is not None:
        search = (f" Searched: {', '.join(script['methods'])} at rtol {script['rtol_first']:.0e} down to "
                  f"{script['rtol_last']:.0e} ({script['rtol_count']} values), atol = rtol x "
                  f"{script['atol_per_rtol']:g}; a method's tolerance for a metric is the loosest from which on "
                  f"every tighter one of the scan reaches the preset's error and finds the reference's impacts; "
                  f"medians of {script['repeats']} interleaved rounds.")
    parts = ["### A plain scipy script at equal accuracy, per metric\n",
             "The fastest of scipy's `solve_ivp` methods (`scripts/plain_scipy.py`, written from the equations with "
             "numpy and scipy only) at the loosest tolerance that is as accurate as the preset on each metric "
             "separately, against the same event-driven reference at rtol 1e-12; the ratio is the script's wall time "
             "(solve and metrics) over the product's complete run (assembly, solve, all of its post-processing)."
             + search + "\n"]
    if "presets" in section:
        parts += ["The product's runs, and the same run if its solve cost Exudyn's floor per step (the same system "
                  "with built-in laws, no sensors, no pre-step function; the rest of the run unchanged):\n",
                  "| preset | steps | complete run | solve | solve per step | Exudyn's floor per step | "
                  "the run at the floor |", "|---|---:|---:|---:|---:|---:|---:|",
                  *[f"| `{preset}` | {run['steps']} | {run['complete_s'] * 1e3:.2f} ms | {run['solve_s'] * 1e3:.2f} ms "
                    f"| {run['solve_s'] / run['steps'] * 1e6:.2f} µs | {run['floor_step_s'] * 1e6:.2f} µs | "
                    f"{run['floor_run_s'] * 1e3:.2f} ms |" for preset, run in section["presets"].items()], ""]
    detailed = all("atol" in row for row in section["scipy"])

    def chosen(row: dict) -> str:
        if row["ratio"] is None:
            return "none reached it | | | - | - | -" if detailed else "none reached it | -"
        if not detailed:
            return f"{row['method']} rtol {row['rtol']:.2g} | {row['ratio']:.2f}x"
        return (f"{row['method']} rtol {row['rtol']:.2g}, atol {row['atol']:.2g} | {row['error']:.1e} | "
                f"{row['evaluations']} | {row['ratio']:.2f}x | {row['floor_bound']:.2f}x | {row['ceiling']:.2f}x")

    if detailed:
        parts.append("Per metric: the fastest script, the error it reached, its evaluations of the right-hand side, "
                     "the ratio, the ratio if the product's solve cost Exudyn's floor per step (the rest of its run "
                     "as measured), and if its whole run did (nothing but Exudyn's floor at the preset's steps: the "
                     "most any product on Exudyn could reach).\n")
        header = ["| script | preset | metric | preset's error | fastest script | its error | evaluations of f | "
                  "scipy / product | solve at the floor | whole run at the floor | issue's target |",
                  "|---|---|---|---:|---|---:|---:|---:|---:|---:|---:|"]
    else:
        header = ["| script | preset | metric | preset's error | fastest script | scipy / product | issue's target |",
                  "|---|---|---|---:|---|---:|---:|"]
    parts += [*header, *[f"| {row['variant']} | `{row['preset']}` | {row['metric']} | {row['target_error']:.1e} | "
                         f"{chosen(row)} | >= {row['issue_target']:g}x |" for row in section["scipy"]], ""]
    return parts


def bench_tables(data: dict) -> str:
    errors = ", ".join(f"{name.replace('_', ' ')} {value:.1e}" for name, value in data["standard"]["errors"].items())
    parts = [
        f"Measured on {data['date']} with `{data['command']}` ({data['scene']}, {data['end_time_s']:g} s simulated, "
        f"medians of {data['repeats']} interleaved rounds) on a machine with {data['cpus']} CPUs. Machine load: wall / "
        f"CPU time of the `standard` run {data['machine_load']:.2f} (1.00 = the run had a core to itself), 1-minute "
        f"load average {data['load_average_1min']:.1f} at the end of the run (other jobs were running). The "
        f"`standard` run took {data['standard']['steps']} steps; its errors against a tight reference: {errors}.\n",
        "### Against other integrators of the same equations\n",
        "| ratio (wall time) | measured |", "|---|---:|", *_ratio_rows(data["ratios"]), "",
        "### Where one run's time goes\n",
        "Fractions of one complete `standard` run (the import: once per process, relative to one run).\n",
        "| stage | share |", "|---|---:|",
        *[f"| {name} | {value:.1f}x |" if name.startswith("import") else f"| {name} | {100 * value:.1f} % |"
          for name, value in data["breakdown"].items()], "",
    ]
    if data.get("step_layers"):
        parts += ["### What a step adds to Exudyn's floor\n",
                  "The `standard` solve with one layer of the product added at a time (the items folded as the engine "
                  "assembles them). Without the laws' user functions the contact is gone and the motion differs: "
                  "compare per step. An attempt is an accepted or a rejected step; Exudyn evaluates every item at every "
                  "stage of both.\n",
                  "| solve | steps | rejected | per step | / floor | per attempt | / floor |",
                  "|---|---:|---:|---:|---:|---:|---:|",
                  *[f"| {row['name']} | {row['steps']} | {row['rejected']} | {row['per_step_s'] * 1e6:.2f} µs | "
                    f"{row['per_step_over_floor']:.2f}x | {row['per_attempt_s'] * 1e6:.2f} µs | "
                    f"{row['per_attempt_over_floor']:.2f}x |" for row in data["step_layers"]], ""]
    if "elements" in data:
        parts += ["### What elements cost\n",
                  "The same motion split over n absorbers (cost relative to one absorber), and capturing the onset "
                  "rate of the restitution laws inside the solve.\n",
                  "| case | complete run | solve per step |", "|---|---:|---:|",
                  *[f"| {name} | {values['complete run']:.2f}x | {values['solve per step']:.2f}x |"
                    for name, values in data["elements"].items()], ""]
    if data.get("targets"):
        parts += ["### Issue #11's targets\n", "| ratio | measured | target | |", "|---|---:|---|---|",
                  *[f"| {row['name']} | {row['value']:.2f} | {row['target']} | {'met' if row['met'] else 'not met'} |"
                    for row in data["targets"]], ""]
    if "carriage" in data:
        floor = data["carriage"]
        parts += ["### The gun on its carriage\n",
                  "A carriage scene against its 1-D twin (the same hardware on a fixed mount), per simulated second. "
                  f"Exudyn's own floor: a bare tree of the planar links costs "
                  f"{floor['bare_tree_us'] / floor['bare_mass_us']:.1f}x a bare 1-D mass per fixed DOPRI5 step "
                  f"({floor['bare_tree_us']:.1f} against {floor['bare_mass_us']:.1f} us).\n",
                  "| scene | preset | complete run | solve | steps |", "|---|---|---:|---:|---:|",
                  *[f"| `{row['scene']}` | `{row['preset']}` | {row['run_ratio']:.1f}x | {row['solve_ratio']:.1f}x | "
                    f"{row['step_ratio']:.2f}x |" for row in floor["rows"]], ""]
    if "issue24" in data:
        parts += _scipy_tables(data["issue24"])
        section = data["issue24"]
        if "now_before" in section:
            parts += ["### Now against the code before the speed work\n",
                      f"Ratios now / before (commit `{section['commit'][:12]}`), both trees measured in the same run, "
                      "interleaved (below 1: faster now).\n",
                      "| measurement | now / before |", "|---|---:|",
                      *[f"| {name} | {value:.3f} |" for name, value in section["now_before"].items()], ""]
        if section.get("import_floor_s"):  # (measured on compiled bytecode, as installed, beside its floor)
            floor = section["import_floor_s"]
            parts += ["### Import to the first result\n",
                      "A fresh interpreter that imports the package and runs a first `simulate` (what every CLI call "
                      "and sweep worker pays), process wall time, beside the floor no change of this package moves "
                      "(medians of the same interleaved rounds; the package compiled to bytecode, as installed).\n",
                      "| process | wall time |", "|---|---:|",
                      f"| `import mbs_models` and a first result | {_milliseconds(section['import_process_s'])} |",
                      *[f"| {name} | {_milliseconds(value)} |" for name, value in floor.items()], ""]
    return "\n".join(parts)


def _milliseconds(seconds: float) -> str:
    return f"{seconds * 1e3:.0f} ms"


def _generate(app) -> None:
    src = Path(app.srcdir)
    write_if_changed(src / "validation" / "_guarantee.md", guarantee_table())
    data = json.loads((src / "_generated" / "bench.json").read_text())
    write_if_changed(src / "performance" / "_bench.md", bench_tables(data))


def setup(app):
    app.connect("builder-inited", _generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
