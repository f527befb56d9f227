"""Progress of the long commands (``recoil paper``, ``recoil precision``) on stderr, as tqdm bars.

The studies report progress through one callable (``validation.studies.progress``):

* ``progress(message)`` starts a stage (a line above the bars);
* ``progress.counter(label)`` returns a ``(done, total, note=None)`` callback that draws a bar with its
  rate and remaining time (ETA); a new bar starts when a finished one is called again;
* ``counter.named(name)`` is the same bar for one named pass, described as "label: name".

Quiet -- nothing at all is written -- when the stream is not a terminal (a log file, a pipe, CI).
"""

from __future__ import annotations

import shutil
import sys
from typing import TextIO

from tqdm import tqdm


class ProgressBars:
    """Stage lines and tqdm bars on ``stream`` (default stderr); ``enabled=None``: only on a terminal."""

    def __init__(self, stream: TextIO | None = None, *, enabled: bool | None = None, prefix: str = "recoil"):
        self.stream = stream if stream is not None else sys.stderr
        if enabled is None:
            isatty = getattr(self.stream, "isatty", None)
            enabled = bool(isatty and isatty())
        self.enabled = enabled
        self.prefix = prefix

    def __call__(self, message: str) -> None:
        """A new stage: one line, written above any bar."""
        if self.enabled:
            tqdm.write(f"[{self.prefix}] {message}", file=self.stream)

    def counter(self, label: str, unit: str = "run") -> "ProgressBar":
        """A bar counting ``unit``s, described by ``label``."""
        return ProgressBar(self, label, unit)


class ProgressBar:
    """A ``(done, total, note=None)`` callback drawing one tqdm bar (rate, ETA; ``note`` after it)."""

    def __init__(self, owner: ProgressBars, label: str, unit: str = "run"):
        self.owner, self.label, self.unit = owner, label, unit
        self.bar: tqdm | None = None
        self.bars_started = 0

    def named(self, name: str) -> "ProgressBar":
        """The bar of one named pass of this counter: "label: name"."""
        return ProgressBar(self.owner, f"{self.label}: {name}", self.unit)

    def __call__(self, done: int, total: int, note: str | None = None) -> None:
        if not self.owner.enabled:
            return
        if self.bar is None or self.bar.total != total or done < self.bar.n:
            self.close()
            # the terminal's width (a pseudo-terminal may report 0 columns: then 100)
            width = shutil.get_terminal_size((100, 24)).columns or 100
            self.bar = tqdm(total=total, desc=self.label, unit=self.unit, file=self.owner.stream, leave=True,
                            ncols=width, smoothing=0.1)
            self.bars_started += 1
        if note is not None:
            self.bar.set_postfix_str(note, refresh=False)
        self.bar.update(done - self.bar.n)
        if done >= total:
            self.close()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None
