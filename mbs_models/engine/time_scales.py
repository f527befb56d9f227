"""The always-acting time scales of a scene, and the up-front refusal of a run they would make too long.

An explicit Runge-Kutta step (Exudyn's adaptive DOPRI5 and ODE23) is stable only while ``h |lambda|`` stays
inside its stability region, which reaches no further than ``|z| = 3.4`` for DOPRI5 and 2.5 for ODE23
(:data:`STABILITY_REACH` counts 4, a margin).  A motion of rate ``|lambda|`` that lasts the whole run therefore
needs at least ``duration |lambda| / 4`` steps, whatever the tolerances.  The connectors that act in every
state with a linear law -- a linear spring, a linear damper
(:meth:`~mbs_models.elements.connector.Connector.always_acting_fields`) -- give such motions: on the reduced
mass ``m`` of their two ends (the body's mass against the ground), a stiffness ``k`` and a damping ``c`` move
as ``m s^2 + c s + k = 0``, whose larger root is at least ``max(sqrt(k / m), c / (2 m))`` in magnitude (the
product of the roots is ``k / m``, their sum ``-c / m``): the connector's *rate* (1/s).

:func:`check_time_scales` (called by :func:`~mbs_models.simulate` before an adaptive solve) refuses a run whose
fastest such motion needs more steps than its step budget (:class:`~mbs_models.engine.guard.StepBudget`) with
a :class:`~mbs_models.errors.SceneError` naming the scene key, the time scale, the steps it needs and the
largest value that fits.  It refuses only what the budget would stop anyway, later: the contacts
(intermittent), the recoil brake's ``v|v|`` (stiff only while fast), the friction band (stiff only while
stuck) and a gas spring are not counted -- the budget bounds them.  :func:`time_scale_hint` says the same
for a run the budget stopped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..elements.connector import GROUND
from ..errors import SceneError
from .guard import MAX_STORED_VALUES, MINIMUM_STEP_BUDGET, STEPS_PER_SIMULATED_SECOND, StepBudget
from .mechanism import Mechanism
from .stability import estimate_contact

#: Largest ``|h lambda|`` counted for a stable explicit step (DOPRI5's stability region reaches 3.4, ODE23's 2.5).
STABILITY_REACH = 4.0
#: An always-acting motion needing this many steps per simulated second (1 % of the budget's rate) is named in the
#: message of a run the budget stopped.
NOTABLE_STEPS_PER_SECOND = 0.01 * STEPS_PER_SIMULATED_SECOND


@dataclass(frozen=True)
class TimeScale:
    """The fastest motion one always-acting connector gives (module docstring), SI units.

    key: the scene key that sets it (``"recoil_spring.stiffness"``); value: its value (N/m or N s/m);
    mass: the reduced mass of the connector's ends (kg); rate: the lower bound on the fastest root (1/s);
    stiffness: True if the spring sets it (a period, ``2 pi / rate``), False if the damper (a time constant,
    ``1 / rate``).
    """

    key: str
    value: float
    mass: float
    rate: float
    stiffness: bool

    @property
    def unit(self) -> str:
        return "N/m" if self.stiffness else "N s/m"

    def describe(self, key: bool = True) -> str:
        """``recoil_spring.stiffness = 1e+19 N/m on 5600 kg gives a period of 1.5e-07 s`` (without ``key``: from
        the value on)."""
        if self.stiffness:
            scale = f"a period of {2.0 * math.pi / self.rate:.2g} s"
        else:
            scale = f"a time constant of {1.0 / self.rate:.2g} s"
        text = f"{self.value:.3g} {self.unit} on {self.mass:.4g} kg gives {scale}"
        return f"{self.key} = {text}" if key else text

    def steps(self, duration: float) -> float:
        """Steps an explicit adaptive solve needs at least to follow this motion for ``duration`` s."""
        return duration * self.rate / STABILITY_REACH

    def largest_value(self, rate: float) -> float:
        """The largest value of :attr:`key` whose rate stays within ``rate`` (1/s): ``m rate^2`` or ``2 m rate``."""
        return self.mass * rate * rate if self.stiffness else 2.0 * self.mass * rate


def _table_keys(mechanism: Mechanism) -> dict[str, str]:
    """The scene key of every element's table, by element name (``"front"`` -> ``"absorber.0"``)."""
    keys = {}
    for element in mechanism.elements:
        keys[element.name] = next((k for k, t in mechanism.scene.tables() if t is element.table), element.name)
    return keys


