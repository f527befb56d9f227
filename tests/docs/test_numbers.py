"""The numbers contract (docs/DOCS_LAYOUT): every number a page quotes is an entry of a ``docs/numbers_*.py``,
computed from the code, and ``docs/_generated/numbers.json`` holds its current value.

Fails on a stale number (recomputed now, it differs from the JSON by more than the entry's ``rel_tol``), on a page
that quotes an unknown ``{{ name }}``, and on an entry no page quotes."""

import importlib.util
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
GENERATED = DOCS / "_generated" / "numbers.json"
SUBSTITUTION = re.compile(r"\{\{\s*([A-Za-z_][A-Za-z0-9_]*)\s*\}\}")
SKIPPED = ("_build", "auto_examples")


def _script():
    spec = importlib.util.spec_from_file_location("docs_numbers", ROOT / "scripts" / "docs_numbers.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _entries() -> dict[str, dict]:
    return {name: entry for numbers in _script().load_modules(DOCS).values() for name, entry in numbers.items()}


def _recorded() -> dict[str, dict]:
    return json.loads(GENERATED.read_text())


def _quoted() -> dict[str, set[str]]:
    """``{name: pages}`` of every substitution the pages use."""
    out: dict[str, set[str]] = {}
    for page in DOCS.rglob("*.md"):
        if any(part in SKIPPED for part in page.relative_to(DOCS).parts):
            continue
        for name in SUBSTITUTION.findall(page.read_text()):
            out.setdefault(name, set()).add(str(page.relative_to(DOCS)))
    return out


def test_the_json_has_exactly_the_entries_of_the_modules():
    assert sorted(_recorded()) == sorted(_entries())


@pytest.mark.parametrize("name", sorted(_recorded()))
def test_a_recorded_number_is_current(name):
    entry = _entries()[name]
    recorded = _recorded()[name]
    value = float(entry["compute"]())
    allowed = max(entry["rel_tol"] * abs(recorded["value"]), entry.get("abs_tol", 0.0))
    assert abs(value - recorded["value"]) <= allowed, (
        f"{name} is stale: {recorded['value']!r} recorded, {value!r} now; run python scripts/docs_numbers.py --write")
    assert recorded["text"] == entry["format"].format(recorded["value"])


def test_every_quoted_number_is_an_entry():
    unknown = {name: pages for name, pages in _quoted().items() if name not in _recorded()}
    assert not unknown, f"pages quote numbers that no docs/numbers_*.py defines: {unknown}"


def test_every_entry_is_quoted_by_a_page():
    unused = sorted(set(_recorded()) - set(_quoted()))
    assert not unused, f"entries no page quotes (remove them or quote them): {unused}"


def test_an_entry_without_its_tolerance_or_a_name_defined_twice_is_refused(tmp_path):
    (tmp_path / "numbers_a.py").write_text('NUMBERS = {"x": {"compute": float, "format": "{}", "why": "w"}}\n')
    with pytest.raises(ValueError, match="x lacks rel_tol"):
        _script().load_modules(tmp_path)
    (tmp_path / "numbers_a.py").write_text('NUMBERS = {"x": {"compute": float, "format": "{}", "rel_tol": 0, "why": "w"}}\n')
    (tmp_path / "numbers_b.py").write_text('NUMBERS = {"x": {"compute": float, "format": "{}", "rel_tol": 0, "why": "w"}}\n')
    with pytest.raises(ValueError, match="defined in both"):
        _script().load_modules(tmp_path)
