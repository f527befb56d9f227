"""The refinements of one run on its interpolated state, in lockstep: contact episodes and the support peak.

A contact episode is a maximal run of samples with force > 0.  For every episode of every contact its
peak is refined near its largest sample (:func:`~mbs_models.results.peaks.maxima_near_samples`: the law
on the Hermite-interpolated state, nested grids over the two sample intervals beside it); for every
episode whose peak exceeds the impact threshold (every impact among them: :meth:`Episodes.impact_mask`),
its start and end are refined to the first time the force is > 0 after the sample before it and the first
time it is <= 0 after its last sample (:func:`~mbs_models.results.nested_grids.first_true_search`).  The
largest |support force| is refined the same way near its largest sample.

All these searches run in lockstep (:func:`~mbs_models.results.nested_grids.run`): the peaks of every
contact's episodes and the support peak are one nested-grid search over all their brackets, the
starts and ends of every contact's episodes another; each bracket is evaluated with its own function
(the contact's force, or |S|), each function once per round on the neighbouring brackets it owns.
Each round interpolates every body's state once at all the times the searches ask for.  Start and
end searches of the episodes whose largest *sample* exceeds the threshold (surely impacts) run beside
the peak searches; those of episodes that only the refined peak lifts above it run in a second round
of searches.  Every bracket's arithmetic is that of the one-episode search, so the results are those
of refining the episodes one by one, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..elements.connector import GROUND
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

    def impact_mask(self, threshold: float, initial_force: float = 0.0) -> np.ndarray:
        """Which episodes are impacts (DESIGN.md, "Outputs every scene gets"): those whose peak force rises
        above the force they start from at rest by more than ``threshold`` (N), ``peak - B > threshold``.
        ``B`` is 0 for an episode that begins inside the window (the force was 0 just before it: the bodies
        came together) and ``initial_force`` (N: the contact's force at rest at t = 0, ``k p(0)^n``) for the
        episode already going on at the first sample (an initial interference): a preload resting on its
        stop is not an impact, an interference approached at t = 0 is one once its force rises enough."""
        baseline = np.where(self.first == 0, initial_force, 0.0)
        return self.peak_force - baseline > threshold

    def impacts(self, contact: str, mask=None) -> list[Impact]:
        """The episodes (those in ``mask``) as :class:`Impact` records."""
        columns = (self.start, self.end, self.peak_force, self.time_of_peak_force)
        if mask is not None:
            columns = tuple(c[mask] for c in columns)
        return [Impact(start=a, end=b, peak_force=p, time_of_peak_force=tp, contact=contact)
                for a, b, p, tp in zip(*(c.tolist() for c in columns))]


def _crossing_brackets(time: np.ndarray, first: np.ndarray, last: np.ndarray, opens: np.ndarray,
                       closes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(lo, hi, closing)`` of the start searches (after sample first-1) of the episodes ``opens`` and
    the end searches (after sample last) of the episodes ``closes``, in that order."""
    closing = np.concatenate([np.zeros(len(opens), dtype=bool), np.ones(len(closes), dtype=bool)])
    lo = np.concatenate([time[first[opens] - 1], time[last[closes]]])
    hi = np.concatenate([time[first[opens]], time[last[closes] + 1]])
    return lo, hi, closing


class _Rounds:
    """Searches over brackets, each bracket with the function its values come from, run in lockstep.

    A search is added with its groups of brackets: ``[(function, count), ...]`` in bracket order, each
    ``function(x, v, t)`` of per-body positions (m), velocities (m/s) and times (s), with an attribute
    ``bodies``: the names of the bodies it reads (:func:`_reading`).  The functions are elementwise in the
    times, so each is evaluated once per round on every run of neighbouring times that it owns (one
    contact's peak and crossing brackets), whatever the searches they belong to, on the interpolated state
    of its own bodies only (a round's cost grows with the times asked for, not with times x bodies).
    """

    def __init__(self, interp):
        self.interp = interp
        self.searches: list = []
        self.groups: list[list[tuple]] = []

    def add(self, search, groups: list[tuple]) -> int:
        """Add ``search`` with its groups of brackets; return its index among the results of :meth:`run`."""
        self.searches.append(search)
        self.groups.append([(function, int(count)) for function, count in groups if count])
        return len(self.searches) - 1

    def run(self) -> list:
        if not self.searches:
            return []

        def evaluate(times, parts):
            values = np.empty(len(times))
            for function, span in _function_spans(self.groups, parts):
                # only the bodies the function reads: one contact's two, not every body at every contact's times
                x, v = self.interp.state(times[span], function.bodies)
                values[span] = function(x, v, times[span])
            return [values[part] for _, part in parts]

        return run(evaluate, self.searches)


def _function_spans(groups: list[list[tuple]], parts: list[tuple[int, slice]]) -> list[tuple]:
    """``(function, span)`` of each maximal run of neighbouring times of a round evaluated by the same
    function.  ``parts``: ``(search index, slice)`` of each search's times; a search's request has one
    row (or time) per bracket, so its group of ``count`` brackets covers ``count`` rows of its part."""
    spans: list[list] = []
    for index, part in parts:
        brackets = sum(count for _, count in groups[index])
        per_bracket = (part.stop - part.start) // brackets
        start = part.start
        for function, count in groups[index]:
            stop = start + count * per_bracket
            if spans and spans[-1][0] is function and spans[-1][2] == start:
                spans[-1][2] = stop
            else:
                spans.append([function, start, stop])
            start = stop
    return [(function, slice(start, stop)) for function, start, stop in spans]


def _reading(function, connectors):
    """``function`` with the attribute ``bodies``: the bodies (names, in order) at the ends of ``connectors``."""
    function.bodies = tuple(dict.fromkeys(end for c in connectors for end in (c.a, c.b) if end != GROUND))
    return function


def contact_force_function(mechanism, connector):
    """``(x, v, t) -> F``: a connector's force (N) from per-body positions (m), velocities (m/s), times (s)."""
    return _reading(lambda x, v, t: connector.force(mechanism.relative(connector, x),
                                                    mechanism.relative(connector, v), t), [connector])


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

    return _reading(magnitude, ground)


def _add_peak_searches(rounds: _Rounds, time: np.ndarray, groups: list[tuple]):
    """Add the searches for the maxima of each group's function near each of its samples ``ks``
    (``groups``: ``[(function, ks), ...]``); return ``assemble(results)`` -> ``[(values, times), ...]`` per group."""
    if not groups:
        return lambda results: []
    counts = [len(ks) for _, ks in groups]
    bounds = np.concatenate([[0], np.cumsum(counts)])
    searches, brackets, assemble = maxima_near_samples(time, np.concatenate([ks for _, ks in groups]))
    indices = []
    for search, chosen in zip(searches, brackets):
        owned = np.diff(np.searchsorted(chosen, bounds))  # brackets of each group in this search
        indices.append(rounds.add(search, [(function, n) for (function, _), n in zip(groups, owned)]))

    def read(results) -> list[tuple[np.ndarray, np.ndarray]]:
        values, times = assemble([results[i] for i in indices])
        return [(values[a:b], times[a:b]) for a, b in zip(bounds[:-1], bounds[1:])]

    return read


def _add_crossing_search(rounds: _Rounds, groups: list[tuple]):
    """Add one search for the first times each group's function turns > 0 (an onset) or <= 0 (a release)
    in its brackets (``groups``: ``[(function, (lo, hi, closing)), ...]``); return ``read(results)`` -> the
    times (s) of each group's brackets, or None if there is no bracket."""
    counts = [len(lo) for _, (lo, _, _) in groups]
    if not sum(counts):
        return None
    bounds = np.concatenate([[0], np.cumsum(counts)])
    lo, hi, closing = (np.concatenate([brackets[i] for _, brackets in groups]) for i in range(3))
    closing = closing[:, None]
    search = first_true_search(lambda force: (force > 0.0) != closing, lo, hi)
    index = rounds.add(search, [(function, n) for (function, _), n in zip(groups, counts)])
    return lambda results: [results[index][a:b] for a, b in zip(bounds[:-1], bounds[1:])]


#: Contact episodes refined together at most: their searches' grids are held at once (some 55 kB per episode),
#: so a run with more episodes (a contact chattering over a long window) is refined in batches of this many,
#: one after the other -- the same floats, a bounded memory.
EPISODES_PER_BATCH = 1024


def refine(mechanism, time: np.ndarray, forces: dict[str, np.ndarray], interp, contacts, threshold: float,
           support_sample: int | None = None) -> tuple[dict[str, Episodes], tuple[float, float] | None]:
    """Episodes of each contact in ``contacts`` (their sampled ``forces[name]``, N) and, if
    ``support_sample`` is given, the refined maximum ``(value N, time s)`` of |S| near that sample.

    The episodes are refined in batches of at most :data:`EPISODES_PER_BATCH` (every contact's in one batch
    unless there are more): each bracket's arithmetic is the same in any batch, so the results are too."""
    sampled = []
    for connector in contacts:
        force = forces[connector.name]
        first, last = run_bounds(force > 0.0)
        sampled.append((connector, contact_force_function(mechanism, connector), force, first, last,
                        run_argmax(force, first, last)))
    parts: dict[str, list] = {connector.name: [] for connector in contacts}
    support_peak = None
    for batch in _batches(sampled, EPISODES_PER_BATCH):
        refined, support = _refine_batch(time, interp, batch, threshold, support_sample, mechanism)
        if support is not None:
            support_peak, support_sample = support, None  # searched in the first batch
        for (connector, *_), episodes in zip(batch, refined):
            parts[connector.name].append(episodes)
    episodes = {name: pieces[0] if len(pieces) == 1 else
                Episodes(*(np.concatenate([getattr(e, f) for e in pieces]) for f in Episodes.__dataclass_fields__))
                for name, pieces in parts.items()}
    return episodes, support_peak


def _batches(sampled: list, size: int) -> list[list]:
    """``sampled`` (per contact: connector, function, force, first, last, k) cut into batches of at most
    ``size`` episodes in all, each contact's episodes in order (a contact without episodes in the first)."""
    batches, current, room = [], [], size
    for connector, function, force, first, last, k in sampled:
        start = 0
        while True:
            stop = min(len(first), start + room)
            current.append((connector, function, force, first[start:stop], last[start:stop], k[start:stop]))
            room -= stop - start
            start = stop
            if start >= len(first):
                break
            batches.append(current)
            current, room = [], size
    batches.append(current)
    return batches


def _refine_batch(time: np.ndarray, interp, sampled: list, threshold: float, support_sample: int | None,
                  mechanism) -> tuple[list[Episodes], tuple[float, float] | None]:
    """:func:`refine` of the episodes in ``sampled`` (per contact: connector, function, force, first, last, k),
    all their searches in lockstep: the :class:`Episodes` of each entry and the support peak (or None)."""
    functions = [function for _, function, *_ in sampled]
    rounds = _Rounds(interp)
    peak_groups = [(function, k) for _, function, _, _, _, k in sampled]
    if support_sample is not None:  # first: the contacts' peak and crossing brackets then neighbour
        peak_groups.insert(0, (support_magnitude_function(mechanism), np.array([support_sample])))
    read_peaks = _add_peak_searches(rounds, time, peak_groups)
    surely = []
    for _, _, force, first, last, k in sampled:
        sure = force[k] > threshold  # the peak is never below the sample: an impact, unless NaN
        surely.append((np.flatnonzero(sure & (first > 0)), np.flatnonzero(sure & (last < len(time) - 1))))
    read_crossings = _add_crossing_search(rounds, [
        (function, _crossing_brackets(time, first, last, opens, closes))
        for function, (_, _, _, first, last, _), (opens, closes) in zip(functions, sampled, surely)])
    results = rounds.run()
    peaks = read_peaks(results)
    support_peak = None
    if support_sample is not None:
        values, times = peaks.pop(0)
        support_peak = (float(values[0]), float(times[0]))
    crossings = read_crossings(results) if read_crossings is not None else [None] * len(sampled)

    episodes: list[Episodes] = []
    lifted = []
    for (_, _, force, first, last, k), (peak, t_peak), (opens, closes), found in zip(
            sampled, peaks, surely, crossings):
        sample = force[k]
        peak = np.where(sample > peak, sample, peak)  # max(refined, sample): the refined one on ties
        start, end = time[first], time[last]
        strong = peak > threshold
        if found is not None:
            keep = strong[opens]
            start[opens[keep]] = found[:len(opens)][keep]
            keep = strong[closes]
            end[closes[keep]] = found[len(opens):][keep]
        late = strong & (force[k] <= threshold)
        lifted.append((np.flatnonzero(late & (first > 0)), np.flatnonzero(late & (last < len(time) - 1))))
        episodes.append(Episodes(first, last, k, peak, t_peak, start, end))
    late_rounds = _Rounds(interp)
    read_late = _add_crossing_search(late_rounds, [
        (function, _crossing_brackets(time, first, last, opens, closes))
        for function, (_, _, _, first, last, _), (opens, closes) in zip(functions, sampled, lifted)])
    if read_late is not None:
        for refined, (opens, closes), found in zip(episodes, lifted, read_late(late_rounds.run())):
            refined.start[opens] = found[:len(opens)]
            refined.end[closes] = found[len(opens):]
    return episodes, support_peak
