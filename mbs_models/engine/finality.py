"""When is a metric final?  The early stop's tracker, from the energy bounds of :mod:`.energy_bounds`.

The sweeps and studies need peak metrics (Table 2's maximum barrel displacement, the peak contact
force, the maximum absorber velocity, the peak force on the mount), which occur in the first second of
a 10 s run.  This module proves, from the state at one instant, that no later instant can beat the
maxima seen so far; the engine (:func:`mbs_models.simulate` with ``stop_when_final``) then stops there.
The bounds it uses (and their numerical slack) are those of :mod:`.energy_bounds`.

Finality (what :class:`FinalityTracker` decides from the states it is shown)
---------------------------------------------------------------------------
* ``max_barrel_displacement`` (and its time): final once the x_M bound <= the largest x_M seen;
* ``max_absorber_velocity``: once every absorber's velocity bound <= the largest velocity it had;
* ``peak_contact_force``: once every contact (absorbers and stops) is unreachable or its force bound
  <= the largest force it had;
* ``impacts``: once every contact's force bound <= the impact threshold and no contact is going on.  An
  impact is an episode whose peak rises above the force the contact held at rest when it began by more
  than the threshold (0 for an episode beginning inside the window, ``k p(0)^n`` for one going on at
  t = 0).  With every contact open, every episode so far is closed, so its record and whether it is an
  impact are those of the full run; every later episode begins inside the window, from 0 N, and peaks
  at most at the bound: no impact.  A contact going on blocks it: its episode's end is not known yet,
  and even a preload's hold from t = 0 (no impact) could still open and a new episode begin (telling
  the hold from a later episode would take the history of every sample, which the tracker, shown only
  some states, does not have).  So a preload resting on its stop keeps ``impacts`` from being final;
* ``peak_support_force``: once the bound on |S| <= the largest |S| seen.

Ties keep the earliest time, as the peak refinement does.  The observed values are samples of the
solution, hence lower bounds of its refined maxima: a metric proven final from samples is final.
"""

from __future__ import annotations

import math
from typing import Iterable

from ..errors import SceneError
from ..results.result import ALL_METRICS
from ..scene import Scene
from ..stop_reason import StopReason
from .energy_bounds import ENERGY_SLACK, EnergyBounds, connector_ends, dissipative
from .mechanism import Mechanism

#: Metrics that can be proven final before the end time (names of :class:`~mbs_models.results.result.Result` fields).
FINAL_METRICS = ALL_METRICS
#: Why a run ended (``Result.stop_reason``): the members of :class:`~mbs_models.stop_reason.StopReason`.
STOP_END_TIME = StopReason.END_TIME
STOP_METRICS_FINAL = StopReason.METRICS_FINAL
STOP_NO_BOUND = StopReason.NO_ENERGY_BOUND
STOP_ENERGY_CHECK = StopReason.ENERGY_CHECK
STOP_AT_REST = StopReason.AT_REST
#: The metrics :meth:`FinalityTracker.check` decides together.
_CONTACT_METRICS = ("peak_contact_force", "impacts", "max_absorber_velocity")
_CONTACT_METRICS_SET = frozenset(_CONTACT_METRICS)
#: :meth:`FinalityTracker.check`'s metrics left when the barrel's maximum is the only one
_BARREL_ONLY = ["max_barrel_displacement"]


def check_metric_names(names, key: str = "stop_when_final") -> tuple[str, ...]:
    """Validate a collection of metric names; return them as a tuple in :data:`FINAL_METRICS` order.

    Raises SceneError naming ``key`` and the allowed values for a string (not a sequence of names),
    an unknown name or a non-string item.
    """
    if isinstance(names, str):
        raise SceneError(key, f"must be a sequence of metric names (e.g. ({names!r},)), not a string; "
                              f"allowed: {', '.join(FINAL_METRICS)}")
    try:
        items = list(names)
    except TypeError:
        raise SceneError(key, f"must be a sequence of metric names; allowed: {', '.join(FINAL_METRICS)}") from None
    for name in items:
        if not isinstance(name, str) or name not in FINAL_METRICS:
            raise SceneError(key, f"unknown metric {name!r}; allowed: {', '.join(FINAL_METRICS)}")
    return tuple(name for name in FINAL_METRICS if name in items)


