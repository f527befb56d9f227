"""Term of ``[firing]``: the shot's momentum sets the barrel moving, or its breech force pushes it.

Momentum of a shot (conservation of momentum, with the powder gas's after-effect)::

    I = projectile_mass * muzzle_velocity + charge_mass * gas_velocity          (kg m/s)

e.g. 6.86 x 564 = 3869 kg m/s in the paper (no charge).  Without ``[firing.pulse]`` the shot is an impulse:
the barrel starts at ``v0 = I / moving_mass`` (6.86 x 564 / 5600 = 0.6909 m/s; the barrel term,
:mod:`.barrel`, applies the conventions) and the table adds nothing else.

With ``[firing.pulse]`` (``times`` s, ``forces`` N) the barrel starts at rest (v0 = 0) and the breech
force ``F(t)`` acts on it: linear between the table's points, 0 before the first and after the last (so
it jumps there if the first or last force is not 0), multiplied by ``I / J`` with
``scale_to_momentum`` (``J = sum (F_i + F_(i+1)) (t_(i+1) - t_i) / 2``, the table's impulse: exact for a
piecewise-linear force), so that its impulse is the shot's momentum.  Every shot of a ``[burst]`` repeats it
shifted by its firing time ``t_k`` (:func:`shot_times`).  It is a
:class:`~validation.reference.model.PiecewiseLinearLoad` named ``breech_force`` on the barrel: its work
``integral F v_M dt`` enters the energy balance, its table points are time events of the solve.
"""

from __future__ import annotations

from ..model import BARREL, PiecewiseLinearLoad

TABLES = ("firing",)
#: Name of the breech-force load (and of its work).
BREECH_FORCE = "breech_force"


def momentum(firing) -> float:
    """``I = m_p v_p + m_c v_g`` (kg m/s) of a ``[firing]`` table (module docstring)."""
    value = firing.projectile_mass * firing.muzzle_velocity
    charge = getattr(firing, "charge_mass", 0.0) or 0.0
    if charge > 0:
        value += charge * firing.gas_velocity
    return value


def recoil_velocity(firing, moving_mass: float) -> float:
    """``I / moving_mass`` (m/s) of a ``[firing]`` table and a recoiling mass (kg); 0 with a pulse (the
    barrel starts at rest and the breech force accelerates it)."""
    if getattr(firing, "pulse", None) is not None:
        return 0.0
    return momentum(firing) / moving_mass


def shot_times(scene) -> tuple[float, ...]:
    """Firing times (s): ``t_k = k * interval``, k = 0 .. shots - 1, of the scene's ``[burst]``; ``(0.0,)``
    without one."""
    burst = getattr(scene, "burst", None)
    if burst is None:
        return (0.0,)
    return tuple(k * float(burst.interval) for k in range(int(burst.shots)))


def pulse_table(pulse) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(times s, forces N) of a ``[firing.pulse]`` table as given (read from its file if it names one)."""
    table = getattr(pulse, "table", None)
    times, forces = table if table is not None else (pulse.times, pulse.forces)
    return tuple(float(t) for t in times), tuple(float(f) for f in forces)


def table_impulse(times, forces) -> float:
    """``sum (F_i + F_(i+1)) (t_(i+1) - t_i) / 2`` (N s): the integral of the piecewise-linear force."""
    return sum(0.5 * (forces[i] + forces[i + 1]) * (times[i + 1] - times[i]) for i in range(len(times) - 1))


def breech_force_points(firing, shots) -> list[tuple[float, float]]:
    """``(t s, F N)`` of the breech force of every shot (shot times ``shots``, s): the table shifted by each
    shot time, scaled (``scale_to_momentum``), with a point of force 0 at the table's first and last time
    where the force jumps from or to 0 (a repeated time: a jump)."""
    times, forces = pulse_table(firing.pulse)
    scale = momentum(firing) / table_impulse(times, forces) if firing.pulse.scale_to_momentum else 1.0
    points = []
    for shot in shots:
        if forces[0] != 0.0:
            points.append((shot + times[0], 0.0))
        points += [(shot + t, scale * f) for t, f in zip(times, forces)]
        if forces[-1] != 0.0:
            points.append((shot + times[-1], 0.0))
    return points


def build(builder, key: str, table) -> None:
    """The breech force on the barrel if the table has a pulse (every shot of a burst); else nothing: the
    effect is the barrel's initial velocity (:mod:`.barrel`)."""
    if getattr(table, "pulse", None) is None:
        return
    builder.add_load(PiecewiseLinearLoad(BREECH_FORCE, BARREL, breech_force_points(table, shot_times(builder.scene))))
