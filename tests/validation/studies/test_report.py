"""The replication report builds on a reduced sweep, and every figure and table is present.

The page is also read as a browser would: :func:`page_problems` parses it with ``html.parser`` and lists
what a reader would see as broken (empty boxes, dead links, images that are not PNGs, ...).
"""

from __future__ import annotations

import base64
import html
import json
import re
import struct
import zlib
from html.parser import HTMLParser

import pytest

from mbs_models.cli import main
from validation.studies.report import ReportOptions, _sketch, write_report


# ------------------------------------------------------------------------------------- reading the page
#: Characters an ASCII drawing is made of.
DRAWING = set("|/\\-=+[]<>")
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
SUPPORT_FORCE_HEADER = "peak support force [kN]"
#: The header's fields (label -> what its text must look like): the paper's title, when and with what.
HEADER_FIELDS = {
    "Paper replicated": r"analysis of a dynamic system subjected to an impulsive and internal contact force",
    "Made on": r"\d{4}-\d\d-\d\d \d\d:\d\d( UTC)?",
    "Package": r"recoil-mbs \d+\.\d+\.\d+\S*",
    "Commit": r"([0-9a-f]{40}( \(uncommitted changes\))?|unknown)",
    "Exudyn": r"(\d+\.\d+\S*|unknown)", "numpy": r"(\d+\.\d+\S*|unknown)", "scipy": r"(\d+\.\d+\S*|unknown)",
    "Machine": r".+, \d+ CPUs",
}


class _Page(HTMLParser):
    """What a reader meets in the page: ids, sections, preformatted boxes, links, images, tables, text."""

    def __init__(self):
        super().__init__()
        self.ids: list[str] = []
        self.sections: list[str | None] = []        # the id of every <h2>, in order
        self.pres: list[dict] = []                   # {"section", "after_h3", "text"}
        self.contents_links: list[str] = []          # href of every link in the table of contents
        self.contents_found = False
        self.images: list[str] = []
        self.tables: list[dict] = []                 # {"section", "headers", "rows", "classes"}
        self.text: list[str] = []                    # visible text and attribute values but image data
        self.viewport: str | None = None             # content of <meta name="viewport">
        self.header: dict[str, str] = {}             # the provenance header: <dt> label -> <dd> text
        self.order: list[str] = []                   # ids of the summary, contents and sections, in order
        self._dt: str | None = None
        self._field: list[str] | None = None
        self._section: str | None = None
        self._after_h3 = False
        self._pre: dict | None = None
        self._nav_depth = 0
        self._cell: list[str] | None = None
        self._row: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        self.text += [str(v) for k, v in attrs.items() if k != "src" and v]
        if "id" in attrs:
            self.ids.append(attrs["id"])
            self.order.append(attrs["id"])
        if tag == "meta" and attrs.get("name") == "viewport":
            self.viewport = attrs.get("content", "")
        if tag in ("dt", "dd"):
            self._field = []
        if tag == "h2":
            self._section = attrs.get("id")
            self.sections.append(self._section)
        if tag == "pre":
            self._pre = {"section": self._section, "after_h3": self._after_h3, "text": ""}
        if tag == "nav" and attrs.get("id") == "contents":
            self.contents_found = True
            self._nav_depth = 1
        elif tag == "nav" and self._nav_depth:
            self._nav_depth += 1
        if tag == "a" and self._nav_depth:
            self.contents_links.append(attrs.get("href", ""))
        if tag == "img":
            self.images.append(attrs.get("src", ""))
        if tag == "table":
            self.tables.append({"section": self._section, "headers": [], "rows": [], "classes": []})
        if tag == "tr" and self.tables:
            self._row = []
            self.tables[-1]["classes"].append([])
        if tag in ("th", "td"):
            self._cell = []
            if self.tables and self.tables[-1]["classes"]:
                self.tables[-1]["classes"][-1].append(attrs.get("class", ""))
        if tag not in ("pre", "h3"):
            self._after_h3 = False          # a sketch is the box right after a model's <h3>

    def handle_endtag(self, tag):
        if tag in ("dt", "dd") and self._field is not None:
            text = "".join(self._field).strip()
            if tag == "dt":
                self._dt = text
            elif self._dt is not None:
                self.header[self._dt] = text
            self._field = None
        if tag == "h3":
            self._after_h3 = True
        if tag == "pre" and self._pre is not None:
            self.pres.append(self._pre)
            self._pre, self._after_h3 = None, False
        if tag == "nav" and self._nav_depth:
            self._nav_depth -= 1
        if tag in ("th", "td") and self._cell is not None:
            cell = "".join(self._cell).strip()
            if tag == "th":
                self.tables[-1]["headers"].append(cell)
            elif self._row is not None:
                self._row.append(cell)
            self._cell = None
        if tag == "tr" and self._row:
            self.tables[-1]["rows"].append(self._row)
            self._row = None

    def handle_data(self, data):
        self.text.append(data)
        if self._field is not None:
            self._field.append(data)
        if self._pre is not None:
            self._pre["text"] += data
        if self._cell is not None:
            self._cell.append(data)


