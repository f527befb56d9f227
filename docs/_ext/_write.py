"""Shared by the local extensions: write a generated source file only when its text changed."""

from __future__ import annotations

from pathlib import Path


def write_if_changed(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` (creating its folder) unless the file already holds exactly that text, so that
    Sphinx does not re-read an unchanged generated page."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def markdown_cell(text: str) -> str:
    """``text`` (RST-ish docstring prose) for a Markdown table cell: ````x```` as ```x```, ``:role:`~a.B``` as
    ```B```, pipes escaped, one line."""
    import re

    text = re.sub(r":[a-z]+:`~?([^`<]*?)(?: <[^>]*>)?`", lambda m: f"`{m.group(1).split('.')[-1]}`", text)
    text = text.replace("``", "`")
    return " ".join(text.replace("|", "\\|").split())
