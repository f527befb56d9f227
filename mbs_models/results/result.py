"""What a simulation returns: :class:`Result` (time histories + metrics), :class:`Impact`, :class:`ContactOutput`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..elements.barrel import BARREL
from ..elements.declaration import ABSORBER, END_STOP, elements_with
from ..stop_reason import StopReason
from . import element_outputs

#: Every metric a run can report (and prove final with ``stop_when_final``).
ALL_METRICS = ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "impacts",
               "peak_support_force")


@dataclass(frozen=True)
class Impact:
    """One contact episode that is an impact: its peak force rises above the force the contact held at rest
    when it began (0, or an initial interference's static force) by more than the impact threshold.

    Attributes: ``start`` and ``end`` (s) bound the interval where the contact force is > 0;
    ``peak_force`` (N) is its maximum, reached at ``time_of_peak_force`` (s); ``contact`` names the
    contact (``"contact"`` for the one absorber's, ``"front_contact"``, an end stop's name).
    """

    start: float
    end: float
    peak_force: float
    time_of_peak_force: float
    contact: str = "contact"

    @property
    def duration(self) -> float:
        """Contact duration in s."""
        return self.end - self.start

    def to_dict(self) -> dict[str, Any]:
        return {"start": self.start, "end": self.end, "peak_force": self.peak_force,
                "time_of_peak_force": self.time_of_peak_force, "contact": self.contact}


@dataclass(frozen=True)
class ContactOutput:
    """One contact of a run: its force history (N, at the output times), refined peak and impacts.

    ``element`` is the element it belongs to (the absorber's name, a stop's...); ``episodes`` the
    number of contact episodes (force > 0), ``impacts`` those that are impacts (:class:`Impact`); ``onsets``: for laws
    that use it, ``(time s, v- m/s)`` at the onset of each episode as captured in the solve.
    ``peak_force``/``impacts`` are None when an early-stopped run did not prove them final.
    """

    name: str
    element: str
    force: np.ndarray = field(repr=False)
    peak_force: float | None
    time_of_peak_force: float | None
    impacts: list[Impact] | None
    episodes: int = 0
    onsets: list[tuple[float, float]] | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "element": self.element, "peak_contact_force": self.peak_force,
                "time_of_peak_contact_force": self.time_of_peak_force,
                "impacts": None if self.impacts is None else [i.to_dict() for i in self.impacts]}


@dataclass(frozen=True)
class Result:
    """Time histories (numpy arrays at the solver's output steps, SI units) and metrics of one run.

    Histories: ``time`` (s); ``positions``, ``velocities``, ``accelerations`` per body name (m, m/s,
    m/s^2; ``"barrel"`` and the absorbers); ``contacts`` per contact name (:class:`ContactOutput`, force
    history and metrics); ``support_force`` (N): the force on the mount, positive in the recoil direction.
    Version-1 shortcuts: ``barrel_position`` ... ``barrel_acceleration``; ``absorber_position`` ...,
    ``contact_force`` for a scene with one absorber (None without -- never zeros -- and with several:
    use the dictionaries).

    Metrics (refined between output samples, see :mod:`mbs_models.results.peaks`):
    ``max_barrel_displacement`` (m, Table 2) and its time; ``peak_support_force`` (largest ``|S|``, N) and its
    time; ``peak_contact_force`` (N) and ``max_absorber_velocity`` (m/s), the largest over all absorbers,
    with their times; ``impacts`` (all absorbers' impacts in time order); ``dissipated_energy`` (J per
    dissipating connector at the end time); :meth:`absorbers`, :meth:`stops`, :meth:`energy` per element.

    Declared outputs (:mod:`mbs_models.elements.declaration`): ``element_histories`` and ``element_metrics``,
    ``{element: {name: value}}``, the histories and metrics elements declare (a burst's ``shots``); a declared
    metric is also an attribute by its name when one element of the run declares it (``result.shots``).

    Window: the histories cover ``[0, end_time]`` s.  ``requested_end_time`` is what was asked for;
    ``end_time`` is smaller only when ``simulate(..., stop_when_final=...)`` stopped the solve because
    the named metrics were proven final (``stop_reason == "metrics_final"``, see
    :mod:`mbs_models.engine.final_metrics`).  ``final_metrics`` names the metrics whose values are those
    of a run to ``requested_end_time``; every other metric (with its time) is None -- ``impacts`` too.

    At rest (``stop_reason == "at_rest"``, :mod:`mbs_models.engine.rest`): the solve stopped at ``rest_time`` (s),
    from which on energy bounds prove every position within ``rest_tolerance`` (m) of the rest state and every
    velocity within it (m/s); the histories are integrated up to ``rest_time`` and hold the rest state from
    there (a sample at ``rest_time`` and one at ``end_time``, the requested end time; velocities, accelerations
    0).  ``rest_time`` and ``rest_tolerance`` are None otherwise.

    ``stop_reason`` (:class:`~mbs_models.stop_reason.StopReason`, a string: ``"end_time"``, ``"metrics_final"``...)
    says why the run ended, ``stop_reason.message`` in words.  A Result is immutable: it is built once, from
    everything the run collected (:mod:`mbs_models.engine.result_builder`); assigning to an attribute raises
    ``dataclasses.FrozenInstanceError``.

    Step ends and dense histories: the histories are the solver's step-end samples (``samples``, a
    :class:`~mbs_models.results.samples.Samples`; ``mechanism``: the solve's bodies and connectors, whose laws
    give the forces between them).  :meth:`densified` gives the same run with its histories on a fine grid (the
    plots' and ``--csv``'s, :mod:`mbs_models.results.dense`); its ``step_ends`` is the Result of the step-end
    samples (None on a Result of step-end samples), and every metric is that Result's.
    """

    scene: Any
    settings: Any
    end_time: float
    time: np.ndarray
    positions: dict[str, np.ndarray] = field(repr=False)
    velocities: dict[str, np.ndarray] = field(repr=False)
    accelerations: dict[str, np.ndarray] = field(repr=False)
    contacts: dict[str, ContactOutput] = field(repr=False)
    support_force: np.ndarray = field(repr=False)
    max_barrel_displacement: float | None
    time_of_max_barrel_displacement: float | None
    peak_contact_force: float | None
    time_of_peak_contact_force: float | None
    max_absorber_velocity: float | None
    time_of_max_absorber_velocity: float | None
    impacts: list[Impact] | None
    impact_threshold: float
    dissipated_energy: dict[str, float]
    peak_support_force: float | None = None
    time_of_peak_support_force: float | None = None
    max_velocities: dict[str, tuple[float | None, float | None]] = field(default_factory=dict)
    dissipated_energy_history: dict[str, np.ndarray] = field(repr=False, default_factory=dict)
    stored_energy_histories: dict[str, np.ndarray] = field(repr=False, default_factory=dict)
    kinetic_energy_histories: dict[str, np.ndarray] = field(repr=False, default_factory=dict)
    element_of: dict[str, str] = field(repr=False, default_factory=dict)
    work_histories: dict[str, np.ndarray] = field(repr=False, default_factory=dict)
    element_histories: dict[str, dict[str, np.ndarray]] = field(repr=False, default_factory=dict)
    element_metrics: dict[str, dict[str, Any]] = field(default_factory=dict)
    wall_time: float = 0.0
    timings: dict[str, float] = field(default_factory=dict)
    steps: int = 0
    requested_end_time: float | None = None
    stop_reason: StopReason = StopReason.END_TIME
    final_metrics: tuple[str, ...] = ALL_METRICS
    rest_time: float | None = None
    rest_tolerance: float | None = None
    carriage: Any = field(repr=False, default=None)
    samples: Any = field(repr=False, default=None, compare=False)
    mechanism: Any = field(repr=False, default=None, compare=False)
    step_ends: "Result | None" = field(repr=False, default=None, compare=False)

    def __getattr__(self, name: str):
        """A carriage metric (``result.stability_margin``, ... :data:`~mbs_models.results.carriage.CARRIAGE_METRICS`;
        None without a carriage), or a metric an element declares, by its name (``result.shots`` of a burst): the run's one element that
        declares it (None if none of the run's does but a registered element could; see
        :func:`~mbs_models.results.element_outputs.lookup`)."""
        if name.startswith("_") or "element_metrics" not in self.__dict__:  # (copy, pickle: before the fields)
            raise AttributeError(name)
        from .carriage import CARRIAGE_METRICS  # (imported here, not with the module: a run never needs it)

        if name in CARRIAGE_METRICS:  # a carriage scene's metric (None without a carriage)
            carriage = self.__dict__.get("carriage")
            return None if carriage is None else getattr(carriage, name)
        from .element_outputs import lookup

        return lookup(self, name)

    def __post_init__(self):
        # (while it is built: frozen from then on)
        if self.requested_end_time is None:
            object.__setattr__(self, "requested_end_time", self.end_time)
        object.__setattr__(self, "stop_reason", StopReason(self.stop_reason))  # its text (an old value) read back

    def state_at(self, t) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        """Every body's position (m) and velocity (m/s) at times ``t`` (s, any shape, within ``[0, end_time]``):
        ``(positions, velocities)`` by body name, each of ``t``'s shape.

        The cubic Hermite interpolant of the step-end samples (position from velocity, velocity from
        acceleration; :mod:`mbs_models.results.samples`), the one the metrics are refined on: histories at any
        sampling interval (``result.state_at(np.arange(0.0, result.end_time, 1e-3))``) without small steps; at a
        sample time, the sample itself.  Raises ``ValueError`` for a time outside the histories."""
        from .samples import Interpolant, Samples

        base = self.step_ends if self.step_ends is not None else self  # a densified Result: its step-end samples
        t = np.asarray(t, dtype=float)
        if t.size and not (np.min(t) >= base.time[0] and np.max(t) <= base.time[-1]):
            raise ValueError(f"state_at: times must lie in [{base.time[0]:g}, {base.time[-1]:g}] s (the histories), "
                             f"got [{np.min(t):g}, {np.max(t):g}] s")
        return Interpolant(Samples(base.time, base.positions, base.velocities, base.accelerations)).state(t)

    def densified(self, interval: float | None = None) -> "Result":
        """The same run with every history on a fine time grid: the step-end samples and, in each step longer
        than ``interval`` (s, 1e-5 to 1; None: 1 ms, finer for a window under 2 s, coarser beyond 1000 s,
        :func:`~mbs_models.results.dense.default_interval`), equally spaced times no more than ``interval`` apart,
        where positions and velocities are the cubic Hermite interpolant of :meth:`state_at`, accelerations its
        velocity's derivative, and forces and energies the same laws as at the samples
        (:func:`mbs_models.results.dense.densify`).  Every metric is this Result's; the plots and ``recoil run
        --csv`` use it.  SceneError naming ``interval`` outside its range."""
        from .dense import densify

        return densify(self, interval)

    # ------------------------------------------------------------------ version-1 shortcuts
    @property
    def barrel_position(self) -> np.ndarray:
        """x_M (m)."""
        return self.positions[BARREL]

    @property
    def barrel_velocity(self) -> np.ndarray:
        return self.velocities[BARREL]

    @property
    def barrel_acceleration(self) -> np.ndarray:
        return self.accelerations[BARREL]

    def _single_absorber(self) -> str | None:
        names = self.absorber_names
        return names[0] if len(names) == 1 else None

    @property
    def absorber_names(self) -> list[str]:
        """The absorbers' (bodies') names: the bodies of the elements whose role is an absorber
        (:data:`~mbs_models.elements.declaration.ABSORBER`)."""
        absorbers = set(elements_with(self.scene, ABSORBER))
        return [name for name in self.positions if self.element_of.get(name, name) in absorbers]

    @property
    def absorber_position(self) -> np.ndarray | None:
        """x_m (m) of the one absorber (None without, or with several)."""
        name = self._single_absorber()
        return None if name is None else self.positions[name]

    @property
    def absorber_velocity(self) -> np.ndarray | None:
        name = self._single_absorber()
        return None if name is None else self.velocities[name]

    @property
    def absorber_acceleration(self) -> np.ndarray | None:
        name = self._single_absorber()
        return None if name is None else self.accelerations[name]

    @property
    def contact_force(self) -> np.ndarray | None:
        """F (N, >= 0) of the one absorber's contact (None without, or with several)."""
        output = self.contacts.get("contact")
        return None if output is None else output.force

    @property
    def kinetic_energy_history(self) -> np.ndarray:
        """Kinetic energy of all bodies (J) at the output times."""
        return total_history(self.kinetic_energy_histories.values(), self.time)

    @property
    def stored_energy_history(self) -> np.ndarray:
        """Energy stored in all springs and contacts (J) at the output times."""
        return total_history(self.stored_energy_histories.values(), self.time)

    # ------------------------------------------------------------------ energy
    @property
    def total_dissipated_energy(self) -> float:
        """Energy dissipated by all dampers and contacts up to the end time, in J."""
        return float(sum(self.dissipated_energy.values()))

    def energy_error(self) -> np.ndarray:
        """Energy balance residual over time, in J: kinetic + stored + dissipated - work - initial energy.

        The initial energy is the kinetic energy at t = 0 plus the stored energy of an initial
        interference.  Zero for an exact solution; its size measures the integration (and quadrature) error.
        """
        dissipated = sum(self.dissipated_energy_history.values())
        initial = self.kinetic_energy_history[0] + self.stored_energy_history[0]
        error = self.kinetic_energy_history + self.stored_energy_history + dissipated - initial
        if self.work_histories:
            error = error - self.work_history
        return error

    @property
    def work_history(self) -> np.ndarray:
        """Work (J) done on the mechanism by every external input (breech force, shots, gravity) since t = 0."""
        return total_history(self.work_histories.values(), self.time)

    def energy(self) -> dict[str, dict[str, float]]:
        """Per element at the end time, J: ``{element: {"kinetic": ..., "stored": ..., "dissipated": ...}}``.

        Elements with an external input (the firing's breech force or shots, gravity) also have ``"work"``,
        the work done on the mechanism.  Kinetic + stored + dissipated - work, summed over the elements,
        is the initial energy (up to :meth:`energy_error`).
        """
        out: dict[str, dict[str, float]] = {}
        for kind, histories in (("kinetic", self.kinetic_energy_histories), ("stored", self.stored_energy_histories),
                                ("dissipated", self.dissipated_energy_history)):
            for name, history in histories.items():
                element = self.element_of.get(name, name)
                entry = out.setdefault(element, {"kinetic": 0.0, "stored": 0.0, "dissipated": 0.0})
                entry[kind] += float(history[-1])
        for name, history in self.work_histories.items():
            element = self.element_of.get(name, name)
            entry = out.setdefault(element, {"kinetic": 0.0, "stored": 0.0, "dissipated": 0.0})
            entry["work"] = entry.get("work", 0.0) + float(history[-1])
        return out

    # ------------------------------------------------------------------ per element
    def absorbers(self) -> list[dict[str, Any]]:
        """Per absorber: ``name``, ``peak_contact_force`` (N) and time, ``max_absorber_velocity`` (m/s) and
        time, ``impacts`` (its contact's)."""
        out = []
        for name in self.absorber_names:
            contact = next((c for c in self.contacts.values() if c.element == name), None)
            v_max, t_v = self.max_velocities.get(name, (None, None))
            out.append({"name": name,
                        "peak_contact_force": None if contact is None else contact.peak_force,
                        "time_of_peak_contact_force": None if contact is None else contact.time_of_peak_force,
                        "max_absorber_velocity": v_max, "time_of_max_absorber_velocity": t_v,
                        "impacts": None if contact is None or contact.impacts is None else
                        [i.to_dict() for i in contact.impacts]})
        return out

    def stops(self) -> list[dict[str, Any]]:
        """Per end stop (a contact of an element whose role is
        :data:`~mbs_models.elements.declaration.END_STOP`): ``name``, ``peak_contact_force`` (N) and time,
        ``impacts``, ``dissipated_energy`` (J)."""
        out = []
        stops = set(elements_with(self.scene, END_STOP))
        for contact in self.contacts.values():
            if contact.element not in stops:
                continue
            entry = contact.to_dict()
            entry["dissipated_energy"] = self.dissipated_energy.get(contact.name)
            out.append(entry)
        return out

    # ------------------------------------------------------------------ the window
    @property
    def max_at_end_of_window(self) -> bool | None:
        """True when the maximum barrel displacement is the last instant of the window with the barrel still
        moving out (v > 0): the largest value *seen*, not a turning point -- a longer run would find a
        larger maximum.  None when the maximum is not reported (an early stop that did not prove it)."""
        if self.max_barrel_displacement is None:
            return None
        return bool(self.time_of_max_barrel_displacement >= self.time[-1] and self.barrel_velocity[-1] > 0.0)

    @property
    def time_to_battery(self) -> float | None:
        """A single shot's return (s after the shot at t = 0): the first time ``t >= t_max`` at which the barrel is
        back within :data:`~mbs_models.results.battery.BATTERY_TOLERANCE` (1 mm) of its position at t = 0,

            ``x_M(t) <= x_M(0) + 1e-3 m``,  ``t_max`` = :attr:`time_of_max_barrel_displacement`,

        found on the output samples and refined on the cubic Hermite interpolant of ``(x_M, v_M)`` (as each shot's
        ``time_to_battery`` of a burst; ``t_max`` itself when the maximum is within 1 mm).  None with a burst
        (each shot's is in ``shots``), when the maximum is not reported (an early stop that did not prove it) or
        is the end of the window, or when the barrel is not back within the window."""
        from .battery import return_to_battery

        if getattr(self.scene, "burst", None) is not None or self.max_barrel_displacement is None \
                or self.max_at_end_of_window:
            return None
        base = self.step_ends if self.step_ends is not None else self  # found on the step-end samples
        return return_to_battery(base.time, base.barrel_position, base.barrel_velocity,
                                 self.time_of_max_barrel_displacement, self.max_barrel_displacement)

    def maxima_at_end_of_window(self) -> list[str]:
        """The peak metrics whose maximum is the window's last instant (still rising there, so not a turning
        point): ``max_barrel_displacement`` as :attr:`max_at_end_of_window` says, and ``peak_support_force``,
        ``peak_contact_force``, ``max_absorber_velocity`` when their time is the end of the window."""
        out = ["max_barrel_displacement"] if self.max_at_end_of_window else []
        end = self.time[-1]
        for name in ("peak_support_force", "peak_contact_force", "max_absorber_velocity"):
            moment = getattr(self, f"time_of_{name}")
            if getattr(self, name) is not None and moment is not None and moment >= end:
                out.append(name)
        return out

    # ------------------------------------------------------------------ reports
    def metrics(self) -> dict[str, Any]:
        """The scalar results as a JSON-ready dict (the keys of ``recoil run --json``)."""
        return {
            "scene": self.scene.name,
            "model": self.scene.model_label,
            "initial_velocity": self.scene.initial_velocity,
            "end_time": self.end_time,
            "requested_end_time": self.requested_end_time,
            "stop_reason": self.stop_reason,
            "final_metrics": list(self.final_metrics),
            "solver": self.settings.label(),
            "max_barrel_displacement": self.max_barrel_displacement,
            "time_of_max_barrel_displacement": self.time_of_max_barrel_displacement,
            "max_at_end_of_window": self.max_at_end_of_window,
            "maxima_at_end_of_window": self.maxima_at_end_of_window(),
            "time_to_battery": self.time_to_battery,
            "peak_support_force": self.peak_support_force,
            "time_of_peak_support_force": self.time_of_peak_support_force,
            "peak_contact_force": self.peak_contact_force,
            "time_of_peak_contact_force": self.time_of_peak_contact_force,
            "max_absorber_velocity": self.max_absorber_velocity,
            "time_of_max_absorber_velocity": self.time_of_max_absorber_velocity,
            "impact_threshold": self.impact_threshold,
            "impacts": None if self.impacts is None else [impact.to_dict() for impact in self.impacts],
            "absorbers": self.absorbers(),
            "stops": self.stops(),
            "dissipated_energy": dict(self.dissipated_energy),
            "energy": self.energy(),
            **self._firing_metrics(),
            **self._rest_metrics(),
            **self._carriage_metrics(),
            "steps": self.steps,
            "wall_time": self.wall_time,
        }

    def _firing_metrics(self) -> dict[str, Any]:
        """``pulse_impulse`` (N s, with a breech-force pulse), the declared metrics
        (:func:`~mbs_models.results.element_outputs.json_entries`: a burst's ``shots``), ``work`` (J, with external
        inputs): only for scenes that have them (version-1 keys stay as they were)."""
        out: dict[str, Any] = {}
        firing = getattr(self.scene, "firing", None)
        pulse = getattr(firing, "pulse", None)
        if pulse is not None:
            out["pulse_impulse"] = firing.shot_momentum
        out.update(element_outputs.json_entries(self))
        if self.work_histories:
            out["work"] = {name: float(history[-1]) for name, history in self.work_histories.items()}
        return out

    def _carriage_metrics(self) -> dict[str, Any]:
        """A carriage scene's metrics (:mod:`mbs_models.results.carriage`) and ``supports`` (a list of
        ``{name, static_normal_force, min_normal_force, max_normal_force}``, N); nothing without a carriage."""
        if self.carriage is None:
            return {}
        return {**self.carriage.metrics(), "supports": self.supports}

    @property
    def supports(self) -> list[dict[str, Any]] | None:
        """Per support of a carriage scene: name and static, smallest and largest normal force (N); None without."""
        if self.carriage is None:
            return None
        return [output.to_dict() for output in self.carriage.supports.values()]

    @property
    def carriage_position(self) -> np.ndarray | None:
        """The carriage's CG (x, y) in m at every sample, shape (n, 2); None without a carriage."""
        return None if self.carriage is None else self.carriage.position

    @property
    def carriage_pitch(self) -> np.ndarray | None:
        """The carriage's pitch (rad, nose up) at every sample; None without a carriage."""
        return None if self.carriage is None else self.carriage.pitch

    def _carriage_lines(self) -> list[str]:
        """The summary's lines of a carriage scene: the verdict, the stability margin, each support's loads."""
        carriage = self.carriage
        if carriage is None:
            return []
        verdict = ("stays on the ground" if carriage.lift_off_time is None else
                   f"a support leaves the ground at {carriage.lift_off_time:.5f} s (lift {carriage.max_lift * 1e3:.3f} mm)")
        lines = [f"  carriage                 {verdict}",
                 f"  stability margin         {carriage.stability_margin:.4f} (least support load / its static load)",
                 f"  carriage pitch, shift    {carriage.max_carriage_pitch * 1e3:.4f} mrad, "
                 f"{carriage.max_carriage_displacement * 1e3:.4f} mm"]
        for name, support in carriage.supports.items():
            lines.append(f"  {name:24s} {support.static_normal_force / 1e3:.3f} kN static, "
                         f"{support.min_normal_force / 1e3:.3f} to {support.max_normal_force / 1e3:.3f} kN")
        return lines

    def _rest_metrics(self) -> dict[str, Any]:
        """``rest_time`` (s) and ``rest_tolerance`` (m and m/s) of a run stopped at rest (only then)."""
        if self.rest_time is None:
            return {}
        return {"rest_time": self.rest_time, "rest_tolerance": self.rest_tolerance}

    def rest_note(self) -> str | None:
        """One line saying when the run came to rest and what was proven (None if it did not stop at rest)."""
        if self.rest_time is None:
            return None
        return (f"at rest from t = {self.rest_time:.6g} s (proven: every position within {self.rest_tolerance:g} m "
                f"of its rest position and every velocity within {self.rest_tolerance:g} m/s from then on); the "
                f"remaining {self.end_time - self.rest_time:.6g} s hold the rest state, not integrated")

    def summary(self) -> str:
        """A few human-readable lines."""
        window = f"{self.end_time:g} s"
        if self.rest_time is not None:
            window += f" (at rest from {self.rest_time:.6g} s)"
        elif self.stop_reason != StopReason.END_TIME:
            window += f" of {self.requested_end_time:g} s requested: {self.stop_reason.message}"
        name, label = self.scene.name, self.scene.model_label
        header = name if label.lower() in name.lower() else f"{name} ({label})"  # the model named once
        lines = [f"{header}, {window}, {self.settings.label()}"]
        not_final = "not proven final (run stopped early)"
        at_end = self.maxima_at_end_of_window()

        def end_note(name: str) -> str:
            return " (the end of the window: still rising, not a turning point)" if name in at_end else ""

        if self.max_barrel_displacement is not None:
            lines.append(f"  max barrel displacement  {self.max_barrel_displacement:.6f} m at "
                         f"{self.time_of_max_barrel_displacement:.5f} s{end_note('max_barrel_displacement')}")
        else:
            lines.append(f"  max barrel displacement  {not_final}")
        if getattr(self.scene, "burst", None) is None:   # a burst: per shot, below
            back = self.time_to_battery
            lines.append("  back in battery          " + (f"{back:.5f} s (within 1 mm)" if back is not None else
                                                         "not within the window" if self.max_barrel_displacement
                                                         is not None else not_final))
        if self.peak_support_force is not None:
            lines.append(f"  peak support force       {self.peak_support_force / 1e3:.3f} kN at "
                         f"{self.time_of_peak_support_force:.5f} s{end_note('peak_support_force')}")
        else:
            lines.append(f"  peak support force       {not_final}")
        if elements_with(self.scene, ABSORBER):
            if self.peak_contact_force is None:
                lines.append(f"  peak contact force       {not_final}")
            elif self.time_of_peak_contact_force is None:
                lines.append("  peak contact force       0 (no contact)")
            else:
                lines.append(f"  peak contact force       {self.peak_contact_force / 1e3:.3f} kN at "
                             f"{self.time_of_peak_contact_force:.5f} s{end_note('peak_contact_force')}")
            if self.max_absorber_velocity is None:
                lines.append(f"  max absorber velocity    {not_final}")
            else:
                lines.append(f"  max absorber velocity    {self.max_absorber_velocity:.5f} m/s at "
                             f"{self.time_of_max_absorber_velocity:.5f} s{end_note('max_absorber_velocity')}")
            impacts = not_final if self.impacts is None else len(self.impacts)
            lines.append(f"  impacts (> {self.impact_threshold / 1e3:g} kN)      {impacts}")
        for stop in self.stops():
            peak = stop["peak_contact_force"]
            text = not_final if peak is None else (f"{peak / 1e3:.3f} kN" + (
                f", {len(stop['impacts'])} impacts" if stop["impacts"] is not None else ""))
            lines.append(f"  {stop['name'].replace('_', ' '):24s} {text}")
        firing = self._firing_metrics()
        if "pulse_impulse" in firing:
            lines.append(f"  breech pulse impulse     {firing['pulse_impulse']:.1f} N s per shot")
        lines += element_outputs.summary_lines(self)
        lines += self._carriage_lines()
        supplied = self.kinetic_energy_history[0] + self.stored_energy_history[0] + sum(firing.get("work", {}).values())
        lines.append(f"  energy dissipated        {self.total_dissipated_energy:.2f} J of "
                     f"{supplied:.2f} J" + (" (with the work of the inputs)" if "work" in firing else ""))
        if at_end:
            lines.append("  a maximum at the end of the window is only the largest value seen: run longer for "
                         "the turning point")
        lines.append(f"  wall time                {self.wall_time * 1e3:.1f} ms ({self.steps} steps)")
        return "\n".join(lines)


def total_history(arrays, like: np.ndarray) -> np.ndarray:
    """The sum of the histories ``arrays`` (added in their order), zeros like ``like`` if there is none."""
    total = None
    for array in arrays:
        total = array if total is None else total + array
    return np.zeros_like(like) if total is None else total