def _png_size(png: bytes) -> tuple[int, int] | None:
    """(width, height) from a PNG's header chunk, None when the bytes do not start as a PNG."""
    if len(png) < 24 or png[:8] != PNG_SIGNATURE or png[12:16] != b"IHDR":
        return None
    return struct.unpack(">II", png[16:24])


def _is_drawing(text: str) -> bool:
    lines = [line for line in text.splitlines() if line.strip()]
    return len(lines) >= 3 and sum(ch in DRAWING for ch in text) >= 10


#: A cell a reader reads as a number: a signed decimal (maybe with exponent), a unit or % after it.
_NUMBER_CELL = re.compile(r"[+-]?\d+(\.\d+)?(e[+-]?\d+)?(\u00a0(%|kN|mm|m|s|N))?|\d+ / \d+")


def _alignment_problems(table: dict, name: str) -> list[str]:
    """Number columns right-aligned (class "n"), text columns left-aligned ("l"), "%" bound to its number."""
    problems = []
    body = [(row, classes) for row, classes in zip(table["rows"], table["classes"][1:])]
    for column, header in enumerate(table["headers"]):
        cells = [(row[column], classes[column]) for row, classes in body if column < len(row)]
        texts = [text for text, _ in cells if text not in ("", "-", "\u2013")]
        if any(re.search(r"\d %", text) for text in texts):
            problems.append(f"{name}, column {header!r}: a '%' after a plain space can wrap onto its own line")
        numeric = bool(texts) and all(_NUMBER_CELL.fullmatch(text) for text in texts)
        wanted = "n" if numeric else "l"
        classes = [table["classes"][0][column]] + [cls for _, cls in cells]
        if any(wanted not in cls.split() for cls in classes):
            problems.append(f"{name}, column {header!r}: {'numbers' if numeric else 'text'} not "
                            f"{'right' if numeric else 'left'}-aligned (classes {sorted(set(classes))})")
    return problems


