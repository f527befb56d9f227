"""How the studies report progress: a counter per phase, a named one per pass of the convention study."""

from __future__ import annotations

from validation.studies import conventions
from validation.studies.progress import counter, named


def test_plain_progress_gets_a_line_about_every_quarter():
    lines = []
    count = counter(lines.append, "gap sweeps")
    for done in range(1, 9):
        count(done, 8)
    assert lines == ["  gap sweeps: 2/8", "  gap sweeps: 4/8", "  gap sweeps: 6/8", "  gap sweeps: 8/8"]
    lines.clear()
    named(count, "engine pass")(8, 8)
    assert lines == ["  gap sweeps: 8/8 (engine pass)"]


class _Bars:
    """A progress object with counters that name their passes (as the command line's tqdm bars do)."""

    def __init__(self):
        self.calls = []

    def __call__(self, message):
        self.calls.append(("stage", message))

    def counter(self, label, unit="run"):
        return _Counter(self, label)


class _Counter:
    def __init__(self, owner, label):
        self.owner, self.label = owner, label

    def named(self, name):
        return _Counter(self.owner, f"{self.label}: {name}")

    def __call__(self, done, total, note=None):
        self.owner.calls.append((self.label, done, total))


def test_the_convention_study_names_its_two_passes(monkeypatch):
    def fake_parallel_map(function, items, *, workers=None, progress=None):
        items = list(items)
        progress(len(items), len(items))
        return [{} for _ in items]

    monkeypatch.setattr(conventions, "parallel_map", fake_parallel_map)
    bars = _Bars()
    cases = conventions.CONVENTION_CASES[:1]
    conventions.study_conventions(cases, workers=1, progress=counter(bars, "convention study"))
    labels = [call[0] for call in bars.calls]
    assert labels == ["convention study: reference pass", "convention study: engine pass"]
    assert bars.calls[0][1] == bars.calls[0][2] == len(conventions._cases(cases[0][1]))
