"""From sampled states to metrics: refined extrema, impacts per contact, energies per element, the support force.

Everything here works on the step-end samples of a solve (any solver) and the scene's bodies and
connectors (:class:`~mbs_models.engine.mechanism.Mechanism`); it needs no Exudyn and names no effect.
Between samples the state is the cubic Hermite interpolant of each body (position from velocity,
velocity from acceleration); forces between samples are the connectors' laws on it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..elements.barrel import BARREL
from ..errors import SimulationError
from .energies import Energies, cumulative_quadrature, energies  # noqa: F401  (re-exported)
from . import element_outputs
from .peaks import refine_maximum
from .refinement import Episodes, refine
from .result import ALL_METRICS, ContactOutput, Impact
from .samples import Interpolant, Samples

if TYPE_CHECKING:  # (a carriage scene's outputs: imported where a carriage scene is analysed)
    from .carriage import CarriageOutput


def contact_episodes(mechanism, connector, s: Samples, force: np.ndarray, interp: Interpolant,
                     threshold: float) -> Episodes:
    """The contact episodes of one contact, refined (:func:`~mbs_models.results.refinement.refine`)."""
    return refine(mechanism, s.time, {connector.name: force}, interp, [connector], threshold)[0][connector.name]


def initial_static_force(mechanism, connector, s: Samples) -> float:
    """The force (N) a contact holds at rest at the first sample: its law at ``p' = 0``, ``k p(0)^n``
    (0 unless an initial interference) -- what an episode going on from t = 0 rises from."""
    return connector.elastic_force(float(mechanism.relative(connector, {n: x[0] for n, x in s.positions.items()})))


def impact_mask(mechanism, connector, s: Samples, episodes: Episodes, threshold: float) -> np.ndarray:
    """Which of a contact's episodes are impacts: their peak rises above the force they start from at rest
    by more than ``threshold`` N (:meth:`~mbs_models.results.refinement.Episodes.impact_mask`)."""
    return episodes.impact_mask(threshold, initial_static_force(mechanism, connector, s))


def find_impacts(mechanism, connector, s: Samples, force: np.ndarray, interp: Interpolant,
                 threshold: float) -> tuple[list[Impact], list[Impact]]:
    """Contact episodes of one contact (maximal intervals with force > 0): (all, the impacts among them,
    :func:`impact_mask`).  Peaks are refined on the law over the interpolated state
    (:func:`~mbs_models.results.refinement.refine`)."""
    episodes = contact_episodes(mechanism, connector, s, force, interp, threshold)
    return (episodes.impacts(connector.name),
            episodes.impacts(connector.name, impact_mask(mechanism, connector, s, episodes, threshold)))


@dataclass
class Metrics:
    """All scalar results of one solve and the per-contact outputs (see :class:`~mbs_models.results.result.Result`)."""

    max_barrel_displacement: float | None = None
    time_of_max_barrel_displacement: float | None = None
    max_velocity: dict[str, tuple[float | None, float | None]] = field(default_factory=dict)
    contacts: dict[str, ContactOutput] = field(default_factory=dict)
    support_force: np.ndarray | None = None
    peak_support_force: float | None = None
    time_of_peak_support_force: float | None = None
    energies: Energies | None = None
    element_histories: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    element_metrics: dict[str, dict] = field(default_factory=dict)
    carriage: "CarriageOutput | None" = None


def support_force_samples(mechanism, s: Samples) -> np.ndarray:
    """The force on the mount (N, positive in the recoil direction) at the samples."""
    total = np.zeros_like(s.time)
    for connector in mechanism.connectors:
        sign = connector.support_sign
        if sign:
            d = mechanism.relative(connector, s.positions)
            rate = mechanism.relative(connector, s.velocities)
            total = total + sign * connector.force(d, rate, s.time)
    return total


def _support_sample(mechanism, s: Samples, samples: np.ndarray) -> tuple[int, bool]:
    """The sample of the largest |S| and whether there is anything to refine (a connector to the ground)."""
    return int(np.argmax(np.abs(samples))), any(c.support_sign for c in mechanism.connectors)


def _support_peak(s: Samples, samples: np.ndarray, k: int, refined: tuple[float, float] | None) -> tuple[float, float]:
    """The peak |S| (N) and its time (s): the refined maximum near sample k unless the sample is larger."""
    magnitude = np.abs(samples)
    if refined is None:
        return 0.0, float(s.time[k])
    peak, t_peak = refined
    if magnitude[k] >= peak:
        return float(magnitude[k]), float(s.time[k])
    return float(peak), float(t_peak)


def _refined_support_peak(mechanism, s: Samples, interp: Interpolant, samples: np.ndarray) -> tuple[float, float]:
    """The largest |support force| (N) and its time (s), refined on the interpolated state."""
    k, grounded = _support_sample(mechanism, s, samples)
    refined = refine(mechanism, s.time, {}, interp, [], 0.0, k)[1] if grounded else None
    return _support_peak(s, samples, k, refined)


def analyse(mechanism, s: Samples, impact_threshold: float, wanted: tuple[str, ...] = ALL_METRICS) -> Metrics:
    """Compute the metrics of a solve from its samples: those in ``wanted``, and always the energies.

    Metrics left out are None (a contact's peak and impacts share one search: asking for either
    computes both).  Finite samples may still give forces, powers or energies beyond double precision (a solve
    that diverged to states the model cannot represent): that is a :class:`~mbs_models.errors.SimulationError`
    naming the quantity (:func:`check_representable`), never a numpy warning or an inf/NaN result.
    """
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        metrics = _analyse(mechanism, s, impact_threshold, wanted)
    check_representable(metrics, s)
    return metrics


def check_representable(metrics: Metrics, s: Samples) -> None:
    """SimulationError naming the first quantity of ``metrics`` that is not finite: the support force, a contact's
    force or peak, an energy history, or the energy balance's sum ``kinetic + stored + dissipated - work`` (the
    order the balance is computed in)."""
    quantities = [("force on the mount", metrics.support_force), ("maximum barrel displacement",
                                                                  metrics.max_barrel_displacement),
                  ("peak force on the mount", metrics.peak_support_force)]
    quantities += [(f"maximum velocity of {name}", value) for name, (value, _) in metrics.max_velocity.items()]
    for contact in metrics.contacts.values():
        quantities += [(f"force of {contact.name}", contact.force), (f"peak force of {contact.name}", contact.peak_force)]
    energy = metrics.energies
    for kind in ("kinetic", "stored", "dissipated", "work"):
        quantities += [(f"{kind} energy of {name}", history) for name, history in getattr(energy, kind).items()]
    with np.errstate(over="ignore", invalid="ignore"):
        balance = np.zeros_like(s.time)
        for kind in ("kinetic", "stored", "dissipated"):
            balance = balance + sum(getattr(energy, kind).values(), np.zeros_like(s.time))
        balance = balance - sum(energy.work.values(), np.zeros_like(s.time))
    quantities.append(("sum of the energies (kinetic + stored + dissipated - work)", balance))
    present = [np.ravel(value) for _, value in quantities if value is not None]
    if not present or np.isfinite(np.concatenate(present)).all():  # (one pass over all; the first named below)
        return
    for what, value in quantities:
        if value is not None and not np.all(np.isfinite(value)):
            speed = max(float(np.max(np.abs(v))) for v in s.velocities.values())
            raise SimulationError(f"the {what} is beyond double precision (the solve reached speeds up to {speed:.3g} "
                                  f"m/s): the solution diverged to states the model cannot represent")


def _analyse(mechanism, s: Samples, impact_threshold: float, wanted: tuple[str, ...]) -> Metrics:
    interp = Interpolant(s)
    metrics = Metrics()
    if "max_barrel_displacement" in wanted:
        metrics.max_barrel_displacement, metrics.time_of_max_barrel_displacement = refine_maximum(
            s.time, s.positions[BARREL], s.velocities[BARREL])
    if "max_absorber_velocity" in wanted:
        for body in mechanism.absorber_bodies:
            metrics.max_velocity[body.name] = refine_maximum(s.time, s.velocities[body.name],
                                                             s.accelerations[body.name])
    metrics.support_force = support_force_samples(mechanism, s)
    searched = [c for c in mechanism.contacts] if ("impacts" in wanted or "peak_contact_force" in wanted) else []
    k_support, grounded = _support_sample(mechanism, s, metrics.support_force)
    refine_support = "peak_support_force" in wanted and grounded
    episodes, refined_support = refine(mechanism, s.time, s.forces, interp, searched, impact_threshold,
                                       k_support if refine_support else None)
    for connector in mechanism.contacts:
        if connector.name in episodes:
            metrics.contacts[connector.name] = _contact_output(mechanism, connector, s,
                                                               episodes[connector.name], impact_threshold)
        else:  # the history only
            metrics.contacts[connector.name] = ContactOutput(connector.name, connector.element, s.forces[connector.name],
                                                             None, None, None)
    if "peak_support_force" in wanted:
        metrics.peak_support_force, metrics.time_of_peak_support_force = _support_peak(
            s, metrics.support_force, k_support, refined_support)
    metrics.energies = energies(mechanism, s, interp)
    if s.planar:  # a carriage scene: its outputs, and its energies made planar
        from .carriage import carriage_output  # (imported on first use: the 1-D scenes never load it)

        metrics.carriage = carriage_output(mechanism, s, interp, metrics.energies)
    metrics.element_histories, metrics.element_metrics = element_outputs.compute(mechanism, s, interp)
    return metrics


def _contact_output(mechanism, connector, s: Samples, episodes: Episodes,
                    impact_threshold: float) -> ContactOutput:
    """The episodes, impacts (:func:`impact_mask`) and refined peak force of one contact.

    The peak is the strongest impact's; failing that (no impact, or the sample maximum above every
    impact's peak) the refined peak of the episode holding the sample maximum.
    """
    force = s.forces[connector.name]
    impacts = episodes.impacts(connector.name, impact_mask(mechanism, connector, s, episodes, impact_threshold))
    k = int(np.argmax(force))
    if impacts and max(i.peak_force for i in impacts) >= force[k]:
        strongest = max(impacts, key=lambda i: i.peak_force)  # already refined
        peak, t_peak = strongest.peak_force, strongest.time_of_peak_force
    elif force[k] > 0:
        holding = int(np.flatnonzero(episodes.k == k)[0])  # k is the first largest sample of its episode
        peak, t_peak = float(episodes.peak_force[holding]), float(episodes.time_of_peak_force[holding])
    else:
        peak, t_peak = 0.0, None  # no contact at all
    onsets = list(connector.capture.onsets) if getattr(connector, "capture", None) is not None else None
    return ContactOutput(name=connector.name, element=connector.element, force=force, peak_force=peak,
                         time_of_peak_force=t_peak, impacts=impacts, episodes=len(episodes.k), onsets=onsets)
