"""The replication report builds on a reduced sweep, and every figure and table is present."""

from __future__ import annotations

import json
import re
from html.parser import HTMLParser

import pytest

from mbs_models.cli import main
from validation.studies.report import ReportOptions, _sketch, write_report


class _Collector(HTMLParser):
    def __init__(self):
        super().__init__()
        self.ids, self.images, self.tables = set(), [], 0

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            self.ids.add(attrs["id"])
        if tag == "img":
            self.images.append(attrs.get("src", ""))
        if tag == "table":
            self.tables += 1


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    write_report(out, ReportOptions.reduced())
    return out


def test_report_html_has_every_section_figure_and_table(report_dir):
    text = (report_dir / "report.html").read_text()
    parser = _Collector()
    parser.feed(text)
    for section in ("models", "parameters", "table2", "sweeps", "histories", "contact", "engine-vs-reference",
                    "conventions", "calibration", "claims", "unreproduced", "cost"):
        assert section in parser.ids, section
    for table in ("parameters", "table2", "section22", "engine-vs-reference", "conventions", "calibration-table2",
                  "claims"):
        assert f"tab-{table}" in parser.ids, table
    expected_figures = {"fig4_gap_sweep_model_i", "fig5_gap_sweep_model_ii", "conventions_gap_trend",
                        "support_force_m1000"} | {
        f"{stem}_m{m}" for stem in ("barrel_displacement", "contact_force", "absorber_velocity", "first_impact")
        for m in (100, 500, 1000)}
    assert {f"fig-{name}" for name in expected_figures} <= parser.ids
    # self-contained: every image is embedded PNG data, no external references
    assert len(parser.images) == len(expected_figures)
    assert all(src.startswith("data:image/png;base64,") and len(src) > 5000 for src in parser.images)
    assert not re.search(r'src="(http|file|/)', text)
    for name in expected_figures:
        assert (report_dir / f"{name}.png").read_bytes()[:4] == b"\x89PNG"


def test_results_json_is_complete_and_honest(report_dir):
    data = json.loads((report_dir / "results.json").read_text())
    for key in ("table2", "section22", "engine_vs_reference", "gap_sweeps", "conventions", "calibration",
                "claims", "unreproduced", "timings"):
        assert key in data, key
    assert len(data["table2"]) == 9
    assert all(case["passed"] for case in data["engine_vs_reference"])
    # the known discrepancies are listed, not hidden
    listed = " ".join(item["published"] for item in data["unreproduced"])
    assert "Table 2, model (ii), m = 100 kg" in listed and "Table 2, model (ii), m = 500 kg" in listed
    assert all(item["reason"] for item in data["unreproduced"])
    assert len(data["claims"]) == 14
    assert not list(report_dir.glob(".*.tmp")), "no temporary files left behind"


def test_paper_command_into_unwritable_place_is_bad_input(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["paper", "--quick", "--out", str(blocker)]) == 2
    assert "--out" in capsys.readouterr().err


@pytest.mark.slow
def test_full_report_builds(tmp_path):
    """The main job's report: 1 mm gap sweeps, every reading, the 19 paper cases, 3-parameter calibration."""
    data = write_report(tmp_path, ReportOptions())
    assert len(data["comparisons"]) == 19 and all(c["passed"] for c in data["comparisons"])
    assert all(len(points) == 121 for points in data["sweeps"].values()) and len(data["sweeps"]) == 6
    assert not data["sweep_failures"]
    assert (tmp_path / "report.html").stat().st_size > 100_000


# ----------------------------------------------------------------------------------- force on the mount
#: Section 2.1 of the paper, for bounds on the force on the mount that do not come from the code under test.
RECOIL_STIFFNESS = 27500.0                    # k, N/m
RECOIL_DAMPING = 6239.0                       # c while x_M' > 0, N s/m
INITIAL_VELOCITY = 6.86 * 564.0 / 5600.0      # v0 = m_p v_p / M, m/s


