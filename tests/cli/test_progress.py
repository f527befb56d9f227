"""Progress of ``recoil paper`` / ``recoil precision``: tqdm bars on a terminal, nothing otherwise."""

from __future__ import annotations

import io
import re

from mbs_models.cli import _progress
from mbs_models.cli.progress import ProgressBars


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_bars_show_the_pass_the_rate_and_the_time_left():
    stream = _Terminal()
    bars = ProgressBars(stream)
    assert bars.enabled
    bars("convention study")
    count = bars.counter("convention study")
    reference, engine = count.named("reference pass"), count.named("engine pass")
    for done in range(1, 5):
        reference(done, 4)
    for done in range(1, 3):
        engine(done, 2, "last: model (ii)")
    text = stream.getvalue()
    assert "[recoil] convention study" in text
    assert "convention study: reference pass" in text and "convention study: engine pass" in text
    assert re.search(r"4/4 \[\d\d:\d\d<\d\d:\d\d, +[\d.?]+ ?(run/s|s/run)", text), text
    assert "last: model (ii)" in text


def test_a_finished_bar_called_again_starts_a_new_bar():
    stream = _Terminal()
    count = ProgressBars(stream).counter("runs")
    count(2, 2)
    count(1, 3)
    count(3, 3)
    assert count.bars_started == 2
    assert "2/2" in stream.getvalue() and "3/3" in stream.getvalue()


def test_quiet_when_not_a_terminal():
    stream = io.StringIO()                  # a log file, a pipe: isatty() is False
    bars = ProgressBars(stream)
    assert not bars.enabled
    bars("engine vs reference on the paper cases")
    count = bars.counter("runs").named("reference pass")
    for done in range(1, 4):
        count(done, 3, "note")
    assert stream.getvalue() == ""


def test_the_command_lines_progress_is_quiet_under_capture(capsys):
    bars = _progress()
    bars("stage")
    bars.counter("runs")(1, 1)
    assert capsys.readouterr().err == ""
