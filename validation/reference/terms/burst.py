"""Term of ``[burst]``: ``shots`` shots fired every ``interval`` s, shot k at ``t_k = k * interval``.

The first shot is the scene's firing at t = 0 (the barrel's v0, or the breech-force pulse).  Every later
shot k >= 1:

* without a pulse, is an instantaneous velocity jump of the barrel by v0 (the scene's initial velocity,
  with its conventions, :func:`.barrel.initial_velocity`) at ``t_k`` -- an
  :class:`~validation.reference.model.Impulse` named ``burst``: the solve stops at ``t_k``, jumps the
  state (``v_M += v0``, work ``M ((v_M + v0)^2 - v_M^2) / 2``) and restarts in the mode the new state is in;
* with a pulse, repeats the breech force shifted by ``t_k`` (added by :mod:`.firing`).

The shot times are the model's ``shot_times`` (the result's per-shot outputs) and time events.
"""

from __future__ import annotations

from ..model import BARREL, Impulse
from .barrel import initial_velocity
from .firing import shot_times

TABLES = ("burst",)
#: Name of the later shots' velocity jumps (and of their work).
BURST = "burst"


def build(builder, key: str, table) -> None:
    """The shot times and, without a pulse, the velocity jumps of the shots after the first."""
    scene = builder.scene
    times = shot_times(scene)
    builder.set_shot_times(times)
    firing = getattr(scene, "firing", None)
    if firing is not None and getattr(firing, "pulse", None) is not None:
        return
    if len(times) > 1:
        builder.add_impulse(Impulse(BURST, BARREL, times[1:], initial_velocity(scene)))
