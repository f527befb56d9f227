"""The bounds of every adaptive solve: a step budget and a cap on the stored output, so that no run goes on for ever.

An adaptive solver's step can collapse: e.g. the ``compression_only`` reading of the paper switches the
contact force off at maximum compression while the springs push the bodies back together, so the force
switches on and off at every step (a sticking contact that a force law cannot represent; the event-driven
reference handles it with a sliding mode), and a spring of 1e19 N/m on the barrel has a period of 1.5e-7 s.
Exudyn would then take millions of tiny steps -- or, at its minimum step size, re-try one step for ever (its
DOPRI5 rejects a step at the minimum size once it has warned about it).  :class:`StepBudget` is installed as
Exudyn's pre-step function for every adaptive solve (Exudyn calls it before every attempt of a step, rejected
ones too); when the budget is spent, or the step has stalled (:data:`STALL_WINDOW_STEPS` steps with a mean
step below 1e-7 s) or collapsed (:data:`COLLAPSE_WINDOW_STEPS` steps with a mean below 1e-8 s), it stops the solve,
and ``simulate`` raises a :class:`~mbs_models.errors.SimulationError` that says why.

The budget is the smaller of

* :func:`step_budget`: :data:`STEPS_PER_SIMULATED_SECOND` per simulated second of the requested window, at
  least :data:`MINIMUM_STEP_BUDGET` (the paper's cases take 200-1500 steps per second); and
* :func:`sample_cap`: the output samples the run may store.  Exudyn keeps every step's sensor values (the
  refinement of extrema between steps needs them all), so a long window at many steps per second would keep
  growing: the cap is :data:`MAX_STORED_VALUES` values (samples x sensors) per run, about 1 GB at the peak of
  the post-processing (60-120 bytes per stored value, measured).  A run that needs more fails with a
  SimulationError saying so, instead of thinning its output (which would weaken every refined metric without
  notice).  Runs that come to rest stop there (:mod:`mbs_models.engine.rest`) and store no more.

Fixed-step solvers take the number of steps they are given (at most ``stability.MAX_STEPS``) and store at most
:func:`sample_cap` samples: their output is thinned beyond it (``driver.exudyn_simulation_settings``).

Cost: the engine's pre-step function counts the steps itself and calls :meth:`StepBudget.advance` only at
the budget's checkpoints (:attr:`StepBudget.next_check`: every :data:`COLLAPSE_WINDOW_STEPS`-th step and the
budget's end), so a step pays one Python call with an integer increment and a comparison (about 0.2 us;
the validation pages, "Limits").
"""

from __future__ import annotations

#: Steps allowed per simulated second (the presets use 200-1500 steps/s on the paper cases).
STEPS_PER_SIMULATED_SECOND = 50_000
#: Steps allowed at least, whatever the end time.
MINIMUM_STEP_BUDGET = 200_000
#: Output values (samples x sensors: three per body, one per contact force) one run may store at most.
MAX_STORED_VALUES = 10_000_000
#: A stall: this many consecutive steps ...
STALL_WINDOW_STEPS = 20_000
#: ... advancing the time by less than this in total (mean step < 1e-7 s; the stiffest contacts
#: tested, k_c = 1e12 on a 1 kg absorber, need steps of about 1e-6 s).
STALL_WINDOW_TIME = 2e-3
#: A collapse: this many consecutive steps (a tenth of the stall window; a whole multiple of ...
COLLAPSE_WINDOW_STEPS = 2_000
#: ... advancing the time by less than this (mean step < 1e-8 s: a hundredth of the steps the stiffest tested
#: contact needs, a tenth of the stall's mean step).  A step that has collapsed that far (a contact switching
#: on and off at every step: 1e-10 to 8e-9 s per step measured on the paper's ``compression_only`` reading)
#: is stopped after 2000 steps instead of 20 000; a slower creep is left to the stall window, as before.
COLLAPSE_WINDOW_TIME = 2e-5


def step_budget(end_time: float) -> int:
    """The number of steps an adaptive solve to ``end_time`` (s) may take (the sample cap aside)."""
    return max(MINIMUM_STEP_BUDGET, int(STEPS_PER_SIMULATED_SECOND * end_time))


