"""The shots that drive the recoil: the momentum of each shot, or the breech-force pulse, and bursts.

Table ``[firing]`` (Section 2.1 of the paper; DESIGN.md "Scene format, version 2")::

    projectile_mass = 6.86     # kg
    muzzle_velocity = 564.0    # m/s
    charge_mass = 0.0          # kg of propellant (version 2; default 0)
    gas_velocity = 1400.0      # m/s of the powder gas (needed when charge_mass > 0)
    [firing.pulse]             # version 2: a breech force F(t) on the barrel instead of an initial velocity
    times  = [0.0, 0.002, 0.006, 0.012]     # s, increasing, >= 0
    forces = [0.0, 2.0e6, 6.0e5, 0.0]       # N, >= 0, piecewise linear, 0 outside the table
    # file = "breech_force.csv"             # or two columns time,force (s, N) after a header line
    # scale_to_momentum = true              # scale the forces so that the impulse equals the momentum

Momentum of a shot (the free-recoil momentum, with the gas after-effect)::

    I = projectile_mass * muzzle_velocity + charge_mass * gas_velocity          (kg m/s)

(6.86 kg x 564 m/s = 3869 kg m/s in the paper, no charge).  Without a pulse, a shot is an impulse: the
barrel starts at ``v0 = I / M`` (6.86 x 564 / 5600 = 0.6909 m/s; the paper prints the rounded 0.7 m/s;
the scene's conventions may read it differently: ``v0_includes_absorber`` divides by M + m,
``rounded_initial_velocity`` rounds it).  With a pulse the barrel starts at rest and the breech force
``F(t)`` (N) acts on it: a :class:`BreechForce` load whose work enters the energy balance; its impulse
``integral F dt`` is reported (:attr:`Pulse.impulse`).

Table ``[burst]`` (version 2): ``shots`` (>= 1) fired every ``interval`` s; shot k fires at
``t_k = k * interval``.  Without a pulse each later shot adds the same velocity jump ``v0`` to the barrel
(an impulse, :meth:`Burst.impulses`); with a pulse the pulse repeats, shifted by ``t_k``.  A shot that
fires while the barrel is out of battery is reported, not refused: the burst declares the output ``shots``
(:func:`shot_outputs`; ``Result.shots``, the key ``shots`` of ``recoil run --json``, a line per shot in the
summary).
"""

from __future__ import annotations

import contextvars
import math
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np

from ..errors import SceneError
from ..inputs import read_two_columns
from .barrel import BARREL
from .connector import Load
from .declaration import Metric, Outputs
from .ops import LinearPieces, NumpyPiecewiseLinear, Ops, SymbolicVariables, piecewise_linear
from .table import Rule, Table, check_derived, check_number

#: The directory that relative file names in a scene (``firing.pulse.file``) resolve against: the
#: scene file's directory while :func:`mbs_models.load_scene` reads it, else the working directory.
SCENE_DIRECTORY: contextvars.ContextVar[Path | None] = contextvars.ContextVar("scene_directory", default=None)


#: Points a pulse's table may have at most: the solve restarts at every point (each a linear piece of the force,
#: ~0.2 ms a restart), so 20 000 points cost some 5 s per shot.  A pressure curve sampled at 1 MHz over a 12 ms
#: pulse has 12 000; the shipped example 4, the tests up to 401.
MAX_PULSE_POINTS = 20_000


def _too_many_points(key: str, what: str) -> SceneError:
    return SceneError(key, f"{what} more than {MAX_PULSE_POINTS} points (the solve restarts at every point): "
                           "resample the curve (a breech force needs a few hundred)")


def _number_list(key: str, values, rule: Rule) -> tuple[float, ...]:
    if isinstance(values, (str, bytes)) or not isinstance(values, (list, tuple)):
        raise SceneError(key, f"must be a list of numbers, got {type(values).__name__}")
    if len(values) > MAX_PULSE_POINTS:
        raise _too_many_points(key, f"has {len(values)} points,")
    return tuple(check_number(f"{key}.{i}", v, rule) for i, v in enumerate(values))


