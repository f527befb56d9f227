"""Stand-ins for the top toctree's pages that other branches provide (the user guide's), so that a branch that
does not have them yet still builds without a warning.

At ``config-inited`` each missing page of :data:`PAGES` is written as a one-line placeholder saying so, and removed
again when the build finishes; a page that exists is never touched.  Once every page exists this does nothing.
"""

from __future__ import annotations

from pathlib import Path

#: page (relative to the docs folder) -> its title
PAGES = {
    "getting-started.md": "Getting started",
    "guide/index.md": "User guide",
    "changelog.md": "Changelog",
    "citing.md": "How to cite",
    "contributing.md": "Contributing",
}

_written: list[Path] = []


def _write(app, config) -> None:
    for page, title in PAGES.items():
        path = Path(app.srcdir) / page
        if not path.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(f"# {title}\n\nPlaceholder: this page is written on another branch of issue #25 "
                            f"and is not on this one yet.\n")
            _written.append(path)


def _remove(app, exception) -> None:
    for path in _written:
        path.unlink(missing_ok=True)
        try:
            path.parent.rmdir()  # only if the placeholder was alone in a folder it made
        except OSError:
            pass
    _written.clear()


def setup(app):
    app.connect("config-inited", _write)
    app.connect("build-finished", _remove)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
