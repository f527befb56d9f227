"""Reading the user guide's pages (docs/guide/*.md, docs/getting-started.md) for the tests that check them: code
blocks by the heading above them, tables by a row pattern, console blocks with the command that prints them."""

from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
GUIDE = DOCS / "guide"


def page(name: str) -> str:
    """The text of ``docs/<name>`` (``guide/realistic.md``, ``getting-started.md``)."""
    return (DOCS / name).read_text()


def pages() -> list[Path]:
    """Every page of the guide, and the getting-started page."""
    return sorted(GUIDE.glob("*.md")) + [DOCS / "getting-started.md"]


def python_block_after(text: str, heading: str) -> str:
    """The first ```python block after ``heading`` in ``text``."""
    section = text[text.index(heading):]
    start = section.index("```python\n") + len("```python\n")
    return section[start:section.index("```", start)]


def table_rows(text: str, pattern: re.Pattern) -> list[tuple[str, ...]]:
    """The groups of every line of ``text`` that ``pattern`` matches."""
    return [m.groups() for line in text.splitlines() if (m := pattern.match(line))]


@dataclass(frozen=True)
class ConsoleBlock:
    """A ```console block: ``$ recoil ARGS`` and the lines it prints (``...`` for lines left out)."""

    page: str
    args: tuple[str, ...]
    expected: tuple[str, ...]

    @property
    def name(self) -> str:
        return f"{self.page}: recoil {' '.join(self.args)}"


def console_blocks() -> list[ConsoleBlock]:
    blocks = []
    for path in pages():
        for body in re.findall(r"```console\n(.*?)```", path.read_text(), flags=re.S):
            lines = body.rstrip("\n").splitlines()
            assert lines[0].startswith("$ recoil "), f"{path.name}: a console block starts with '$ recoil ...'"
            blocks.append(ConsoleBlock(path.name, tuple(shlex.split(lines[0][len("$ recoil "):])), tuple(lines[1:])))
    return blocks


_NUMBER = re.compile(r"\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


def _line_pattern(expected: str) -> re.Pattern:
    """A regex of a shown line: its text literally (runs of blanks as blanks), each number as a group, ``…`` as
    anything."""
    parts, position = [], 0
    for match in re.finditer(rf"{_NUMBER.pattern}|…", expected):
        parts.append(re.escape(expected[position:match.start()]))
        parts.append(".*?" if match.group() == "…" else f"({_NUMBER.pattern})")
        position = match.end()
    parts.append(re.escape(expected[position:]))
    return re.compile(re.sub(r"(\\ )+", r"\\s+", "".join(parts)).rstrip() + r"\s*$")


def _same_number(shown: str, printed: str) -> bool:
    """A number the page shows and the one the command printed agree: equal text, or within the larger of 0.2 %
    and one unit of the shown last digit (results of the same computation on another CPU differ in the last bits,
    which may round a shown digit the other way); a relative error the page shows below 1e-4 (an engine-to-reference
    difference, made of the last bits) stands for any printed below 1e-4."""
    if shown == printed:
        return True
    value, other = float(shown), float(printed)
    if "e" in shown.lower() and abs(value) < 1e-4:
        return abs(other) < 1e-4
    mantissa = shown.lower().split("e")[0]
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    exponent = int(shown.lower().split("e")[1]) if "e" in shown.lower() else 0
    unit = 10.0 ** (exponent - decimals)
    return abs(value - other) <= max(2e-3 * abs(value), unit)


def line_matches(expected: str, printed: str) -> bool:
    match = _line_pattern(expected).match(printed)
    if not match:
        return False
    shown = [m.group() for m in re.finditer(rf"{_NUMBER.pattern}|…", expected) if m.group() != "…"]
    return all(_same_number(s, p) for s, p in zip(shown, match.groups()))


def check_console_output(expected: tuple[str, ...], printed: list[str]) -> str | None:
    """None if ``printed`` is what the block shows -- its segments between ``...`` lines each consecutive lines of
    the output, in order, the first at the start and the last at the end unless ``...`` stands there -- else what
    is missing."""
    segments, current = [], []
    for line in (*expected, "..."):
        if line.strip() == "...":
            segments.append(current)
            current = []
        else:
            current.append(line)
    anchored_start = bool(expected) and expected[0].strip() != "..."
    anchored_end = bool(expected) and expected[-1].strip() != "..."
    position = 0
    for index, segment in enumerate(segments):
        if not segment:
            continue
        starts = [position] if (index == 0 and anchored_start) else range(position, len(printed) - len(segment) + 1)
        found = next((s for s in starts
                      if all(line_matches(e, p) for e, p in zip(segment, printed[s:s + len(segment)]))
                      and s + len(segment) <= len(printed)), None)
        if found is None:
            return f"not printed: {segment[0]!r} ... (output:\n" + "\n".join(printed) + ")"
        position = found + len(segment)
    if anchored_end and position != len(printed):
        return "printed more than shown:\n" + "\n".join(printed[position:])
    return None