def page_problems(html_text: str) -> list[str]:
    """What is broken in the report page, as a reader would see it (an empty list: nothing)."""
    page = _Page()
    page.feed(html_text)
    page.close()
    problems = []
    # boxes: no empty one; the model sketches are drawings
    problems += [f"empty <pre> in section {p['section']!r}" for p in page.pres if not p["text"].strip()]
    sketches = [p for p in page.pres if p["section"] == "models" and p["after_h3"]]
    problems += [f"model sketch without a drawing: {p['text'][:40]!r}" for p in sketches if not _is_drawing(p["text"])]
    problems += [f"<pre> under 'Models and equations' with no drawing characters: {p['text'][:40]!r}"
                 for p in page.pres if p["section"] == "models" and not DRAWING & set(p["text"])]
    if len(sketches) < 3:
        problems.append(f"{len(sketches)} model sketches under 'Models and equations', 3 expected")
    # ids and the table of contents
    problems += [f"id {i!r} appears {page.ids.count(i)} times" for i in sorted(set(page.ids)) if page.ids.count(i) > 1]
    if not page.contents_found:
        problems.append("no table of contents (<nav id='contents'>)")
    targets = [href[1:] for href in page.contents_links if href.startswith("#")]
    problems += [f"contents link {href!r} is not a link within the page" for href in page.contents_links
                 if not href.startswith("#")]
    problems += [f"contents link to #{t}, which no element has" for t in targets if t not in page.ids]
    problems += [f"section {s!r} missing from the table of contents" for s in page.sections if s not in targets]
    # images: embedded PNGs with a size
    for number, src in enumerate(page.images):
        prefix = "data:image/png;base64,"
        try:
            png = base64.b64decode(src[len(prefix):], validate=True) if src.startswith(prefix) else b""
        except ValueError:
            png = b""
        size = _png_size(png)
        if size is None or min(size) <= 0:
            problems.append(f"image {number} is not a PNG with a size: {src[:40]!r}")
    # a phone shows the page at its own width
    if page.viewport is None or "width=device-width" not in page.viewport:
        problems.append(f"no viewport meta with width=device-width: {page.viewport!r}")
    # the header: which paper, when, with what
    for label, pattern in HEADER_FIELDS.items():
        if not re.fullmatch(pattern, page.header.get(label, ""), re.IGNORECASE):
            problems.append(f"header field {label!r} is {page.header.get(label)!r}, expected {pattern!r}")
    # the verdict comes first, before the table of contents and every section
    if "summary" not in page.order:
        problems.append("no summary with the verdict (id 'summary')")
    elif page.order.index("summary") > min((page.order.index(i) for i in ["contents", *page.sections]
                                            if i in page.order), default=len(page.order)):
        problems.append("the summary comes after the table of contents or a section")
    elif "Verdict" not in "".join(page.text):
        problems.append("the summary gives no verdict")
    # numbers right-aligned, text left-aligned; a number never wraps away from its unit
    for number, table in enumerate(page.tables):
        problems += _alignment_problems(table, f"table {number} ({table['section']})")
    # no reference to a document the reader does not have
    if any("DESIGN.md" in text for text in page.text):
        problems.append("the page cites DESIGN.md")
    # Table 2 has the force on the mount, in kN, for every row
    table2 = next((t for t in page.tables if t["section"] == "table2"), None)
    if table2 is None:
        problems.append("no Table 2 (a table in the section with id 'table2')")
    elif SUPPORT_FORCE_HEADER not in table2["headers"]:
        problems.append(f"Table 2 has no {SUPPORT_FORCE_HEADER!r} column: {table2['headers']}")
    else:
        column = table2["headers"].index(SUPPORT_FORCE_HEADER)
        for row in table2["rows"]:
            try:
                assert float(row[column]) > 0
            except (AssertionError, IndexError, ValueError):
                problems.append(f"Table 2 row {row[:2]} has no positive support force: {row}")
    return problems


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("report") / "new" / "directory"   # missing directories are created
    write_report(out, ReportOptions.reduced())
    return out


def test_report_html_has_every_section_figure_and_table(report_dir):
    text = (report_dir / "report.html").read_text()
    page = _Page()
    page.feed(text)
    ids = set(page.ids)
    for section in ("models", "parameters", "table2", "sweeps", "histories", "contact", "engine-vs-reference",
                    "conventions", "calibration", "claims", "unreproduced", "carriage", "cost"):
        assert section in ids, section
    for table in ("parameters", "table2", "section22", "engine-vs-reference", "conventions", "conventions-trend",
                  "calibration-table2", "claims", "carriage"):
        assert f"tab-{table}" in ids, table
    expected_figures = {"fig4_gap_sweep_model_i", "fig5_gap_sweep_model_ii", "conventions_gap_trend",
                        "support_force_m1000", "energy_m1000", "carriage_ground_reactions"} | {
        f"{stem}_m{m}" for stem in ("barrel_displacement", "contact_force", "absorber_velocity", "first_impact")
        for m in (100, 500, 1000)}
    assert {f"fig-{name}" for name in expected_figures} <= ids
    # self-contained: every image is embedded PNG data, no external references
    assert len(page.images) == len(expected_figures)
    assert all(src.startswith("data:image/png;base64,") and len(src) > 5000 for src in page.images)
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
    carriage = {row["scene"]: row for row in data["carriage"]}  # the gun on its carriage, as computed
    assert set(carriage) == {"towed_howitzer", "towed_howitzer_45"}
    assert carriage["towed_howitzer_45"]["lift_off_time"] is None and 0.0 < carriage["towed_howitzer_45"]["margin"] < 1.0
    assert carriage["towed_howitzer"]["lift_off_time"] is not None and carriage["towed_howitzer"]["margin"] == 0.0
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