def always_acting_time_scales(mechanism: Mechanism) -> list[TimeScale]:
    """The :class:`TimeScale` of every connector acting in every state with a linear law, fastest first."""
    keys = None
    out = []
    for connector in mechanism.connectors:
        stiffness_field, damping_field = connector.always_acting_fields()
        if stiffness_field is None and damping_field is None:
            continue
        masses = [mechanism.bodies[mechanism.body_index[end]].mass for end in (connector.a, connector.b)
                  if end != GROUND]
        mass = masses[0] if len(masses) == 1 else masses[0] * masses[1] / (masses[0] + masses[1])
        keys = keys or _table_keys(mechanism)
        table = keys.get(connector.element, connector.element)
        candidates = []
        if stiffness_field is not None:
            k = connector.linear_stiffness
            candidates.append(TimeScale(f"{table}.{stiffness_field}", k, mass, math.sqrt(k / mass), True))
        if damping_field is not None:
            c = connector.linear_damping
            candidates.append(TimeScale(f"{table}.{damping_field}", c, mass, c / (2.0 * mass), False))
        out.append(max(candidates, key=lambda s: s.rate))
    return sorted(out, key=lambda s: -s.rate)


def _budget_words(budget: StepBudget, sensors: int) -> str:
    if budget.capped:
        return (f"the {budget.max_steps} output samples a run may store ({MAX_STORED_VALUES:.0e} values over its "
                f"{sensors} sensors)")
    return (f"its step budget of {budget.max_steps} steps ({STEPS_PER_SIMULATED_SECOND} per simulated second, "
            f"at least {MINIMUM_STEP_BUDGET})")


def check_time_scales(mechanism: Mechanism, budget: StepBudget, duration: float) -> None:
    """Refuse (:class:`SceneError`, the key of the fastest always-acting connector) a run whose fastest always-acting
    motion needs more steps over ``duration`` s (the time it surely integrates) than ``budget`` allows."""
    scales = always_acting_time_scales(mechanism)
    if not scales or not scales[0].steps(duration) > budget.max_steps:
        return
    fastest = scales[0]
    fits = fastest.largest_value(STABILITY_REACH * budget.max_steps / duration)
    raise SceneError(fastest.key, f"{fastest.describe(key=False)}: an adaptive solve of {duration:g} s would need "
                                  f"at least {fastest.steps(duration):.2g} steps (an explicit step is stable only "
                                  f"while step x rate < {STABILITY_REACH:g}), more than "
                                  f"{_budget_words(budget, mechanism.sensor_count)}; at most {fits:.3g} "
                                  f"{fastest.unit} fits (or simulate a shorter window)")


def time_scale_hint(mechanism: Mechanism) -> str:
    """What in the scene may make a solve need many steps: for the message of a run the budget stopped."""
    words = []
    contact = estimate_contact(mechanism)
    if contact is not None:
        words.append("Typically a contact that switches on and off at every step (sticking or chattering; the "
                     "event-driven reference, validation.reference, handles such scenes) or a contact too stiff "
                     f"for the window (the fastest impact lasts ~{contact.duration:.2g} s)")
    scales = always_acting_time_scales(mechanism)
    if scales and scales[0].steps(1.0) >= NOTABLE_STEPS_PER_SECOND:
        fastest = scales[0]
        words.append(f"the fastest always-acting motion: {fastest.describe()} (at least "
                     f"{fastest.steps(1.0):.2g} steps per simulated second)")
    keys = _table_keys(mechanism)
    nonlinear = list(dict.fromkeys(keys.get(c.element, c.element) for c in mechanism.connectors
                                   if not c.is_contact and c.always_acting_fields() == (None, None)))
    if contact is None:
        where = f" (here: {', '.join(nonlinear)})" if nonlinear else ""
        words.append(("no linear spring or damper of the scene is that fast: " if not words else "")
                     + f"a nonlinear law{where} -- the recoil brake's v|v| at a small orifice, the cradle's friction "
                     "band, a gas spring -- or a value far outside its physical range can make the motion that stiff: "
                     "check the values and their units")
    text = "; ".join(words)
    return text[0].upper() + text[1:]
