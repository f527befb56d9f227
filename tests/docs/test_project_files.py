"""The project's files for users: LICENSE is the licence pyproject.toml declares, CITATION.cff is valid Citation File
Format 1.2.0 naming this version and licence and the replicated paper, and the docs pages include the files they
say they include.

No YAML library is a dependency: :func:`parse_cff` reads the subset of YAML a CFF file needs (block mappings and
sequences, plain and quoted scalars, folded ``>-`` scalars, comments) and refuses anything else, so that a file it
accepts is YAML with the structure it returns."""

from __future__ import annotations

import re
import tomllib

import pytest
from guide_pages import DOCS, ROOT

PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def _scalar(text: str, where: str):
    text = text.strip()
    if len(text) >= 2 and text[0] == text[-1] == '"':
        return text[1:-1]
    if not text or text[0] in "[{&*!|>'\"%@`" or ": " in text or " #" in text:
        raise ValueError(f"{where}: not a plain scalar this parser reads: {text!r}")
    return text


def parse_cff(text: str):
    """The CFF file as nested dicts and lists of strings (see the module docstring); ValueError on anything else."""
    lines = [(n + 1, line) for n, line in enumerate(text.splitlines())
             if line.strip() and not line.lstrip().startswith("#")]
    for number, line in lines:
        if "\t" in line:
            raise ValueError(f"line {number}: a tab")

    def indent(line: str) -> int:
        return len(line) - len(line.lstrip(" "))

    def block(i: int, level: int):
        """(value, next index) of the block of lines at indentation ``level`` from line ``i``."""
        if lines[i][1].lstrip().startswith("- "):
            items = []
            while i < len(lines) and indent(lines[i][1]) == level and lines[i][1].lstrip().startswith("- "):
                number, line = lines[i]
                rest = line.lstrip()[2:]
                if re.match(r"[\w-]+:( |$)", rest):       # "- key: value": a mapping item, its keys at level + 2
                    lines[i] = (number, " " * (level + 2) + rest)
                    value, i = mapping(i, level + 2)
                else:
                    value, i = _scalar(rest, f"line {number}"), i + 1
                items.append(value)
            return items, i
        return mapping(i, level)

    def mapping(i: int, level: int):
        result = {}
        while i < len(lines) and indent(lines[i][1]) == level and not lines[i][1].lstrip().startswith("- "):
            number, line = lines[i]
            match = re.fullmatch(r"([\w-]+):(?: (.*))?", line.strip())
            if not match or match.group(1) in result:
                raise ValueError(f"line {number}: not a new 'key: value': {line!r}")
            key, value = match.groups()
            i += 1
            if value == ">-":                               # folded scalar: the more indented lines, joined
                parts = []
                while i < len(lines) and indent(lines[i][1]) > level:
                    parts.append(lines[i][1].strip())
                    i += 1
                result[key] = " ".join(parts)
            elif value is None:                             # a nested block, more indented (a sequence may sit at
                if i == len(lines) or indent(lines[i][1]) < level or (  # the key's own level, as YAML allows)
                        indent(lines[i][1]) == level and not lines[i][1].lstrip().startswith("- ")):
                    raise ValueError(f"line {number}: {key} has no value")
                result[key], i = block(i, indent(lines[i][1]))
            else:
                result[key] = _scalar(value, f"line {number}")
        if i < len(lines) and indent(lines[i][1]) > level:
            raise ValueError(f"line {lines[i][0]}: unexpected indentation")
        return result, i

    value, end = block(0, 0)
    if end != len(lines):
        raise ValueError(f"line {lines[end][0]}: unexpected indentation")
    return value


def test_the_cff_parser_refuses_what_it_cannot_read():
    assert parse_cff('a: 1\nb:\n  - name: "x"\n    c: y\nd: >-\n  one\n  two\n') == {
        "a": "1", "b": [{"name": "x", "c": "y"}], "d": "one two"}
    for bad in ("a: 1\na: 2\n", "a:\n", "a: [1, 2]\n", "a: 1\n   b: 2\n", "a:\n\t- 1\n", "a: x: y\n"):
        with pytest.raises(ValueError):
            parse_cff(bad)


def test_citation_cff_is_valid_and_names_this_version_and_the_paper():
    cff = parse_cff((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0"
    assert {"cff-version", "message", "title", "authors"} <= cff.keys()      # CFF 1.2.0's required keys
    assert all("name" in a or "family-names" in a for a in cff["authors"])
    assert cff["type"] == "software"
    assert cff["version"] == PYPROJECT["version"]
    assert cff["license"] == PYPROJECT["license"]["text"]
    paper = cff["references"][0]
    assert {"type", "title", "authors"} <= paper.keys()
    assert paper["title"] == "Analysis of a dynamic system subjected to an impulsive and internal contact force"
    first_line = (ROOT.parent / "shared" / "paper" / "recoil-absorber-paper.md")
    if first_line.is_file():                                               # the source, where it is at hand
        assert paper["title"].upper() in first_line.read_text().splitlines()[0]


def test_the_license_is_the_one_pyproject_declares():
    """pyproject.toml says BSD-3-Clause: LICENSE is that licence's text (its title, three clauses and disclaimer),
    copyright the recoil-mbs authors."""
    assert PYPROJECT["license"]["text"] == "BSD-3-Clause"
    text = (ROOT / "LICENSE").read_text()
    assert text.splitlines()[0] == "BSD 3-Clause License"
    assert re.search(r"^Copyright \(c\) \d{4}, the recoil-mbs authors$", text, flags=re.M)
    assert [int(n) for n in re.findall(r"^(\d)\. ", text, flags=re.M)] == [1, 2, 3]
    assert "Neither the name of the copyright holder nor the names of its" in text
    assert 'THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS "AS IS"' in text


@pytest.mark.parametrize("page, included", [("changelog.md", "../CHANGELOG.md"), ("contributing.md", "../CONTRIBUTING.md"),
                                            ("citing.md", "../CITATION.cff")])
def test_the_docs_pages_include_the_project_files(page, included):
    text = (DOCS / page).read_text()
    assert re.search(rf"^```{{(?:include|literalinclude)}} {re.escape(included)}$", text, flags=re.M)
    assert (DOCS / included).resolve().is_file()


def test_the_changelog_keeps_a_changelog():
    text = (ROOT / "CHANGELOG.md").read_text()
    assert text.startswith("# Changelog\n")
    assert "## [Unreleased]" in text
    assert re.findall(r"^### (Added|Changed|Fixed|Removed|Deprecated|Security)$", text, flags=re.M)
