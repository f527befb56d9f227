"""The refinements of one run on its interpolated state, in lockstep: contact episodes and the support peak.

A contact episode is a maximal run of samples with force > 0.  For every episode of every contact its
peak is refined near its largest sample (:func:`~mbs_models.results.peaks.maxima_near_samples`: the law
on the Hermite-interpolated state, nested grids over the two sample intervals beside it); for every
episode whose peak exceeds the impact threshold, its start and end are refined to the first time the
force is > 0 after the sample before it and the first time it is <= 0 after its last sample
(:func:`~mbs_models.results.nested_grids.first_true_search`).  The largest |support force| is refined
the same way near its largest sample.

All these searches run in lockstep (:func:`~mbs_models.results.nested_grids.run`): each round
interpolates every body's state once at all the times the searches ask for, and evaluates each
search's force on its part.  Start and end searches of the episodes whose largest *sample* exceeds
the threshold (surely impacts) run beside the peak searches; those of episodes that only the refined
peak lifts above it run in a second round of searches.  Every bracket's arithmetic is that of the
one-episode search, so the results are those of refining the episodes one by one, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .nested_grids import first_true_search, run
from .peaks import maxima_near_samples, run_argmax, run_bounds
from .result import Impact


@dataclass
class Episodes:
    """The contact episodes of one contact, as arrays.

    ``first``/``last``: sample indices bounding each run of force > 0; ``k``: its (first) largest
    sample; ``peak_force`` (N) and ``time_of_peak_force`` (s): the refined maximum of the law near ``k``
    (never below the sample); ``start``/``end`` (s): the refined times the force turns positive and back
    for episodes whose peak exceeds the threshold, the bounding samples for the others and at the ends
    of the window.
    """

    first: np.ndarray
    last: np.ndarray
    k: np.ndarray
    peak_force: np.ndarray
    time_of_peak_force: np.ndarray
    start: np.ndarray
    end: np.ndarray

    def impacts(self, contact: str, mask=None) -> list[Impact]:
        """The episodes (those in ``mask``) as :class:`Impact` records."""
        columns = (self.start, self.end, self.peak_force, self.time_of_peak_force)
        if mask is not None:
            columns = tuple(c[mask] for c in columns)
        return [Impact(start=a, end=b, peak_force=p, time_of_peak_force=tp, contact=contact)
                for a, b, p, tp in zip(*(c.tolist() for c in columns))]


def _crossing_search(time: np.ndarray, first: np.ndarray, last: np.ndarray, opens: np.ndarray, closes: np.ndarray):
    """Start (after sample first-1) and end (after sample last) searches of the episodes ``opens``/``closes``."""
    closing = np.concatenate([np.zeros(len(opens), dtype=bool), np.ones(len(closes), dtype=bool)])[:, None]
    lo = np.concatenate([time[first[opens] - 1], time[last[closes]]])
    hi = np.concatenate([time[first[opens]], time[last[closes] + 1]])
    # True where the force is > 0 (an onset) or <= 0 (a release)
    return first_true_search(lambda force: (force > 0.0) != closing, lo, hi)


class _Rounds:
    """Searches with the function each evaluates on the interpolated state ``(x, v, t)``, run in lockstep.

    The functions are elementwise in the times, so neighbouring parts of a round that evaluate the same
    function (one contact's peak and crossing searches) are evaluated in one call on their joined times.
    """

    def __init__(self, interp):
        self.interp = interp
        self.searches: list = []
        self.functions: list = []

    def add(self, searches, function) -> slice:
        start = len(self.searches)
        self.searches += list(searches)
        self.functions += [function] * len(searches)
        return slice(start, len(self.searches))

    def run(self) -> list:
        if not self.searches:
            return []

        def evaluate(times, parts):
            x, v = self.interp.state(times)
            out = []
            for function, span, members in _same_function_spans(self.functions, parts):
                values = function({n: a[span] for n, a in x.items()}, {n: a[span] for n, a in v.items()}, times[span])
                out += [values[part.start - span.start:part.stop - span.start] for part in members]
            return out

        return run(evaluate, self.searches)


def _same_function_spans(functions: list, parts: list[tuple[int, slice]]) -> list[tuple]:
    """``(function, span, parts)`` of each maximal run of neighbouring ``parts`` (``(search index, slice)``)
    whose searches evaluate the same function: ``span`` is the slice they cover together."""
    runs: list[tuple] = []
    for index, part in parts:
        function = functions[index]
        if runs and runs[-1][0] is function and runs[-1][1][-1].stop == part.start:
            runs[-1][1].append(part)
        else:
            runs.append((function, [part]))
    return [(function, slice(members[0].start, members[-1].stop), members) for function, members in runs]


def contact_force_function(mechanism, connector):
    """``(x, v, t) -> F``: a connector's force (N) from per-body positions (m), velocities (m/s), times (s)."""
    return lambda x, v, t: connector.force(mechanism.relative(connector, x), mechanism.relative(connector, v), t)


def support_magnitude_function(mechanism):
    """``(x, v, t) -> |S|``: the magnitude of the force on the mount (N), the sum of the ground connectors'."""
    ground = [c for c in mechanism.connectors if c.support_sign]

    def magnitude(x, v, t):
        total = 0.0
        for connector in ground:
            d = mechanism.relative(connector, x)
            rate = mechanism.relative(connector, v)
            total = total + connector.support_sign * connector.force(d, rate, t)
        return np.abs(total)

    return magnitude


def refine(mechanism, time: np.ndarray, forces: dict[str, np.ndarray], interp, contacts, threshold: float,
           support_sample: int | None = None) -> tuple[dict[str, Episodes], tuple[float, float] | None]:
    """Episodes of each contact in ``contacts`` (their sampled ``forces[name]``, N) and, if
    ``support_sample`` is given, the refined maximum ``(value N, time s)`` of |S| near that sample."""
    rounds = _Rounds(interp)
    plans = []
    for connector in contacts:
        force = forces[connector.name]
        first, last = run_bounds(force > 0.0)
        k = run_argmax(force, first, last)
        function = contact_force_function(mechanism, connector)
        searches, assemble = maxima_near_samples(time, k)
        peaks = rounds.add(searches, function)
        surely = force[k] > threshold  # the peak is never below the sample: an impact, unless NaN
        opens = np.flatnonzero(surely & (first > 0))
        closes = np.flatnonzero(surely & (last < len(time) - 1))
        crossings = rounds.add([_crossing_search(time, first, last, opens, closes)], function) \
            if len(opens) or len(closes) else None
        plans.append((connector, force, first, last, k, assemble, peaks, crossings, opens, closes))
    support = None
    if support_sample is not None:
        searches, assemble_support = maxima_near_samples(time, [support_sample])
        support = rounds.add(searches, support_magnitude_function(mechanism))
    results = rounds.run()

    episodes: dict[str, Episodes] = {}
    late = _Rounds(interp)
    pending = []
    for connector, force, first, last, k, assemble, peaks, crossings, opens, closes in plans:
        peak, t_peak = assemble(results[peaks])
        sample = force[k]
        peak = np.where(sample > peak, sample, peak)  # max(refined, sample): the refined one on ties
        start, end = time[first], time[last]
        strong = peak > threshold
        if crossings is not None:
            found = results[crossings.start]
            keep = strong[opens]
            start[opens[keep]] = found[:len(opens)][keep]
            keep = strong[closes]
            end[closes[keep]] = found[len(opens):][keep]
        late_opens = np.flatnonzero(strong & (force[k] <= threshold) & (first > 0))
        late_closes = np.flatnonzero(strong & (force[k] <= threshold) & (last < len(time) - 1))
        if len(late_opens) or len(late_closes):
            index = late.add([_crossing_search(time, first, last, late_opens, late_closes)],
                             contact_force_function(mechanism, connector))
            pending.append((connector.name, index.start, late_opens, late_closes))
        episodes[connector.name] = Episodes(first, last, k, peak, t_peak, start, end)
    if pending:
        late_results = late.run()
        for name, index, late_opens, late_closes in pending:
            found = late_results[index]
            episodes[name].start[late_opens] = found[:len(late_opens)]
            episodes[name].end[late_closes] = found[len(late_opens):]
    support_peak = None
    if support is not None:
        values, times = assemble_support(results[support])
        support_peak = (float(values[0]), float(times[0]))
    return episodes, support_peak
