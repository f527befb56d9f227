"""Back in battery: when the barrel, after a shot's maximum displacement, returns to where it started.

A barrel within :data:`BATTERY_TOLERANCE` of its position before the (first) shot is "in battery" (DESIGN.md,
"Back in battery"; a burst's per-shot ``time_to_battery`` uses the same tolerance).
"""

from __future__ import annotations

import numpy as np

from .peaks import HermiteTrajectory, refine_crossing

#: A barrel within this distance (m) of its position before the first shot is "in battery".
BATTERY_TOLERANCE = 1.0e-3


def return_to_battery(time: np.ndarray, position: np.ndarray, velocity: np.ndarray, t_max: float,
                      x_max: float) -> float | None:
    """The first time ``t >= t_max`` (s) at which ``x(t) <= x(0) + BATTERY_TOLERANCE``, the barrel back within
    1 mm of its starting position after its maximum ``x_max`` (m) at ``t_max`` (s): the first output sample past
    it, then the crossing refined on the cubic Hermite interpolant of ``(x, v)``.  ``t_max`` when ``x_max`` is
    already that low; None when no sample after ``t_max`` is."""
    level = float(position[0]) + BATTERY_TOLERANCE
    if x_max <= level:
        return float(t_max)
    back = np.flatnonzero((time > t_max) & (position <= level))
    if not len(back):
        return None
    j = int(back[0])
    path = HermiteTrajectory(time, position, velocity)
    return refine_crossing(lambda times: path(times) <= level, max(float(time[j - 1]), t_max), float(time[j]))