def test_the_mount_force_verdict_follows_table2(report_dir):
    text = (report_dir / "report.html").read_text()
    page = _Page()
    page.feed(text)
    table2 = next(t for t in page.tables if t["section"] == "table2")
    force, x_max = table2["headers"].index(SUPPORT_FORCE_HEADER), table2["headers"].index("ours [mm]")
    verdict = re.search(r"<ul id='mount-force-verdict'>(.*?)</ul>", text, re.DOTALL)
    assert verdict, "no verdict on the force on the mount under Table 2"
    sentences = [html.unescape(item) for item in re.findall(r"<li>(.*?)</li>", verdict.group(1))]
    for mass in ("100", "500", "1000"):
        cases = [(row[0], float(row[x_max]), float(row[force])) for row in table2["rows"] if row[1] == mass]
        assert len(cases) == 3
        lowest = min(cases, key=lambda case: case[2])
        shortest = min(cases, key=lambda case: case[1])
        sentence = next(s for s in sentences if s.startswith(f"m = {mass} kg:"))
        assert sentence.startswith(f"m = {mass} kg: {lowest[0]} moderates the force on the mount most"), sentence
        if shortest is not lowest:
            assert f"{shortest[0]} recoils least" in sentence and "harder on the mount" in sentence, sentence
    assert "fig-support_force_m1000" in page.ids

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


# ------------------------------------------------------------------- the page as a reader sees it
def test_reduced_report_reads_right_in_a_browser(report_dir):
    assert page_problems((report_dir / "report.html").read_text()) == []