def read_pulse_file(path: Path, key: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(times s, forces N) from a CSV file of two columns ``time,force`` after one header line: a regular UTF-8
    text file of at most :data:`~mbs_models.inputs.MAX_INPUT_BYTES` (:func:`~mbs_models.inputs.read_text_file`:
    no device such as ``/dev/zero``, directory or pipe) with at most :data:`MAX_PULSE_POINTS` points."""
    pairs = read_two_columns(path, key, "pulse file", "time,force", MAX_PULSE_POINTS,
                             lambda: _too_many_points(key, f"{path} has"))
    return tuple(t for t, _ in pairs), tuple(f for _, f in pairs)


def _impulse(t, f) -> float:
    """``integral F dt`` (N s) of the piecewise-linear force through ``(t, f)``: the trapezoidal sum (halves taken
    first: a sum of two forces near the largest double does not overflow)."""
    return sum((0.5 * f[i] + 0.5 * f[i + 1]) * (t[i + 1] - t[i]) for i in range(len(t) - 1))


@dataclass(frozen=True)
class Pulse(Table):
    """The breech force on the barrel, piecewise linear in time, 0 outside the table (version 2).

    Attributes
    ----------
    times: s, strictly increasing, >= 0 (at least two).
    forces: N, >= 0, one per time.
    file: a CSV file (``time,force`` columns after a header line) instead of ``times``/``forces``;
        relative to the scene file.
    scale_to_momentum: scale the forces so that the impulse equals the firing momentum.
    """

    times: tuple | None = None
    forces: tuple | None = None
    file: str | None = None
    scale_to_momentum: bool = False
    TABLE: ClassVar[str] = "pulse"
    KEY_UNITS: ClassVar = {"times": "[s, ...]", "forces": "[N, ...]", "file": "text (a path)",
                           "scale_to_momentum": "true/false"}
    SINCE_VERSION: ClassVar[int] = 2

    def __post_init__(self):
        key = self.TABLE
        if not isinstance(self.scale_to_momentum, bool):
            raise SceneError(f"{key}.scale_to_momentum", "must be true or false")
        if self.file is not None:
            if not isinstance(self.file, str) or not self.file:
                raise SceneError(f"{key}.file", "must be a file name (a string)")
            if self.times is not None or self.forces is not None:
                raise SceneError(f"{key}.file", "give either file or times and forces, not both")
            path = Path(self.file)
            if not path.is_absolute():
                path = (SCENE_DIRECTORY.get() or Path.cwd()) / path
            times, forces = read_pulse_file(path, f"{key}.file")
        else:
            if self.times is None or self.forces is None:
                missing = "times" if self.times is None else "forces"
                raise SceneError(f"{key}.{missing}", "missing required key (or give file)")
            times, forces = self.times, self.forces
        times = _number_list(f"{key}.times", times, Rule(0.0, unit="s"))
        forces = _number_list(f"{key}.forces", forces, Rule(0.0, unit="N"))
        if len(times) < 2:
            raise SceneError(f"{key}.times", f"needs at least two points, got {len(times)}")
        if len(forces) != len(times):
            raise SceneError(f"{key}.forces", f"needs one force per time: {len(times)} times, {len(forces)} forces")
        for i in range(1, len(times)):
            if times[i] <= times[i - 1]:
                raise SceneError(f"{key}.times.{i}", f"must increase: {times[i]:g} s after {times[i - 1]:g} s")
        if not any(f > 0 for f in forces):
            raise SceneError(f"{key}.forces", "are all 0: the pulse does nothing")
        where = f"{key}.file" if self.file is not None else f"{key}.forces"
        check_derived({where: max(forces), f"{key}.times": times[-1] - times[0]},
                      "the pulse's impulse integral F dt", _impulse(times, forces), "N s", positive=True)
        if self.file is None:
            object.__setattr__(self, "times", times)
            object.__setattr__(self, "forces", forces)
        object.__setattr__(self, "_table", (times, forces))

    @property
    def table(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """(times s, forces N) as given (read from the file if one is named), before any scaling."""
        return self._table

    @property
    def impulse(self) -> float:
        """``integral F dt`` (N s) of the table as given (trapezoidal: exact for a piecewise-linear force)."""
        return _impulse(*self.table)

    @property
    def duration(self) -> float:
        """Last time minus first time of the table (s)."""
        t = self.table[0]
        return t[-1] - t[0]

    def to_mapping(self):
        out = {"file": self.file} if self.file is not None else {"times": list(self.times), "forces": list(self.forces)}
        if self.scale_to_momentum:
            out["scale_to_momentum"] = True
        return out


@dataclass(frozen=True)
class Firing(Table):
    """The shot: the projectile (and its charge) whose momentum drives the recoil, or a breech-force pulse.

    Attributes
    ----------
    projectile_mass: kg (> 0), 6.86 kg in the paper; required unless a pulse is given.
    muzzle_velocity: m/s (> 0), 564 m/s in the paper; required unless a pulse is given.
    charge_mass: kg of propellant (>= 0, default 0): the gas after-effect adds ``charge_mass * gas_velocity``.
    gas_velocity: m/s (> 0) of the powder gas leaving the muzzle; required when ``charge_mass > 0``.
    pulse: a :class:`Pulse` (version 2): the breech force instead of an initial velocity.
    """

    projectile_mass: float | None = None
    muzzle_velocity: float | None = None
    charge_mass: float = 0.0
    gas_velocity: float | None = None
    pulse: Pulse | None = None
    TABLE: ClassVar[str] = "firing"
    ORDER: ClassVar[int] = 5
    RULES: ClassVar = {"projectile_mass": Rule(0.0, strict=True, unit="kg"),
                       "muzzle_velocity": Rule(0.0, strict=True, unit="m/s"),
                       "charge_mass": Rule(0.0, unit="kg"),
                       "gas_velocity": Rule(0.0, strict=True, unit="m/s")}
    NESTED: ClassVar = {"pulse": Pulse}

    def __post_init__(self):
        super().__post_init__()
        needs_projectile = self.pulse is None or self.pulse.scale_to_momentum
        for name in ("projectile_mass", "muzzle_velocity"):
            if needs_projectile and getattr(self, name) is None:
                why = "" if self.pulse is None else " (firing.pulse.scale_to_momentum needs the momentum)"
                raise SceneError(f"{self.TABLE}.{name}", f"missing required key{why}")
        if (self.projectile_mass is None) != (self.muzzle_velocity is None):
            missing = "projectile_mass" if self.projectile_mass is None else "muzzle_velocity"
            raise SceneError(f"{self.TABLE}.{missing}", "missing: give both projectile_mass and muzzle_velocity")
        if self.charge_mass > 0 and self.gas_velocity is None:
            raise SceneError(f"{self.TABLE}.gas_velocity", "missing: a charge_mass > 0 needs the gas velocity (m/s)")
        if self.charge_mass > 0 and self.projectile_mass is None:
            raise SceneError(f"{self.TABLE}.projectile_mass", "missing: the charge's momentum adds to the projectile's")
        if self.projectile_mass is not None:
            check_derived(self._momentum_keys(), "the firing momentum I = projectile_mass muzzle_velocity + "
                                                 "charge_mass gas_velocity", self.momentum, "kg m/s", positive=True)
        if self.pulse is not None and self.pulse.scale_to_momentum:
            keys = {**self._momentum_keys(), **self._pulse_keys()}
            scale = check_derived(keys, "the scale of the pulse to the momentum, I / integral F dt",
                                  self.momentum / self.pulse.impulse, positive=True)
            check_derived(keys, "the peak of the pulse scaled to the momentum", scale * max(self.pulse.table[1]), "N")

    def _momentum_keys(self) -> dict[str, float]:
        """The keys the momentum depends on, with their values (for errors)."""
        keys = {f"{self.TABLE}.projectile_mass": self.projectile_mass, f"{self.TABLE}.muzzle_velocity": self.muzzle_velocity}
        if self.charge_mass > 0:
            keys.update({f"{self.TABLE}.charge_mass": self.charge_mass, f"{self.TABLE}.gas_velocity": self.gas_velocity})
        return keys

    def shot_keys(self) -> dict[str, float]:
        """The keys :attr:`shot_momentum` depends on, with their values (for errors naming them): the
        projectile's, or the pulse's largest force (``firing.pulse.forces`` or ``firing.pulse.file``)."""
        if self.pulse is None or self.pulse.scale_to_momentum:
            return self._momentum_keys()
        return self._pulse_keys()

    def _pulse_keys(self) -> dict[str, float]:
        """The pulse's forces (``firing.pulse.forces``, or ``firing.pulse.file``) with their largest (for errors)."""
        return {f"{self.TABLE}.pulse.{'file' if self.pulse.file is not None else 'forces'}": max(self.pulse.table[1])}

    @classmethod
    def required_keys(cls) -> tuple[str, ...]:
        return ()  # checked in __post_init__: the projectile is required unless a pulse is given

    @property
    def momentum(self) -> float:
        """Free-recoil momentum in kg m/s: ``projectile_mass * muzzle_velocity + charge_mass * gas_velocity``."""
        if self.projectile_mass is None:
            return self.pulse.impulse
        momentum = self.projectile_mass * self.muzzle_velocity
        if self.charge_mass > 0:
            momentum += self.charge_mass * self.gas_velocity
        return momentum

    @property
    def shot_momentum(self) -> float:
        """The momentum (kg m/s) one shot gives the barrel: :attr:`momentum` for an impulse; the pulse's
        impulse (scaled to the momentum if asked) with a pulse."""
        if self.pulse is None or self.pulse.scale_to_momentum:
            return self.momentum
        return self.pulse.impulse

    def initial_velocity(self, moving_mass: float) -> float:
        """v0 (m/s) of a recoiling mass ``moving_mass`` (kg): momentum / mass; 0 with a pulse (at rest)."""
        if self.pulse is not None:
            return 0.0
        return self.momentum / moving_mass

    def pulse_points(self, shot_times=(0.0,)) -> list[tuple[float, float]]:
        """The breech force of every shot as ``(t s, F N)`` points (jumps as repeated times), scaled to the
        momentum if asked: the table shifted by each shot time."""
        times, forces = self.pulse.table
        scale = self.momentum / self.pulse.impulse if self.pulse.scale_to_momentum else 1.0
        points: list[tuple[float, float]] = []
        for shot in shot_times:
            if forces[0] != 0.0:
                points.append((shot + times[0], 0.0))
            points += [(shot + t, scale * f) for t, f in zip(times, forces)]
            if forces[-1] != 0.0:
                points.append((shot + times[-1], 0.0))
        return points

    def bodies(self, scene, name: str) -> list:
        return []

    def connectors(self, scene, name: str) -> list:
        return []

    def loads(self, scene, name: str) -> list[Load]:
        """The breech force on the barrel (every shot of a burst) if a pulse is given; else none."""
        if self.pulse is None:
            return []
        burst = getattr(scene, "burst", None)
        shots = burst.shot_times if burst is not None else (0.0,)
        return [BreechForce(name, self.pulse_points(shots), [(s + self.pulse.table[0][0], s + self.pulse.table[0][-1])
                                                             for s in shots])]


class BreechForce(SymbolicVariables, Load):
    """The breech force ``F(t)`` on the barrel (N): piecewise linear through ``points``, 0 outside.

    The solve is split at every point (:attr:`breakpoints`), and in each segment the solver evaluates the
    linear piece the segment lies in, ``F = F_i + s_i (t - t_i)`` (:meth:`user_function_law`,
    :meth:`start_segment`): the same force inside the piece, and at the segment's end (a table point, where
    the solver's last stage of the last step is evaluated) the piece's end value, not the next piece's.
    """

    needs_user_function = True
    SYMBOLIC = ("_variables",)

    def __init__(self, element: str, points: list[tuple[float, float]], windows: list[tuple[float, float]]):
        super().__init__("breech_force", element, BARREL)
        self.points = list(points)
        self._windows = tuple(windows)
        self._numpy_law = NumpyPiecewiseLinear(self.points)
        self._pieces = LinearPieces(self.points)
        self._piece = list(self._pieces.at(0.0))  # (t_i s, F_i N, s_i N/s) of the segment being solved
        self._variables = None                     # the same numbers as symbolic variables, if recorded

    def law(self, t, ops: Ops):
        return piecewise_linear(t, self.points, ops)

    def user_function_law(self, ops: Ops):
        """``t -> F_i + s_i (t - t_i)`` (N): the piece of the segment being solved, set by :meth:`start_segment`.

        Evaluated at the end of a segment that ends where F jumps (a pulse's start or end at a non-zero
        force), :meth:`law` would give the value after the jump: the last stage of an explicit solver's last
        step is evaluated there, and its error estimate (which uses that stage) would see the jump and shrink
        the step until the solve stops short of the segment's end."""
        if ops.name == "symbolic":
            import exudyn
            start, value, slope = self._variables = [
                exudyn.symbolic.Real(f"{self.name}_{name}_{id(self)}", number)
                for name, number in zip(("start", "value", "slope"), self._piece)]
            return lambda t: value + slope * (t - start)
        piece = self._piece
        return lambda t: piece[1] + piece[2] * (t - piece[0])

    def start_segment(self, t: float) -> None:
        """Fix the piece of the segment that starts at ``t`` (s): the one :meth:`law` uses at ``t`` (after a jump
        there)."""
        self._piece[:] = self._pieces.at(t)
        if self._variables is not None:
            for variable, number in zip(self._variables, self._piece):
                variable.SetValue(number)

    def force(self, t):
        """The force (N) at times ``t`` (s): :meth:`law` over numpy, the table converted once (it is
        evaluated at the start of every segment of a run, one per table point)."""
        return self._numpy_law(np.asarray(t, dtype=float))

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Every point of every shot's table (s): the force may jump at a pulse's start and end, and its slope
        changes at the inner points (F is only continuous there).  The solve is split at each, so that every
        segment integrates one linear piece of F: an adaptive solver's error estimate assumes a smooth
        right-hand side and misses a kink inside a step."""
        return tuple(sorted({t for t, _ in self.points}))

    @property
    def windows(self) -> tuple[tuple[float, float], ...]:
        return self._windows

    @property
    def last_input_time(self) -> float:
        return self._windows[-1][1]


from ..results.battery import BATTERY_TOLERANCE  # noqa: E402  (1 mm: "in battery", as a single shot's return)


def shot_outputs(run) -> list[dict]:
    """Per shot of the burst, in the window simulated (``run``: an
    :class:`~mbs_models.elements.declaration.ElementRun`).

    Each entry: ``shot`` (1, 2, ...), ``time`` (s) it fires; ``max_barrel_displacement`` (m) and its
    time, refined, between this shot and the next (or the end); ``position_at_next_shot`` (m) and
    ``velocity_at_next_shot`` (m/s): the barrel's state just before the next shot fires, and
    ``in_battery_at_next_shot`` (within :data:`BATTERY_TOLERANCE` of its position before the first
    shot), None for the last shot; ``time_to_battery`` (s after the shot): the first return within
    :data:`BATTERY_TOLERANCE` of battery after the shot's maximum displacement (None if it does not
    return before the next shot or the end).
    """
    from ..results.peaks import refine_crossing, refine_maximum

    s, interp = run.samples, run.interpolant
    t, x, v = s.time, s.positions[BARREL], s.velocities[BARREL]
    battery = float(x[0])
    shots = run.table.shot_times
    out = []
    for k, t_shot in enumerate(shots):
        if t_shot > t[-1]:
            break
        lo = int(np.searchsorted(t, t_shot, side="right")) - 1  # the sample after the shot's jump
        following = shots[k + 1] if k + 1 < len(shots) and shots[k + 1] <= t[-1] else None
        hi = int(np.searchsorted(t, following, side="left")) if following is not None else len(t) - 1
        window = slice(lo, hi + 1)
        x_max, t_max = refine_maximum(t[window], x[window], v[window])
        entry = {"shot": k + 1, "time": float(t_shot), "max_barrel_displacement": float(x_max),
                 "time_of_max_barrel_displacement": float(t_max),
                 "position_at_next_shot": None if following is None else float(x[hi]),
                 "velocity_at_next_shot": None if following is None else float(v[hi]),
                 "in_battery_at_next_shot": None if following is None else bool(abs(x[hi] - battery) <= BATTERY_TOLERANCE),
                 "time_to_battery": None}
        back = np.flatnonzero((t[window] > t_max) & (np.abs(x[window] - battery) <= BATTERY_TOLERANCE))
        if len(back):
            j = lo + int(back[0])
            crossing = refine_crossing(lambda times: np.abs(interp.x[BARREL](times) - battery) <= BATTERY_TOLERANCE,
                                       max(t[j - 1], t_max), t[j])
            entry["time_to_battery"] = float(crossing - t_shot)
        out.append(entry)
    return out


def shot_lines(shots: list[dict]) -> list[str]:
    """One line of ``recoil run``'s summary per shot: its time, maximum displacement (m), when it is back in
    battery and whether it is at the next shot."""
    lines = []
    for shot in shots:
        back = "never back in battery" if shot["time_to_battery"] is None else \
            f"in battery {shot['time_to_battery']:.3f} s after it"
        state = "" if shot["in_battery_at_next_shot"] is None else \
            (", in battery at the next shot" if shot["in_battery_at_next_shot"] else
             f", OUT of battery at the next shot (x = {shot['position_at_next_shot'] * 1e3:.1f} mm)")
        lines.append(f"  shot {shot['shot']:<3d} at {shot['time']:7.3f} s  max {shot['max_barrel_displacement']:.6f} m, "
                     f"{back}{state}")
    return lines



@dataclass(frozen=True)
class Burst(Table):
    """``shots`` shots (integer >= 1) fired every ``interval`` s (> 0): shot k at ``t_k = k * interval``.

    Attributes
    ----------
    shots: the number of shots in the burst, an integer >= 1; each is the ``[firing]`` shot.
    interval: the time between two shots in s (> 0): shot k fires at ``t_k = k * interval`` (k from 0).
    """

    shots: int
    interval: float
    TABLE: ClassVar[str] = "burst"
    ORDER: ClassVar[int] = 6
    SINCE_VERSION: ClassVar[int] = 2
    RULES: ClassVar = {"interval": Rule(0.0, strict=True, unit="s")}
    KEY_UNITS: ClassVar = {"shots": "1"}
    #: ``shots`` (:func:`shot_outputs`): at the top level of ``recoil run --json`` (its key before the
    #: declarations), no sweep column (a list), a line per shot in the summary, for any window simulated.
    OUTPUTS: ClassVar = Outputs(metrics=(Metric("shots", "-", shot_outputs, json_key="shots", column=False,
                                                summary=shot_lines, window=True),))

    def __post_init__(self):
        if isinstance(self.shots, bool) or not isinstance(self.shots, int) and not (
                isinstance(self.shots, float) and self.shots.is_integer()):
            raise SceneError(f"{self.TABLE}.shots", f"must be a whole number >= 1, got {self.shots!r}")
        object.__setattr__(self, "shots", int(self.shots))
        if not 1 <= self.shots <= 1000:
            raise SceneError(f"{self.TABLE}.shots", f"must be in [1, 1000], got {self.shots}")
        super().__post_init__()
        check_derived({f"{self.TABLE}.interval": self.interval, f"{self.TABLE}.shots": self.shots},
                      "the end of the last shot's interval, shots x interval", self.shots * self.interval, "s")

    @property
    def shot_times(self) -> tuple[float, ...]:
        """Firing times (s): ``k * interval`` for k = 0 .. shots - 1."""
        return tuple(k * self.interval for k in range(self.shots))

    def check_in_scene(self, scene, key: str) -> None:
        firing = scene.firing
        if firing is not None and firing.pulse is not None and firing.pulse.table[0][-1] >= self.interval:
            where = "firing.pulse.file" if firing.pulse.file is not None else "firing.pulse.times"
            raise SceneError(f"{key}.interval", f"must exceed the pulse's end ({where} ends at "
                                                f"{firing.pulse.table[0][-1]:g} s): got {self.interval:g} s")

    def bodies(self, scene, name: str) -> list:
        return []

    def connectors(self, scene, name: str) -> list:
        return []

    def impulses(self, scene, name: str) -> list[tuple[float, str, float]]:
        """``(time s, body, velocity jump m/s)`` of every later shot of an impulse-model burst: the barrel
        gains ``v0`` (:attr:`~mbs_models.scene.Scene.initial_velocity`) at ``t_k``, k >= 1.  None with a pulse
        (the pulse repeats instead, :meth:`Firing.loads`)."""
        firing = scene.firing
        if firing is not None and firing.pulse is not None:
            return []
        return [(t, BARREL, scene.initial_velocity) for t in self.shot_times[1:]]

