"""The README's numbers are the library's numbers (Table 2 is recomputed and compared) and its examples run.

The examples, tables and console output of the user guide, which the README held before, are checked by
tests/docs/test_guide_pages.py."""

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


def _python_blocks() -> list[str]:
    return [block[:block.index("```")] for block in README.read_text().split("```python\n")[1:]]


def test_the_readmes_python_taste_runs(capsys):
    """The README's Python block: model (ii) at gap 40 mm, and the two absorbers of the shipped scene."""
    blocks = _python_blocks()
    assert len(blocks) == 1
    exec(compile(blocks[0], "README", "exec"), {})
    lines = capsys.readouterr().out.splitlines()
    x_max, force = (float(v) for v in lines[0].split())
    assert 0.1 < x_max < 0.3 and force > 0
    assert lines[-2].startswith("front ") and lines[-1].startswith("rear ")


def test_the_readme_is_short_and_keeps_the_two_commands():
    """At most ~200 lines (issue #25), and the install + test command .ci/run and the tests rely on."""
    text = README.read_text()
    assert len(text.splitlines()) <= 200
    assert "bash scripts/test.sh " in text and "bash scripts/paper.sh --out out" in text
    assert "bash scripts/test.sh" in (README.parent / ".ci" / "run").read_text()


def test_the_readmes_links_and_figure_resolve():
    """Every relative link and image of the README names a file of the repository.  The documentation site's pages
    of another part (docs/theory, validation, performance, reference) are only required once that part is there."""
    root = README.parent
    targets = re.findall(r"\]\(((?!https?://)[^)#\s]+)\)", README.read_text())
    assert "docs/figures/two_absorbers.png" in targets
    missing = [t for t in targets if not (root / t).exists()]
    assert [t for t in missing if (root / Path(t).parent).is_dir() or not t.startswith("docs/")] == []
