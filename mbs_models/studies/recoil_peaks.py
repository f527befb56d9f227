"""The peak forces of a run and the phase of the shot each belongs to.

A shot fired at ``t_s`` drives the barrel out until it turns at ``t_max``, the time of its maximum
displacement ``x_max``; then it returns to battery and, with a battery buffer, into it.  The phase of an
instant ``t`` of that shot is::

    counter-recoil   t > t_max  and  x(t) < (1 - 1e-3) x_max   (returning; "into the buffer" while the
                                                                battery stop's contact force is > 0 at t)
    recoil           otherwise: from the shot to the turning point (the barrel moving out, v >= 0)

(``t_max``, ``x_max`` per shot with a burst, else the run's).  The turning point, not the velocity's sign
at the peak, draws the line: a barrel rebounding off its buffer moves out again (v > 0) but is still
returning from the shot, a barrel at rest before a pulse lifts it (v = 0) is in its recoil, and a stiff
buffer's peak comes at v = 0.  The 0.1 % of the stroke the barrel must have come back by makes a peak *at*
the turning point (the recoil spring's ``k x_max`` with the brake's force vanishing, v = 0) the end of the
recoil: the times of two flat extrema (the peak's and ``t_max``) are known only to
``sqrt(2 e x_max / a)`` for a relative error e of the displacement and a deceleration a, which can put
the peak a hair after ``t_max``, while the barrel has then come back by ~e x_max only.

:func:`peak_forces` lists, each with its time and phase: the brake's (or linear damper's) force, the
battery stop's contact force (when the scene has one and the barrel touches it), and the force on the
mount (the support force).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..elements.barrel import BARREL
from ..elements.connector import GROUND
from ..engine.mechanism import Mechanism

RECOIL, COUNTER_RECOIL = "recoil", "counter-recoil"
#: The elements whose connector force is reported as the brake's, with its label.
BRAKE_LABELS = {"recoil_brake": "brake force", "recoil_damper": "damper force"}
BATTERY_STOP = "battery_stop"


@dataclass(frozen=True)
class Peak:
    """One peak: ``label`` (what force), ``force`` (N, magnitude), ``time`` (s), ``phase`` (:data:`RECOIL` or
    :data:`COUNTER_RECOIL`) and ``into_buffer`` (the battery stop's contact force is > 0 at ``time``)."""

    label: str
    force: float
    time: float
    phase: str
    into_buffer: bool

    @property
    def where(self) -> str:
        """``during recoil``, ``on counter-recoil`` or ``on counter-recoil into the buffer``."""
        if self.phase == RECOIL:
            return "during recoil"
        return "on counter-recoil into the buffer" if self.into_buffer else "on counter-recoil"

    def text(self) -> str:
        """``peak brake force 85.12 kN during recoil (t = 0.012 s)``."""
        return f"peak {self.label} {self.force / 1e3:.2f} kN {self.where} (t = {self.time:.3f} s)"

    def to_dict(self) -> dict:
        return {"force": self.force, "time": self.time, "phase": self.phase, "into_buffer": self.into_buffer}


#: The fraction of its stroke the barrel must have come back by for an instant after ``t_max`` to be its
#: counter-recoil (see the module docstring).
RETURN_FRACTION = 1e-3


def turning_point(result, t: float) -> tuple[float, float]:
    """``(t_max s, x_max m)`` of the shot ``t`` (s) belongs to: the last shot fired at or before ``t`` with a
    burst, else the run's time and value of the maximum barrel displacement."""
    if result.time_of_max_barrel_displacement is None:
        raise ValueError("the phase needs the maximum barrel displacement (a run not stopped early)")
    shots = [shot for shot in (result.shots or []) if shot["time"] <= t]
    if shots:
        return shots[-1]["time_of_max_barrel_displacement"], shots[-1]["max_barrel_displacement"]
    return result.time_of_max_barrel_displacement, result.max_barrel_displacement


def phase_at(result, t: float) -> str:
    """:data:`COUNTER_RECOIL` once the barrel has turned and come back by 0.1 % of its stroke, else
    :data:`RECOIL` (see the module docstring)."""
    t_max, x_max = turning_point(result, t)
    returned = float(np.interp(t, result.time, result.barrel_position)) < (1.0 - RETURN_FRACTION) * x_max
    return COUNTER_RECOIL if t > t_max and returned else RECOIL


def _battery_contact(result):
    return next((c for c in result.contacts.values() if c.element == BATTERY_STOP), None)


def _peak(result, label: str, force: float, time: float) -> Peak:
    contact = _battery_contact(result)
    touching = contact is not None and float(np.interp(time, result.time, contact.force)) > 0.0
    return Peak(label, float(force), float(time), phase_at(result, time), touching)


def brake_force(result) -> tuple[str, np.ndarray] | None:
    """(label, force N on the samples) of the scene's brake or linear damper on the barrel, positive opposing
    the recoil; None without either."""
    for connector in Mechanism(result.scene).connectors:
        if connector.element in BRAKE_LABELS and {connector.a, connector.b} == {GROUND, BARREL}:
            sign = 1.0 if connector.b == BARREL else -1.0  # d = x_M (ground -> barrel) or -x_M
            force = sign * connector.force(sign * result.barrel_position, sign * result.barrel_velocity)
            return BRAKE_LABELS[connector.element], np.asarray(force, dtype=float)
    return None


def peak_forces(result) -> dict[str, Peak]:
    """The run's peak forces with their phases, keyed ``brake`` (the brake's or damper's |force|, largest
    sample), ``battery_stop`` (its contact's refined peak, when touched) and ``mount`` (the refined peak
    |support force|)."""
    out = {}
    brake = brake_force(result)
    if brake is not None:
        label, force = brake
        i = int(np.argmax(np.abs(force)))
        out["brake"] = _peak(result, label, abs(force[i]), result.time[i])
    contact = _battery_contact(result)
    if contact is not None and contact.time_of_peak_force is not None:
        out["battery_stop"] = _peak(result, "battery-stop force", contact.peak_force, contact.time_of_peak_force)
    if result.peak_support_force is not None:
        out["mount"] = _peak(result, "force on the mount", result.peak_support_force, result.time_of_peak_support_force)
    return out