def _tiny_png(width: int = 2, height: int = 1) -> bytes:
    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    rows = b"".join(b"\x00" + b"\x00\x00\x00" * width for _ in range(height))
    return (PNG_SIGNATURE + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


_SKETCH = "    k\n|--/\\/\\--+-----+\n|        |  M  |\n|--[ c ]-+-----+\nground"
_HEADER = ("<dl id='provenance'><dt>Paper replicated</dt><dd><i>Analysis of a dynamic system subjected to an "
           "impulsive and internal contact force</i></dd><dt>Made on</dt><dd>2026-01-02 03:04 UTC</dd>"
           "<dt>Package</dt><dd>recoil-mbs 0.1.0</dd><dt>Commit</dt><dd>unknown</dd><dt>Exudyn</dt><dd>1.13.6</dd>"
           "<dt>numpy</dt><dd>2.4.6</dd><dt>scipy</dt><dd>1.17.1</dd><dt>Machine</dt><dd>Linux, x86_64, 2 CPUs</dd>"
           "</dl><p id='summary'><b>Verdict.</b> all reproduced</p>")
_GOOD_PAGE = (
    "<html><head><meta name='viewport' content='width=device-width, initial-scale=1'></head><body><h1>Report</h1>"
    + _HEADER + "<p>intro</p>"
    "<nav id='contents'><ol><li><a href='#models'>Models</a></li><li><a href='#table2'>Table 2</a></li></ol></nav>"
    "<h2 id='models'>1. Models and equations</h2>"
    + "".join(f"<h3>Model {n}</h3><pre>{_SKETCH}</pre>" for n in (1, 2, 3))
    + "<pre>M x'' + k x = 0</pre>"
    "<h2 id='table2'>2. Table 2</h2><div><table id='tab-table2'><thead><tr><th class='l'>model</th>"
    "<th class='n'>m [kg]</th><th class='n'>ours [mm]</th><th class='n'>peak support force [kN]</th>"
    "<th class='n'>relative</th></tr></thead><tbody><tr><td class='l'>model (i)</td><td class='n'>100</td>"
    "<td class='n'>220.1</td><td class='n'>6.89</td><td class='n'>+1.77&nbsp;%</td></tr></tbody></table></div>"
    f"<figure id='fig-x'><img alt='x' src='data:image/png;base64,{base64.b64encode(_tiny_png()).decode()}'>"
    "</figure></body></html>")


def test_page_checker_passes_a_sound_page():
    assert _png_size(_tiny_png(3, 5)) == (3, 5)
    assert page_problems(_GOOD_PAGE) == []


@pytest.mark.parametrize("broken, expected", [
    (_GOOD_PAGE.replace(f"<h3>Model 2</h3><pre>{_SKETCH}</pre>", "<h3>Model 2</h3><pre></pre>"), "empty <pre>"),
    (_GOOD_PAGE.replace(f"<h3>Model 2</h3><pre>{_SKETCH}</pre>", "<h3>Model 2</h3><pre>k, c\nM\nground</pre>"),
     "without a drawing"),
    (_GOOD_PAGE.replace("<pre>M x'' + k x = 0</pre>", "<pre>equations follow</pre>"), "no drawing characters"),
    (_GOOD_PAGE.replace("id='tab-table2'", "id='table2'"), "id 'table2' appears 2 times"),
    (_GOOD_PAGE.replace("href='#table2'", "href='#table-2'"), "which no element has"),
    (_GOOD_PAGE.replace("<li><a href='#table2'>Table 2</a></li>", ""), "missing from the table of contents"),
    (re.sub("<nav.*</nav>", "", _GOOD_PAGE), "no table of contents"),
    (_GOOD_PAGE.replace(base64.b64encode(_tiny_png()).decode(), base64.b64encode(b"GIF89a" + bytes(30)).decode()),
     "not a PNG"),
    (_GOOD_PAGE.replace(base64.b64encode(_tiny_png()).decode(), base64.b64encode(_tiny_png(0, 1)).decode()),
     "not a PNG"),
    (_GOOD_PAGE.replace("data:image/png;base64,", "tiny.png?"), "not a PNG"),
    (_GOOD_PAGE.replace("<p>intro</p>", "<p>see DESIGN.md</p>"), "DESIGN.md"),
    (_GOOD_PAGE.replace("<meta name='viewport' content='width=device-width, initial-scale=1'>", ""), "viewport"),
    (_GOOD_PAGE.replace("<dd>1.17.1</dd>", "<dd></dd>"), "header field 'scipy'"),
    (_GOOD_PAGE.replace("<dt>Commit</dt><dd>unknown</dd>", ""), "header field 'Commit'"),
    (_GOOD_PAGE.replace("<dd>unknown</dd>", "<dd>HEAD</dd>"), "header field 'Commit'"),
    (_GOOD_PAGE.replace("impulsive and internal", "impulsive"), "header field 'Paper replicated'"),
    (_GOOD_PAGE.replace("<p id='summary'><b>Verdict.</b> all reproduced</p>", ""), "no summary"),
    (_GOOD_PAGE.replace("<p id='summary'><b>Verdict.</b> all reproduced</p>", "").replace(
        "<h2 id='table2'>", "<p id='summary'><b>Verdict.</b> all</p><h2 id='table2'>"), "summary comes after"),
    (_GOOD_PAGE.replace("peak support force [kN]</th>", "peak support force [N]</th>"), "column"),
    (_GOOD_PAGE.replace("<td class='n'>6.89</td>", "<td class='n'>&ndash;</td>"), "no positive support force"),
    (_GOOD_PAGE.replace("+1.77&nbsp;%", "+1.77 %"), "'%' after a plain space"),
    (_GOOD_PAGE.replace("<td class='l'>model (i)</td>", "<td class='n'>model (i)</td>"), "text not left-aligned"),
    (_GOOD_PAGE.replace("<th class='n'>ours [mm]</th>", "<th>ours [mm]</th>"), "numbers not right-aligned"),
])
def test_page_checker_finds_each_defect(broken, expected):
    problems = page_problems(broken)
    assert any(expected in problem for problem in problems), problems


# ------------------------------------------------------------------------------------- percentages
@pytest.mark.parametrize("fraction, expected", [
    (-0.0002, "-0.02\u00a0%"), (0.0177, "+1.8\u00a0%"), (-0.25306, "-25.3\u00a0%"), (0.0, "0\u00a0%"),
    (3e-6, "+0.0003\u00a0%"), (-1e-9, "-less than 0.001\u00a0%"),
])
def test_percent_text_never_rounds_a_difference_to_zero(fraction, expected):
    from validation.studies.report import percent_text
    assert percent_text(fraction) == expected


def test_the_verdict_counts_what_table2_shows(report_dir):
    text = (report_dir / "report.html").read_text()
    summary = html.unescape(re.search(r"<p id='summary'>(.*?)</p>", text, re.DOTALL).group(1))
    page = _Page()
    page.feed(text)
    table2 = next(t for t in page.tables if t["section"] == "table2")
    relative = table2["headers"].index("relative")
    within = [abs(float(row[relative].replace("\u00a0", " ").split()[0])) <= 1.0 for row in table2["rows"]]
    assert f"{sum(within)} of {len(within)} maximum barrel displacements of Table 2" in summary, summary
    comparisons = json.loads((report_dir / "results.json").read_text())["engine_vs_reference"]
    assert f"in {sum(c['passed'] for c in comparisons)} of {len(comparisons)} cases" in summary, summary


def test_the_verdicts_largest_error_is_a_cell_of_the_engine_vs_reference_table(report_dir):
    """The headline's "largest relative error" names a case and a quantity, and that row and column of the
    table hold the same number -- the largest of every number in the table's error columns."""
    text = (report_dir / "report.html").read_text()
    summary = html.unescape(re.sub(r"<[^>]*>", "", re.search(r"<p id='summary'>(.*?)</p>", text, re.DOTALL).group(1)))
    found = re.search(r"largest relative error (\S+): (.+?) of (.+?), in the table", summary)
    assert found, summary
    value, quantity, case = found.groups()
    page = _Page()
    page.feed(text)
    table = next(t for t in page.tables if t["section"] == "engine-vs-reference")
    [row] = [r for r in table["rows"] if r[0] == case]
    assert row[table["headers"].index(quantity)] == value
    errors = [float(cell) for r in table["rows"] for cell in r[1:table["headers"].index("impacts engine / ref.")]
              if re.fullmatch(r"\d\.\de[+-]\d\d", cell)]
    assert float(value) == max(errors)
    # and it is the largest relative error of any check in results.json
    comparisons = json.loads((report_dir / "results.json").read_text())["engine_vs_reference"]
    largest = max(x["relative_error"] for c in comparisons for x in c["checks"] if x["relative_error"] is not None)
    assert f"{largest:.1e}" == value


def test_every_figure_opens_full_size_and_fills_a_narrow_screen(report_dir):
    text = (report_dir / "report.html").read_text()
    figures = re.findall(r"<figure id=\"fig-([^\"]+)\">(.*?)</figure>", text, re.DOTALL)
    assert len(figures) >= 10
    for name, body in figures:
        link = re.match(r'<a href="([^"]+)"[^>]*><img ', body)
        assert link, f"figure {name} is not a link"
        assert (report_dir / link.group(1)).read_bytes()[:8] == PNG_SIGNATURE   # the PNG written beside it
        assert link.group(1) == f"{name}.png"
    narrow = re.search(r"@media \(max-width:(\d+)px\)\{(.*?\})\}", text, re.DOTALL)
    assert narrow and int(narrow.group(1)) >= 390, "no style for a narrow screen"
    assert re.search(r"figure img\{width:100%", narrow.group(2)) and re.search(r"figure\{margin:[^}]*-", narrow.group(2))


# ------------------------------------------------------------------------------------- convention study
def _reading(label: str, trend_mm: tuple[float, float, float]):
    from mbs_models import Conventions
    from validation.studies.conventions import ConventionRow

    flags = {} if label == "default" else {label: True}
    reference = {("table2", "model (ii)", 1000.0): {"max_barrel_displacement": trend_mm[0] / 1e3},
                 ("trend", "model (ii)", 0.04): {"max_barrel_displacement": trend_mm[1] / 1e3},
                 ("trend", "model (ii)", 0.08): {"max_barrel_displacement": trend_mm[2] / 1e3}}
    return ConventionRow(label, Conventions(**flags), reference, {})


def test_convention_figure_shows_every_reading_even_when_two_coincide():
    import matplotlib.pyplot as plt

    from validation.studies.report import _convention_figure

    rows = [_reading("default", (150.8, 176.0, 190.0)), _reading("v0_includes_absorber", (150.8, 176.0, 190.0)),
            _reading("literal_gap_sign", (150.8, 100.4, 91.6)), _reading("compression_only", (151.0, 170.0, 185.0))]
    fig = _convention_figure({"conventions": rows})
    ax = fig.axes[0]
    lines = ax.get_lines()
    assert len(lines) == 4
    styles = [(line.get_linestyle(), line.get_marker()) for line in lines]
    assert len(set(styles)) == 4, styles
    # the reading drawn over another says so in the legend
    legend = [text.get_text() for text in ax.get_legend().get_texts()]
    assert sum("coincides" in text for text in legend) == 1
    assert "coincides with default" in legend[1], legend
    plt.close(fig)


def test_every_reading_has_plain_words():
    from validation.studies.conventions import CONVENTION_CASES
    from validation.studies.report import READINGS

    assert {label for label, _ in CONVENTION_CASES} <= set(READINGS)
    assert all("_" not in text and "_" not in short for text, short in READINGS.values())


def test_convention_table_one_number_per_cell_with_units(report_dir):
    page = _Page()
    page.feed((report_dir / "report.html").read_text())
    table, trend = [t for t in page.tables if t["section"] == "conventions"]
    for model in ("model (i)", "model (ii)"):
        for mass in ("100", "500", "1000"):
            assert f"{model}, {mass} kg" in table["headers"], table["headers"]
    for gap in ("0", "40", "80"):
        column = trend["headers"].index(f"gap {gap} mm [mm]")
        assert all(re.fullmatch(r"\d+\.\d", row[column]) for row in trend["rows"]), [r[column] for r in trend["rows"]]
    # the same readings, in the same order, in both tables (the second names each by its short name)
    assert [row[0] for row in trend["rows"]] == [row[0][:len(trend_row[0])] for row, trend_row in
                                                  zip(table["rows"], trend["rows"])]


# ------------------------------------------------------------------------------- what we cannot reproduce
def prose_problems(text: str) -> list[str]:
    """What reads wrong in a paragraph written for an engineer (an empty list: nothing)."""
    problems = []
    if ".." in text:
        problems.append("a doubled full stop")
    if re.search(r"[+-]0\.0*\s?%", text.replace("\u00a0", " ")):
        problems.append("a difference printed as zero with a sign (-0.0 %)")
    identifiers = re.findall(r"\b[a-z][a-z0-9]*(?:_[a-z0-9]+)+\b", text)
    if identifiers:
        problems.append(f"internal identifiers in the text: {identifiers}")
    starts = re.findall(r"[.!?]\s+([a-z]\S*)", text)
    starts = [word for word in starts if not re.match(r"[a-z]$", word)]   # "m = 100 kg" starts with a symbol
    if starts:
        problems.append(f"sentences starting in lower case: {starts}")
    return problems


@pytest.mark.parametrize("text, expected", [
    ("The gap is zero.. Then", "doubled"), ("It gives -0.0 %.", "zero with a sign"),
    ("The reading 'v0_includes_absorber' gives", "identifiers"), ("It gives 1 %. the closest", "lower case"),
])
def test_prose_checker_finds_each_defect(text, expected):
    assert any(expected in problem for problem in prose_problems(text)), prose_problems(text)


def test_what_we_cannot_reproduce_reads_as_plain_sentences(report_dir):
    text = (report_dir / "report.html").read_text()
    listing = re.search(r"<ul id='unreproduced-list'>(.*?)</ul>", text, re.DOTALL).group(1)
    items = [html.unescape(re.sub(r"<[^>]*>", "", item)) for item in re.findall(r"<li>(.*?)</li>", listing, re.DOTALL)]
    assert len(items) >= 3
    assert prose_problems("The closest reading is fine. It gives +0.02 %. m = 100 kg: largest 202.4 mm.") == []
    for item in items:
        assert prose_problems(item) == [], item


# ------------------------------------------------------------------------------------------ energy figure
def test_energy_figure_shows_every_element_and_the_sum_stays_the_initial_energy():
    import matplotlib.pyplot as plt
    import numpy as np

    from mbs_models import model_i, model_ii, simulate
    from validation.studies.report import ENERGY_STYLES, _energy_figure

    runs = {("model (i)", 1000.0): simulate(model_i(1000.0, 0.0), 10.0, "standard"),
            ("model (ii)", 1000.0): simulate(model_ii(1000.0, 0.0), 10.0, "standard")}
    fig = _energy_figure({"runs": runs}, 1000.0)
    initial = 0.5 * 5600.0 * INITIAL_VELOCITY ** 2          # J, the barrel's kinetic energy after the shot
    for ax in fig.axes:
        labels = [line.get_label() for line in ax.get_lines()]
        for kind in ENERGY_STYLES:
            assert any(label.endswith(f": {kind}") for label in labels), (kind, labels)
        for element in ("barrel", "absorber", "recoil spring", "recoil damper", "contact"):
            assert any(label.startswith(element) for label in labels), (element, labels)
        total = next(line for line in ax.get_lines() if line.get_label().startswith("sum"))
        values = np.asarray(total.get_ydata())
        assert values[0] == pytest.approx(initial, rel=1e-9)
        assert np.max(np.abs(values - initial)) < 1e-3 * initial
    plt.close(fig)


def test_report_has_the_energy_figure(report_dir):
    page = _Page()
    page.feed((report_dir / "report.html").read_text())
    assert "fig-energy_m1000" in page.ids and "energy" in page.ids
    assert (report_dir / "energy_m1000.png").read_bytes()[:8] == PNG_SIGNATURE


def test_the_page_shows_mm_and_kn_while_the_files_stay_si(report_dir):
    """Display units are the page's only: table2.json and results.json keep metres and newtons."""
    table = json.loads((report_dir / "table2.json").read_text())
    results = json.loads((report_dir / "results.json").read_text())
    assert table["units"]["engine"] == "m" and table["units"]["peak_support_force"] == "N"
    assert results["table2"] == table["rows"]
    for row in table["rows"]:
        assert 0.1 < row["engine"] < 0.3 and 0.1 < row["paper"] < 0.3          # metres, not millimetres
        assert 1e3 < row["peak_support_force"] < 1e5                            # newtons, not kilonewtons
    page = _Page()
    page.feed((report_dir / "report.html").read_text())
    shown = next(t for t in page.tables if t["section"] == "table2")
    ours, force = shown["headers"].index("ours [mm]"), shown["headers"].index(SUPPORT_FORCE_HEADER)
    for row, cells in zip(table["rows"], shown["rows"]):
        assert float(cells[ours]) == pytest.approx(row["engine"] * 1e3, abs=0.006)
        assert float(cells[force]) == pytest.approx(row["peak_support_force"] / 1e3, abs=0.006)
    for item in results["unreproduced"]:
        assert item["unit"] in ("m", "N", "m/s", "s", ""), item["unit"]


def test_every_image_of_the_page_decodes_to_its_stated_size(report_dir):
    import io

    import matplotlib.image

    page = _Page()
    page.feed((report_dir / "report.html").read_text())
    assert page.images
    for src in page.images:
        png = base64.b64decode(src.split(",", 1)[1], validate=True)
        width, height = _png_size(png)
        pixels = matplotlib.image.imread(io.BytesIO(png), format="png")
        assert pixels.shape[:2] == (height, width) and pixels.shape[0] > 100 and pixels.shape[1] > 100
