"""How the studies report progress, whoever draws it.

A study takes one ``progress`` callable: ``progress(message)`` announces a stage.  For counted work
(``done`` of ``total`` runs) it asks :func:`counter` for a ``(done, total, note=None)`` callback: the
progress object's own ``counter(label)`` when it has one (the command line's tqdm bars,
:class:`mbs_models.cli.progress.ProgressBars`), otherwise a callback that writes
"label: done/total" through ``progress`` about every quarter.  :func:`named` gives a counter for one
named pass (e.g. the convention study's reference pass and engine pass).
"""

from __future__ import annotations

from typing import Callable

Progress = Callable[[str], None]
Counter = Callable[..., None]


def counter(progress: Progress, label: str, unit: str = "run") -> Counter:
    """A ``(done, total, note=None)`` progress callback for ``label``."""
    make = getattr(progress, "counter", None)
    if make is not None:
        return make(label, unit)

    def report(done: int, total: int, note: str | None = None) -> None:
        if done == total or done % max(1, total // 4) == 0:
            progress(f"  {label}: {done}/{total}" + (f" ({note})" if note else ""))
    report.label = label        # type: ignore[attr-defined]
    return report


def named(count: Counter | None, name: str) -> Counter | None:
    """The counter of one named pass: ``count.named(name)`` when it names passes, else a plain counter
    whose lines say the pass ("label: name: done/total"), else ``count`` itself (or None)."""
    if count is None:
        return None
    if hasattr(count, "named"):
        return count.named(name)
    label = getattr(count, "label", None)
    if label is None:
        return count

    def report(done: int, total: int, note: str | None = None) -> None:
        count(done, total, f"{name}" + (f", {note}" if note else ""))
    return report