class FinalityTracker:
    """Watches the states of one solve and says which metrics are final (see the module docstring).

    Show it the states in time order with :meth:`observe` (body positions m and velocities m/s in body
    order); :attr:`final` holds the metrics proven final so far (once final, always final) and
    :attr:`final_at` the time (s) each was proven.  ``requested`` are the metrics the caller wants;
    :attr:`done` is True once all of them are final (never for a non-dissipative scene).  Metrics of
    effects the scene lacks (contacts, absorbers) count as final from the start.
    """

    def __init__(self, scene: Scene | Mechanism, requested: Iterable[str], impact_threshold: float):
        self.bounds = EnergyBounds(scene)
        self.mechanism = self.bounds.mechanism
        self.scene = self.mechanism.scene
        self.requested = check_metric_names(requested)
        self.impact_threshold = float(impact_threshold)
        self.enabled = dissipative(self.mechanism)
        #: the energy bounds hold only after the last shot or pulse (s): states before it prove nothing
        self.after = self.mechanism.last_input_time
        self.max_barrel_position = -math.inf
        self.max_velocity = [-math.inf] * len(self.mechanism.bodies)
        self.max_contact_force = [0.0] * len(self.bounds.contacts)
        self.max_support_force = 0.0
        self.final: set[str] = set()
        self.final_at: dict[str, float] = {}
        self.done = False
        #: the requested metrics not final yet (kept by _mark, through which alone :attr:`final` grows)
        self._pending = list(self.requested)
        self._absorbers = list(range(1, len(self.mechanism.bodies)))
        #: ``(j, F, a, b)`` per contact (index j in :attr:`EnergyBounds.contacts`, its ``python_force_function``, its
        #: ends as :func:`connector_ends` gives them): :meth:`EnergyBounds.contact_force` without the lookups
        self._contact_forces = tuple((j, c.python_force_function()) + connector_ends(self.mechanism, c)
                                     for j, c in enumerate(self.bounds.contacts))
        #: :meth:`EnergyBounds.contact_reachable` of a contact in the potential well moves the well's cached
        #: ends (the start of the next :meth:`PotentialWell.end`): :meth:`check` then evaluates it at every
        #: call, as always; otherwise (a pure function) only when a contact metric is pending
        self._reach_moves_well = any(self.bounds._in_well(c) for c in self.bounds.contacts)
        self._needs_support = "peak_support_force" in self.requested
        self._needs_contacts = any(n in self.requested for n in ("peak_contact_force", "impacts"))
        empty = []
        if not self.bounds.contacts:
            empty += ["peak_contact_force", "impacts"]
        if not self._absorbers:
            empty.append("max_absorber_velocity")
        self._mark(empty, 0.0)

    @property
    def max_absorber_velocity(self) -> float:
        """The largest absorber velocity seen (m/s), over all absorbers."""
        return max((self.max_velocity[i] for i in self._absorbers), default=-math.inf)

    def _mark(self, names: Iterable[str], t: float) -> None:
        for name in names:
            if name not in self.final:
                self.final.add(name)
                self.final_at[name] = float(t)
        self._pending = [name for name in self.requested if name not in self.final]
        self.done = self.enabled and bool(self.requested) and not self._pending

    def observe(self, t: float, x, v, *, support: bool | None = None) -> bool:
        """Take the state at time ``t`` (s) into account; return :attr:`done`.

        The state updates the running maxima (samples of the solution: lower bounds of its maxima,
        so observing only some states is safe, it merely proves finality a little later), then the
        bounds of the requested metrics are evaluated at it.
        """
        if x[0] > self.max_barrel_position:
            self.max_barrel_position = x[0]
        max_velocity = self.max_velocity
        for i in self._absorbers:
            if v[i] > max_velocity[i]:
                max_velocity[i] = v[i]
        forces = []
        max_contact_force = self.max_contact_force
        for j, contact_force, a, b in self._contact_forces:  # EnergyBounds.contact_force, inlined
            force = contact_force((x[b] if b is not None else 0.0) - (x[a] if a is not None else 0.0),
                                  (v[b] if b is not None else 0.0) - (v[a] if a is not None else 0.0))
            forces.append(force)
            if force > max_contact_force[j]:
                max_contact_force[j] = force
        if self._needs_support if support is None else support:
            magnitude = abs(self.bounds.support_force(x, v))
            if magnitude > self.max_support_force:
                self.max_support_force = magnitude
        if self.enabled:
            self.check(t, x, v, forces, self.requested, rising=x[0] >= self.max_barrel_position and v[0] > 0.0)
        return self.done

    def check(self, t: float, x, v, forces, names: Iterable[str] = FINAL_METRICS, *, rising: bool = False) -> None:
        """Mark those of ``names`` that the energy at this state (contact forces ``forces`` N, in
        :attr:`EnergyBounds.contacts` order) proves final.

        ``rising``: the barrel is at the largest x_M seen and moving on (v_M > 0): x_M exceeds that maximum
        right after this instant, so no bound that holds can prove it final here; ``max_barrel_displacement``
        is not evaluated then (nor the energy, when it is the only metric left: most observed states of a
        sweep's early stop, during the recoil)."""
        if not self.enabled or t < self.after:
            return
        # (the requested names not final yet are kept by _mark: not filtered again at every observed state)
        todo = self._pending if names is self.requested else [name for name in names if name not in self.final]
        if not todo or (rising and todo == _BARREL_ONLY):
            return
        bounds = self.bounds
        energy = bounds.with_slack(bounds.energy(x, v))
        newly = []
        if ("max_barrel_displacement" in todo and not rising
                and bounds.barrel_displacement(energy) <= self.max_barrel_position):
            newly.append("max_barrel_displacement")
        # the contact metrics are decided together (as they are cheap together): all of them as soon as
        # any is pending
        contact_metrics = not _CONTACT_METRICS_SET.isdisjoint(todo)  # any of them in todo
        if contact_metrics:  # (a new list: todo may be _pending)
            todo = todo + [n for n in _CONTACT_METRICS if n not in self.final and n not in todo]
        if contact_metrics or self._reach_moves_well:  # else nothing below reads it (see __init__)
            reachable = [bounds.contact_reachable(j, energy) for j in range(len(bounds.contacts))]
        if "peak_contact_force" in todo or "impacts" in todo:
            force_bounds = [bounds.contact_force_bound(j, energy) for j in range(len(bounds.contacts))]
            if all(not reachable[j] or force_bounds[j] <= self.max_contact_force[j] for j in range(len(reachable))):
                newly.append("peak_contact_force")
            if all(fb <= self.impact_threshold for fb in force_bounds) and all(f == 0.0 for f in forces):
                newly.append("impacts")
        if "max_absorber_velocity" in todo:
            final = True
            for i in self._absorbers:
                bound = bounds.body_velocity(i, energy)
                if i in bounds._free_oscillators:
                    _, contacts = bounds._free_oscillators[i]
                    if not any(reachable[bounds.contacts.index(c)] for c in contacts):
                        own = bounds.oscillator_energy(i, x, v) * (1.0 + ENERGY_SLACK)
                        bound = min(bound, bounds.velocity_from_own_energy(i, own))
                if bound > self.max_velocity[i]:
                    final = False
                    break
            if final:
                newly.append("max_absorber_velocity")
        if "peak_support_force" in todo and bounds.support_force_bound(energy) <= self.max_support_force:
            newly.append("peak_support_force")
        if newly:
            self._mark(newly, t)

    def observe_last(self, t: float, x, v) -> None:
        """Observe the final state of a solve and check *every* metric there (not only the requested ones)."""
        self.observe(t, x, v, support=True)
        forces = [self.bounds.contact_force(c, x, v) for c in self.bounds.contacts]
        self.check(t, x, v, forces, FINAL_METRICS)
