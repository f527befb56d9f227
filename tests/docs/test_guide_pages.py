"""The user guide's examples run and its tables are the library's (what tests/test_readme.py checked while the README
held them): code blocks executed, tables recomputed or compared with the constants they state, console blocks
compared with what the command prints, and every ``{{ name }}`` a page quotes defined in docs/numbers_guide.py."""

from __future__ import annotations

import importlib.util
import json
import re
import subprocess
import sys

import pytest
from guide_pages import (DOCS, ROOT, check_console_output, console_blocks, line_matches, page, pages,
                         python_block_after, table_rows)

from mbs_models import load_scene, model_i, model_ii, simplified_model, simulate
from mbs_models.scenes import scene_path


# ---------------------------------------------------------------------------------------------- the numbers' names

def _numbers_guide():
    spec = importlib.util.spec_from_file_location("numbers_guide", DOCS / "numbers_guide.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_quoted_number_is_defined_and_every_defined_one_quoted():
    """A page's ``{{ name }}`` names an entry of docs/numbers_guide.py, each entry to the contract (compute,
    format, rel_tol, why), and each entry is quoted somewhere (DOCS_LAYOUT.md: no unknown name, no unused entry)."""
    numbers = _numbers_guide().NUMBERS
    used = {name for path in pages() for name in re.findall(r"\{\{\s*(\w+)\s*\}\}", path.read_text())}
    assert used - numbers.keys() == set()
    assert numbers.keys() - used == set()
    for name, entry in numbers.items():
        assert set(entry) == {"compute", "format", "rel_tol", "why"} and callable(entry["compute"]), name
        assert 0 < entry["rel_tol"] < 1 and entry["why"], name


def test_the_stale_numbers_of_the_former_readme_are_the_computed_ones():
    """Issue #25's stale numbers, recomputed by the entries that quote them and checked against what the commands
    print: the realistic system's battery buffer takes 72.4 kN and the mount 39.4 kN on counter-recoil (the former
    README gave the buffer 39 kN), and `recoil contact-laws` differs from the closed form by ~1.5e-7, not 2e-6."""
    numbers = _numbers_guide().NUMBERS
    realistic = json.loads(subprocess.run(
        [sys.executable, "-m", "mbs_models", "run", "realistic", "--end-time", "3", "--json"], capture_output=True,
        text=True, cwd=ROOT, timeout=600, check=True).stdout)
    buffer = next(stop for stop in realistic["stops"] if stop["name"] == "battery_stop")
    assert numbers["realistic_buffer_force"]["compute"]() == pytest.approx(buffer["peak_contact_force"] / 1e3,
                                                                             rel=1e-3)
    assert numbers["realistic_buffer_force"]["compute"]() > 1.5 * numbers["realistic_mount_on_return"]["compute"]()
    assert numbers["contact_laws_worst_difference"]["compute"]() < 1e-6


# ---------------------------------------------------------------------------------------------- code blocks

def test_the_version_2_example_runs(capsys):
    exec(compile(python_block_after(page("guide/scene-format.md"), "## Shipped scenes"), "scene-format.md", "exec"),
         {})
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("front ") and lines[1].startswith("rear ")


def test_the_building_block_example_runs_and_rebounds_with_the_restitution_asked(capsys):
    """The guide's hand-built Exudyn model with our contact: exact-restitution gives e = 0.6."""
    block = python_block_after(page("guide/building-blocks.md"), "# Building blocks")
    exec(compile(block, "building-blocks.md", "exec"), {})
    out = capsys.readouterr().out
    restitution = float(re.search(r"restitution (\S+)", out).group(1))
    assert restitution == pytest.approx(0.6, abs=1e-6)
    assert float(re.search(r"peak force (\S+) N", out).group(1)) > 0


def test_the_sweep_example_runs_and_gives_the_table(capsys):
    """The guide's run_sweep example: a 2 x 2 grid, every point ok."""
    namespace: dict = {}
    exec(compile(python_block_after(page("guide/sweep.md"), "## `recoil sweep`"), "sweep.md", "exec"), namespace)
    table = namespace["table"]
    assert len(table) == 4 and (table["status"] == "ok").all()
    assert table["contact.gap"].tolist() == [0.0, 0.04, 0.0, 0.04]
    assert "peak_support_force" in capsys.readouterr().out


def test_the_early_stop_example_prints_what_its_comment_says(capsys):
    """The "From Python" block's early stop: the commented end time (s), stop reason and maximum (m)."""
    lines = python_block_after(page("guide/python.md"), "# From Python").splitlines()
    i = next(n for n, line in enumerate(lines) if "stop_when_final=" in line and line.startswith("result ="))
    call, printed = lines[i], lines[i + 1]
    match = re.search(r"# ~(\S+) s, (\w+), (\S+) m$", printed)
    assert match, printed
    exec(compile(f"from mbs_models import model_ii, simulate\n{call}\n{printed}", "python.md", "exec"), {})
    end_time, reason, x_max = capsys.readouterr().out.split()
    assert float(end_time) == pytest.approx(float(match.group(1)), abs=0.006)
    assert reason == match.group(2)
    assert f"{float(x_max):.4f}" == match.group(3)


def test_the_getting_started_example_runs(capsys):
    exec(compile(python_block_after(page("getting-started.md"), "## A first run"), "getting-started.md", "exec"), {})
    x_max, force = capsys.readouterr().out.splitlines()[0].split()
    assert 0.1 < float(x_max) < 0.3 and float(force) > 0


def test_the_own_element_example_is_the_example_modules_law():
    """The guide's "Adding your own element" block, run in a process of its own (it registers a table), gives the
    run of ``examples/progressive_spring.py`` bit for bit (one law, written twice: the page's copy cannot drift)."""
    block = python_block_after(page("guide/own-element.md"), "# Adding your own element")
    run = ("from mbs_models import load_scene, simulate\n"
           "r = simulate(load_scene('examples/progressive_spring.toml'), 0.5, 'draft')\n"
           "print(r.max_barrel_displacement.hex(), r.peak_support_force.hex())\n")
    outputs = []
    for prelude in (block, "import runpy; runpy.run_path('examples/progressive_spring.py')\n"):
        done = subprocess.run([sys.executable, "-c", prelude + "\n" + run], capture_output=True, text=True, cwd=ROOT,
                              timeout=300)
        assert done.returncode == 0, done.stderr[-2000:]
        outputs.append(done.stdout.split()[-2:])
    assert outputs[0] == outputs[1]


# ---------------------------------------------------------------------------------------------- tables

_GUARANTEE_ROW = re.compile(r"^\| `(draft|standard|reference)` \| (\S+) \| (\S+) \| (\S+) \| (\S+) \| (\d+) (ms|µs) \|$")


def test_the_guarantee_table_is_the_tested_tolerances():
    """The accuracy page's guarantee table states exactly the bounds tests/test_hard_cases.py enforces."""
    from validation.studies.guarantee import TOLERANCES

    rows = table_rows(page("guide/accuracy.md"), _GUARANTEE_ROW)
    assert [r[0] for r in rows] == list(TOLERANCES)
    for preset, energy, metric, force, impact_peak, time_value, unit in rows:
        tol = TOLERANCES[preset]
        assert (float(energy), float(metric), float(force), float(impact_peak)) == (
            tol["energy"], tol["metric"], tol["force"], tol["impact_peak"]), preset
        assert float(time_value) * (1e-3 if unit == "ms" else 1e-6) == pytest.approx(tol["time"], rel=1e-12), preset


_PRESET_ROW = re.compile(r"^\| `(draft|standard|reference)`(?: \(default\))? \| DOPRI5 rtol (\S+), atol (\S+), "
                         r"max step (\d+) ms \| (\S+) / (\S+) / (\S+) \|$")


def test_the_presets_table_is_the_presets_and_their_stated_bounds():
    """Each preset's settings are ACCURACY_PRESETS' and its bounds PRESET_ERROR_BOUNDS' (which
    tests/validation/studies/test_presets.py holds the presets to)."""
    from mbs_models.engine.accuracy import ACCURACY_PRESETS
    from validation.studies.precision import PRESET_ERROR_BOUNDS, PRESET_METRICS

    rows = table_rows(page("guide/accuracy.md"), _PRESET_ROW)
    assert [r[0] for r in rows] == list(ACCURACY_PRESETS)
    for preset, rtol, atol, max_step_ms, *bounds in rows:
        settings = ACCURACY_PRESETS[preset]
        assert (settings.solver, float(rtol), float(atol)) == ("DOPRI5", settings.relative_tolerance,
                                                                settings.absolute_tolerance), preset
        assert float(max_step_ms) * 1e-3 == pytest.approx(settings.max_step, rel=1e-12), preset
        assert [float(b) for b in bounds] == [PRESET_ERROR_BOUNDS[preset][m] for m in PRESET_METRICS], preset


def test_the_realistic_table_of_shots():
    """The realistic page's shots are the scene's (7.5 s: three shots)."""
    result = simulate(load_scene(scene_path("realistic")), 7.5)
    text = page("guide/realistic.md")
    for shot in result.shots:
        battery = "--" if shot["in_battery_at_next_shot"] is None else ("yes" if shot["in_battery_at_next_shot"] else "no")
        row = (f"| {shot['shot']} | {shot['time']:.1f} | {1e3 * shot['max_barrel_displacement']:.1f} | {battery} | "
               f"{shot['time_to_battery']:.3f} |")
        assert row in text, row


_OPTIMISED_ROW = re.compile(r"^\| (--|model \(i\)|model \(ii\)) \| "
                            r"(simplified model|Table 2|gap alone, [AB]|[AB]: [^|]+) \| "
                            r"(--|\d+) \| (--|\d+\.?\d*) \| (\d+\.\d\d) \| (\d+\.\d{3}) \|$")


def test_the_optimised_absorbers_are_the_scripts_and_the_engines():
    """The optimised-absorber table: the numbers scripts/optimise_absorbers.py wrote, and the engine's at those
    designs (full 10 s runs)."""
    data = json.loads((DOCS / "optimise_absorbers.json").read_text())
    rows = table_rows(page("guide/optimise.md"), _OPTIMISED_ROW)
    assert len(rows) == 14
    for mount, design, mass, gap, length, force in rows:
        factory = model_i if mount == "model (i)" else model_ii
        if design == "simplified model":
            values, scene = data["simplified"], simplified_model()
        elif design == "Table 2":
            assert gap == "0"
            values, scene = data["mounts"][mount]["paper_designs"][mass], factory(float(mass), 0.0)
        elif design.startswith("gap alone"):
            best = data["mounts"][mount]["gap_only"][mass][design[-1]]
            assert gap == f"{best['gap'] * 1e3:.1f}"
            values, scene = best["full_run"], factory(float(mass), best["gap"])
        else:
            best = data["mounts"][mount][design[0]]
            parameters = best["parameters"]
            assert best["feasible"] and (mass, gap) == (f"{parameters['absorber.mass']:.0f}",
                                                        f"{parameters['contact.gap'] * 1e3:.1f}")
            values = best["full_run"]["standard"]
            scene = factory(parameters["absorber.mass"], parameters["contact.gap"])
        assert (length, force) == (f"{values['max_barrel_displacement'] * 1e3:.2f}",
                                   f"{values['peak_support_force'] / 1e3:.3f}"), (mount, design, mass)
        result = simulate(scene, 10.0)
        assert (length, force) == (f"{result.max_barrel_displacement * 1e3:.2f}",
                                   f"{result.peak_support_force / 1e3:.3f}"), (mount, design, mass)


# ---------------------------------------------------------------------------------------------- console blocks

#: Commands too long for the fast suite (an optimisation of 500+ runs).
_SLOW = ("optimise",)


@pytest.mark.parametrize("block", [pytest.param(b, id=b.name, marks=[pytest.mark.slow] if b.args[0] in _SLOW else [])
                                   for b in console_blocks()])
def test_a_console_block_is_what_the_command_prints(block, tmp_path):
    """``$ recoil ...`` run in an empty directory (scene paths of the repository made absolute): its stdout and
    stderr are the lines the page shows, numbers within what the page's digits and another CPU allow."""
    args = [str(ROOT / a) if (ROOT / a).is_file() and "/" in a else a for a in block.args]
    done = subprocess.run([sys.executable, "-m", "mbs_models", *args], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, cwd=tmp_path, timeout=900)
    problem = check_console_output(block.expected, done.stdout.splitlines())
    assert problem is None, problem


def test_the_console_check_can_fail():
    """The comparison refuses another number, another word, a missing line and an extra one."""
    shown = ("  max barrel displacement  0.153718 m at 0.50426 s", "  impacts (> 1 kN)      8")
    printed = ["  max barrel displacement  0.153718 m at 0.50426 s", "  impacts (> 1 kN)      8"]
    assert check_console_output(shown, printed) is None
    assert check_console_output(shown, [printed[0].replace("0.153718", "0.154718"), printed[1]]) is not None
    assert check_console_output(shown, [printed[0].replace("barrel", "absorber"), printed[1]]) is not None
    assert check_console_output(shown, printed[:1]) is not None
    assert check_console_output(shown, printed + ["extra"]) is not None
    assert check_console_output((*shown, "..."), printed + ["extra"]) is None
    assert line_matches("rel. error 8.46e-11 at … s", "rel. error 9.1e-11 at 1.5 s")
    assert not line_matches("error 8.46e-11", "error 3.2e-3")