def sample_cap(sensors: int) -> int:
    """The output samples a run with ``sensors`` sensors may store: ``MAX_STORED_VALUES // sensors``."""
    return max(1, MAX_STORED_VALUES // max(1, int(sensors)))


class StepBudget:
    """Exudyn pre-step user function that stops the solve after ``max_steps`` steps, or earlier when
    :data:`STALL_WINDOW_STEPS` consecutive steps advance the time by less than :data:`STALL_WINDOW_TIME` (a stall),
    or :data:`COLLAPSE_WINDOW_STEPS` by less than :data:`COLLAPSE_WINDOW_TIME` (a collapse, found sooner).

    ``stored_samples``: the run's :func:`sample_cap`, if it binds (smaller than ``max_steps``, which it then
    replaces); the explanation then says that the output cap, not the step budget, stopped the solve."""

    def __init__(self, max_steps: int, stored_samples: int | None = None):
        self.capped = stored_samples is not None and int(stored_samples) < int(max_steps)
        self.max_steps = int(stored_samples) if self.capped else int(max_steps)
        self.steps = 0
        self.exhausted_at: float | None = None
        self.stalled = False
        #: the stall was found by the shorter collapse window (:data:`COLLAPSE_WINDOW_STEPS`)
        self.collapsed = False
        self._window_start = 0.0
        self._collapse_start = 0.0

    @classmethod
    def for_run(cls, end_time: float, sensors: int) -> "StepBudget":
        """The budget of a run to ``end_time`` (s) storing ``sensors`` sensors: :func:`step_budget` or
        :func:`sample_cap`, whichever is smaller."""
        return cls(step_budget(end_time), sample_cap(sensors))

    def __call__(self, mbs, t: float) -> bool:
        """Count one step at time ``t`` (s); False once the budget is spent (and on every later call)."""
        return self.advance(self.steps + 1, t)

    def advance(self, steps: int, t: float) -> bool:
        """The budget after ``steps`` steps in all, the last at time ``t`` (s): the same as calling it once per
        step, provided no checkpoint (:attr:`next_check`) was skipped since the last call -- between two
        checkpoints a call only counts.  False once the budget is spent (and on every later call)."""
        self.steps = steps
        if self.exhausted_at is not None:
            return False
        if steps % COLLAPSE_WINDOW_STEPS == 0:
            collapsed = t - self._collapse_start < COLLAPSE_WINDOW_TIME
            stalled = steps % STALL_WINDOW_STEPS == 0 and t - self._window_start < STALL_WINDOW_TIME
            if collapsed or stalled:
                self.stalled = True
                self.collapsed = collapsed and not stalled
                self.exhausted_at = float(t)
                return False
            self._collapse_start = t
            if steps % STALL_WINDOW_STEPS == 0:
                self._window_start = t
        if steps > self.max_steps:
            self.exhausted_at = float(t)
            return False
        return True

    @property
    def next_check(self) -> int:
        """The smallest step count at which :meth:`advance` can do more than count: the end of the current
        stall window or the first step beyond the budget (the next step once the budget is spent)."""
        if self.exhausted_at is not None:
            return self.steps + 1
        return min((self.steps // COLLAPSE_WINDOW_STEPS + 1) * COLLAPSE_WINDOW_STEPS, self.max_steps + 1)

    def explanation(self, solver: str, end_time: float, hint: str | None = None) -> str:
        """Why the solve was stopped, for the SimulationError message.  ``hint``: what in the scene makes it
        need so many steps (the end of the message); None: the chattering contact, the usual cause."""
        mean_step = f"mean step {self.exhausted_at / self.max_steps:.2g} s"
        if self.stalled:
            steps, time = ((COLLAPSE_WINDOW_STEPS, COLLAPSE_WINDOW_TIME) if self.collapsed
                           else (STALL_WINDOW_STEPS, STALL_WINDOW_TIME))
            cause = f"the step size collapsed: {steps} steps advanced less than {time:g} s (step budget stopped the solve)"
        elif self.capped:
            cause = (f"the run stores every step's output and reached its cap of {self.max_steps} samples "
                     f"({MAX_STORED_VALUES:.0e} values over its sensors, about 1 GB; {mean_step}): simulate a "
                     f"shorter window, or stop once the metrics are final (stop_when_final)")
        else:
            cause = (f"the step budget of {self.max_steps} steps ({STEPS_PER_SIMULATED_SECOND} per simulated "
                     f"second, at least {MINIMUM_STEP_BUDGET}) was spent ({mean_step})")
        if hint is None:
            hint = ("Typically a contact that switches on and off at every step (sticking or chattering); the "
                    "event-driven reference (validation.reference) handles such scenes")
        return f"Exudyn {solver} stopped at t = {self.exhausted_at:.6g} s of {end_time:g} s: {cause}. {hint}"