def _markdown_rows(text: str) -> list[dict]:
    lines = [line for line in text.splitlines() if line.startswith("|") and not line.startswith("|---")]
    headers = [cell.strip() for cell in lines[0].strip("|").split("|")]
    return [dict(zip(headers, (cell.strip() for cell in line.strip("|").split("|")))) for line in lines[1:]]


def test_table2_gives_the_force_on_the_mount(report_dir):
    table = json.loads((report_dir / "table2.json").read_text())
    assert table["units"]["peak_support_force"] == "N" and table["units"]["engine"] == "m"
    rows = {(r["model"], r["absorber_mass"]): r for r in table["rows"]}
    assert len(rows) == 9
    for (model, mass), r in rows.items():
        force = r["peak_support_force"]
        # at t = 0 the barrel moves at v0 and nothing else touches the ground: the mount feels c v0
        assert force >= RECOIL_DAMPING * INITIAL_VELOCITY * (1 - 1e-6), (model, mass)
        if model != "model (ii)":  # the barrel stops at its largest displacement: the recoil spring alone, k x_max
            assert force >= RECOIL_STIFFNESS * r["engine"] * (1 - 1e-6), (model, mass)
        assert 0.0 <= r["time_of_peak_support_force"] <= 10.0
    assert len({rows[("simplified", m)]["peak_support_force"] for m in (100.0, 500.0, 1000.0)}) == 1
    # table2.md: the same numbers, in kN
    for row in _markdown_rows((report_dir / "table2.md").read_text()):
        expected = rows[(row["model"], float(row["m [kg]"]))]["peak_support_force"] / 1e3
        assert float(row["peak support force [kN]"]) == pytest.approx(expected, abs=0.005)
    # results.json: the same rows, from the same gap-0 runs as the time histories
    results = json.loads((report_dir / "results.json").read_text())
    assert [r["peak_support_force"] for r in results["table2"]] == [r["peak_support_force"] for r in table["rows"]]
    for (model, mass), r in rows.items():
        key = model if model == "simplified" else f"{model}:{mass:g}"
        assert results["time_histories"][key]["peak_support_force"] == r["peak_support_force"]


# ------------------------------------------------------------------------------------------ model sketches
@pytest.mark.parametrize("name", ["simplified_model", "model_i", "model_ii"])
def test_model_sketch_is_the_docstrings_drawing_with_its_indentation(name):
    from mbs_models.scene import models

    func = getattr(models, name)
    sketch = _sketch(func).splitlines()
    assert len(sketch) >= 4, sketch
    assert any(line.startswith("|") for line in sketch), "the ground line of the drawing, moved to the left edge"
    assert any(line.startswith(" ") for line in sketch), "the drawing's own indentation is kept"
    # every line of the sketch is a line of the docstring, all shifted left by the same amount
    doc = func.__doc__.splitlines()
    ground = next(line for line in sketch if line.startswith("|"))
    shift = next(len(d) - len(ground) for d in doc if d.endswith(ground) and not d[:len(d) - len(ground)].strip())
    assert all(" " * shift + line in doc for line in sketch if line.strip())
    assert "Parameters" not in "\n".join(sketch)


def _first_line_block():
    """A drawing::

            top
        |--+
        |  |

    After the drawing.
    """


def _later_paragraph_block():
    """Summary.

    The drawing follows::

        a
          b

        c
    Text again.
    """


def _drawing_only():
    """Only a drawing::

            x
        |---|
    """


def _no_block():
    """No drawing here: just text."""


@pytest.mark.parametrize("func, expected", [
    (_first_line_block, "    top\n|--+\n|  |"),
    (_later_paragraph_block, "a\n  b\n\nc"),
    (_drawing_only, "    x\n|---|"),
    (_no_block, ""),
])
def test_sketch_extraction_follows_the_literal_block(func, expected):
    assert _sketch(func) == expected
