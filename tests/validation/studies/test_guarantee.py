"""The guarantee's comparison of impacts (validation.studies.guarantee): impacts whose rise above the force at
rest they began with lies within THRESHOLD_BAND of the threshold may count on either side."""

from __future__ import annotations

from types import SimpleNamespace

from validation.studies.guarantee import THRESHOLD_BAND, _impact_errors

THRESHOLD = 1000.0  # N


def _impact(start: float, peak: float, end: float | None = None):
    return SimpleNamespace(start=start, end=start + 0.01 if end is None else end, peak_force=peak)


def test_the_ambiguous_band_is_on_the_rise_above_the_force_at_rest():
    """A hold from t = 0 at 8.5 kN rising to 9.5 kN + 0.5 band (one side only): ambiguous, no mismatch; rising
    to 9.5 kN + 2 bands: a mismatch.  A landing later in the window is judged on its peak (its force at rest: 0)."""
    band = THRESHOLD_BAND * THRESHOLD
    near = [_impact(0.0, 8500.0 + THRESHOLD + 0.5 * band)]
    clear = [_impact(0.0, 8500.0 + THRESHOLD + 2.0 * band)]
    assert _impact_errors(near, [], THRESHOLD, 1.0, 0.0, 8500.0)[0] == 0
    assert _impact_errors(clear, [], THRESHOLD, 1.0, 0.0, 8500.0)[0] == 1
    assert _impact_errors([], clear, THRESHOLD, 1.0, 0.0, 8500.0)[0] == 1
    # the same peaks later in the window rise from 0: far above the threshold, never ambiguous
    assert _impact_errors([_impact(0.5, near[0].peak_force)], [], THRESHOLD, 1.0, 0.0, 8500.0)[0] == 1
    # a landing peaking within the band of the threshold itself is ambiguous
    assert _impact_errors([_impact(0.5, THRESHOLD + 0.5 * band)], [], THRESHOLD, 1.0, 0.0, 8500.0)[0] == 0


def test_an_impact_cut_off_by_the_window_is_compared_on_its_start_only():
    """Its last force is on the rise: a start 8.4 us late gave 2.4 % at standard (a chattering 1-kg absorber)."""
    ours, theirs = _impact(0.9996, 1239.9, end=1.0), _impact(0.9996, 1269.8, end=1.0)
    mismatch, time_error, peak_error = _impact_errors([ours], [theirs], THRESHOLD, 1.0, 0.0)
    assert (mismatch, peak_error) == (0, 0.0) and time_error < 1e-12
    inside = _impact_errors([_impact(0.5, 1239.9, end=0.6)], [_impact(0.5, 1269.8, end=0.6)], THRESHOLD, 1.0, 0.0)
    assert abs(inside[2] - (1269.8 - 1239.9) / 1269.8) < 1e-15  # one that ends inside: its peak counts
