"""The README's numbers are the library's numbers (Table 2 is recomputed and compared)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from mbs_models import model_i, model_ii, simplified_model, simulate

README = Path(__file__).resolve().parent.parent / "README.md"
_ROW = re.compile(r"^\| (simplified|model \(i\)|model \(ii\)) \| (any|\d+) \| (0\.\d{4}) \| (0\.\d{4}) \| ([+−-]\d+\.\d+) \|$")


def _readme_table2():
    rows = [m.groups() for line in README.read_text().splitlines() if (m := _ROW.match(line))]
    assert len(rows) == 7, "README Table 2 must list the simplified model and 3 masses of each model"
    return rows


@pytest.mark.parametrize("row", _readme_table2(), ids=lambda r: f"{r[0]}-{r[1]}")
def test_readme_table2_matches_the_engine(row):
    model, mass, ours, paper, difference_mm = row
    if model == "simplified":
        scene = simplified_model()
    else:
        scene = (model_i if model == "model (i)" else model_ii)(float(mass), 0.0)
    x_max = simulate(scene, 10.0).max_barrel_displacement
    assert f"{x_max:.4f}" == ours
    assert float(difference_mm.replace("−", "-")) == pytest.approx((x_max - float(paper)) * 1e3, abs=0.006)


_GUARANTEE_ROW = re.compile(r"^\| `(draft|standard|reference)` \| (\S+) \(worst [^)]*\) \| (\S+) \(worst [^)]*\) \| "
                            r"(\S+) \(worst [^)]*\) \| (\S+) \(worst [^)]*\) \| (\d+) (ms|µs) \(worst [^)]*\) \|$")


def test_readme_guarantees_are_the_tested_tolerances():
    """The "What is guaranteed" table states exactly the bounds tests/test_hard_cases.py enforces."""
    from validation.studies.guarantee import TOLERANCES

    rows = [m.groups() for line in README.read_text().splitlines() if (m := _GUARANTEE_ROW.match(line))]
    assert [r[0] for r in rows] == list(TOLERANCES)
    for preset, energy, metric, force, impact_peak, time_value, unit in rows:
        tol = TOLERANCES[preset]
        assert (float(energy), float(metric), float(force), float(impact_peak)) == (
            tol["energy"], tol["metric"], tol["force"], tol["impact_peak"]), preset
        assert float(time_value) * (1e-3 if unit == "ms" else 1e-6) == pytest.approx(tol["time"], rel=1e-12), preset


def _python_block_after(heading: str) -> str:
    text = README.read_text()
    section = text[text.index(heading):]
    start = section.index("```python\n") + len("```python\n")
    return section[start:section.index("```", start)]


def test_the_building_block_example_runs_and_rebounds_with_the_restitution_asked(capsys):
    """The README's hand-built Exudyn model with our contact: exact-restitution gives e = 0.6."""
    exec(compile(_python_block_after("### Building blocks for your own Exudyn scripts"), "README", "exec"), {})
    out = capsys.readouterr().out
    restitution = float(re.search(r"restitution (\S+)", out).group(1))
    assert restitution == pytest.approx(0.6, abs=1e-6)
    assert float(re.search(r"peak force (\S+) N", out).group(1)) > 0


def test_the_version_2_example_runs(capsys):
    exec(compile(_python_block_after("### Richer mechanisms: scene format version 2"), "README", "exec"), {})
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("front ") and lines[1].startswith("rear ")


def test_the_sweep_example_runs_and_gives_the_table(capsys):
    """The README's run_sweep example: a 2 x 2 grid, every point ok."""
    namespace: dict = {}
    exec(compile(_python_block_after("### `recoil sweep`"), "README", "exec"), namespace)
    table = namespace["table"]
    assert len(table) == 4 and (table["status"] == "ok").all()
    assert table["contact.gap"].tolist() == [0.0, 0.04, 0.0, 0.04]
    assert "peak_support_force" in capsys.readouterr().out


def test_the_early_stop_example_prints_what_its_comment_says(capsys):
    """The "From Python" block's early stop: the commented end time (s), stop reason and maximum (m)."""
    block = _python_block_after("### From Python")
    lines = block.splitlines()
    i = next(n for n, line in enumerate(lines) if "stop_when_final=" in line and line.startswith("result ="))
    call, printed = lines[i], lines[i + 1]
    match = re.search(r"# ~(\S+) s, (\w+), (\S+) m$", printed)
    assert match, printed
    exec(compile(f"from mbs_models import model_ii, simulate\n{call}\n{printed}", "README", "exec"), {})
    end_time, reason, x_max = capsys.readouterr().out.split()
    assert float(end_time) == pytest.approx(float(match.group(1)), abs=0.006)
    assert reason == match.group(2)
    assert f"{float(x_max):.4f}" == match.group(3)


_OPTIMISED_ROW = re.compile(r"^\| (--|model \(i\)|model \(ii\)) \| "
                            r"(simplified model|Table 2|gap alone, [AB]|[AB]: [^|]+) \| "
                            r"(--|\d+) \| (--|\d+\.?\d*) \| (\d+\.\d\d) \| (\d+\.\d{3}) \|$")


def test_readme_optimised_absorbers_are_the_scripts_and_the_engines():
    """The optimised-absorber table: the numbers scripts/optimise_absorbers.py wrote, and the engine's at
    those designs (full 10 s runs)."""
    import json

    data = json.loads((README.parent / "docs" / "optimise_absorbers.json").read_text())
    rows = [m.groups() for line in README.read_text().splitlines() if (m := _OPTIMISED_ROW.match(line))]
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


def test_the_own_element_example_is_the_example_modules_law():
    """The README's "Adding your own element" block, run in a process of its own (it registers a table), gives the
    run of ``examples/progressive_spring.py`` bit for bit (one law, written twice: the README's copy cannot drift)."""
    import subprocess
    import sys

    root = README.parent
    block = _python_block_after("### Adding your own element")
    run = ("from mbs_models import load_scene, simulate\n"
           "r = simulate(load_scene('examples/progressive_spring.toml'), 0.5, 'draft')\n"
           "print(r.max_barrel_displacement.hex(), r.peak_support_force.hex())\n")
    outputs = []
    for prelude in (block, "import runpy; runpy.run_path('examples/progressive_spring.py')\n"):
        done = subprocess.run([sys.executable, "-c", prelude + "\n" + run], capture_output=True, text=True, cwd=root,
                              timeout=300)
        assert done.returncode == 0, done.stderr[-2000:]
        outputs.append(done.stdout.split()[-2:])
    assert outputs[0] == outputs[1]
