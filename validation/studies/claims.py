"""Checking the paper's qualitative claims (:func:`validation.studies.paper.qualitative_claims`) on our results.

Each claim's ``predicate`` text is implemented here as code over a :class:`ClaimEvidence` (engine
results for m = 1000 kg at gap 0, Table 2 values and the gap sweeps), so the report can say which
claims hold, which do not, and show the numbers behind each verdict.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from mbs_models.results.result import Result

from .paper import MODEL_I, MODEL_II, SIMPLIFIED, QualitativeClaim, qualitative_claims


@dataclass
class ClaimEvidence:
    """What the claims are checked on.

    ``x_max``: (model label, absorber mass) -> max barrel displacement at gap 0 (m), simplified under
    (SIMPLIFIED, mass); ``runs``: model label -> engine Result at m = 1000 kg, gap 0, 10 s;
    ``sweeps``: (model label, mass) -> list of (gap m, max barrel displacement m), may be empty.
    """

    x_max: dict[tuple[str, float], float]
    runs: dict[str, Result]
    sweeps: dict[tuple[str, float], list[tuple[float, float]]]


@dataclass(frozen=True)
class ClaimVerdict:
    claim: QualitativeClaim
    holds: bool | None  # None: not checkable with the evidence given
    evidence: str

    def to_dict(self) -> dict:
        return {"key": self.claim.key, "text": self.claim.text, "source": self.claim.source,
                "predicate": self.claim.predicate, "holds": self.holds, "evidence": self.evidence}


def _second_impact(result: Result):
    return result.impacts[1] if len(result.impacts) > 1 else None


def _ii_max_at_gap_zero(e: ClaimEvidence):
    parts, holds = [], True
    for mass in (100.0, 500.0, 1000.0):
        sweep = e.sweeps.get((MODEL_II, mass))
        if not sweep:
            return None, "no gap sweep in the evidence"
        gap, value = max(sweep, key=lambda p: p[1])
        holds &= gap == 0.0
        parts.append(f"m = {mass:g} kg: largest {value * 1e3:.1f} mm at gap {gap * 1e3:g} mm "
                     f"(gap 0: {sweep[0][1] * 1e3:.1f} mm)")
    return holds, "; ".join(parts)


def _rel(a: float, b: float) -> float:
    return abs(a - b) / abs(b)


def _checks() -> dict[str, Callable[[ClaimEvidence], tuple[bool | None, str]]]:
    x = lambda e, model, m: e.x_max[(model, m)]  # noqa: E731
    s = lambda e: e.x_max[(SIMPLIFIED, 100.0)]  # noqa: E731
    return {
        "ii_max_at_gap_zero": _ii_max_at_gap_zero,
        "i_m100_close_to_simplified": lambda e: (
            _rel(x(e, MODEL_I, 100.0), s(e)) < 0.03,
            f"model (i) {x(e, MODEL_I, 100.0) * 1e3:.1f} mm vs simplified {s(e) * 1e3:.1f} mm "
            f"({_rel(x(e, MODEL_I, 100.0), s(e)) * 100:.2f} %)"),
        "ii_m100_lower_than_simplified": lambda e: (
            x(e, MODEL_II, 100.0) < s(e),
            f"model (ii) {x(e, MODEL_II, 100.0) * 1e3:.1f} mm vs simplified {s(e) * 1e3:.1f} mm"),
        "ii_m100_equals_simplified": lambda e: (
            abs(x(e, MODEL_II, 100.0) - s(e)) < 5e-5,
            f"model (ii) {x(e, MODEL_II, 100.0) * 1e3:.1f} mm vs simplified {s(e) * 1e3:.1f} mm"),
        "i_difference_grows_with_m": lambda e: (
            x(e, MODEL_I, 100.0) > x(e, MODEL_I, 500.0) > x(e, MODEL_I, 1000.0),
            ", ".join(f"{m:g} kg: {x(e, MODEL_I, m) * 1e3:.1f} mm" for m in (100.0, 500.0, 1000.0))),
        "ii_decreases_with_m": lambda e: (
            x(e, MODEL_II, 100.0) > x(e, MODEL_II, 500.0) > x(e, MODEL_II, 1000.0)
            and x(e, MODEL_II, 1000.0) < 0.8 * s(e),
            ", ".join(f"{m:g} kg: {x(e, MODEL_II, m) * 1e3:.1f} mm" for m in (100.0, 500.0, 1000.0))
            + f"; simplified {s(e) * 1e3:.1f} mm"),
        "absorber_reduces_displacement": lambda e: (
            all(x(e, model, m) <= s(e) for model in (MODEL_I, MODEL_II) for m in (100.0, 500.0, 1000.0)),
            f"largest with an absorber "
            f"{max(x(e, mo, m) for mo in (MODEL_I, MODEL_II) for m in (100.0, 500.0, 1000.0)) * 1e3:.1f}"
            f" mm vs simplified {s(e) * 1e3:.1f} mm"),
        "first_peaks_similar": lambda e: (
            _rel(e.runs[MODEL_I].peak_contact_force, e.runs[MODEL_II].peak_contact_force) < 0.05,
            f"{e.runs[MODEL_I].peak_contact_force / 1e3:.1f} kN vs {e.runs[MODEL_II].peak_contact_force / 1e3:.1f} kN"),
        "i_later_peaks_smaller": lambda e: (
            (_second_impact(e.runs[MODEL_I]).peak_force if _second_impact(e.runs[MODEL_I]) else 0.0)
            < 0.5 * (_second_impact(e.runs[MODEL_II]).peak_force if _second_impact(e.runs[MODEL_II]) else 0.0),
            "second impact: " + " vs ".join(
                f"{label} {(_second_impact(e.runs[label]).peak_force / 1e3 if _second_impact(e.runs[label]) else 0):.1f} kN"
                for label in (MODEL_I, MODEL_II))),
        "max_velocities_same": lambda e: (
            _rel(e.runs[MODEL_I].max_absorber_velocity, e.runs[MODEL_II].max_absorber_velocity) < 0.01,
            f"{e.runs[MODEL_I].max_absorber_velocity:.4f} vs {e.runs[MODEL_II].max_absorber_velocity:.4f} m/s"),
        "vmax_time_is_contact_duration": lambda e: (
            all(abs(r.time_of_max_absorber_velocity - r.impacts[0].end) / r.impacts[0].duration < 0.1
                for r in (e.runs[MODEL_I], e.runs[MODEL_II])),
            "; ".join(f"{label}: v_max at {r.time_of_max_absorber_velocity * 1e3:.2f} ms, first contact ends "
                      f"{r.impacts[0].end * 1e3:.2f} ms" for label, r in ((MODEL_I, e.runs[MODEL_I]),
                                                                          (MODEL_II, e.runs[MODEL_II])))),
        "i_second_impact_late": lambda e: (
            _second_impact(e.runs[MODEL_I]) is None
            or _second_impact(e.runs[MODEL_I]).start - e.runs[MODEL_I].impacts[0].start > 1.5,
            f"second impact of model (i) at "
            f"{_second_impact(e.runs[MODEL_I]).start:.3f} s" if _second_impact(e.runs[MODEL_I]) else "no second impact"),
        "ii_second_impact_early": lambda e: (
            _second_impact(e.runs[MODEL_II]) is not None
            and _second_impact(e.runs[MODEL_II]).start - e.runs[MODEL_II].impacts[0].start < 0.5,
            f"second impact of model (ii) at "
            f"{_second_impact(e.runs[MODEL_II]).start:.3f} s" if _second_impact(e.runs[MODEL_II]) else "no second impact"),
        "ii_absorbs_more": lambda e: (
            _absorbed(e.runs[MODEL_II]) > _absorbed(e.runs[MODEL_I]),
            f"absorber damper + contact: model (i) {_absorbed(e.runs[MODEL_I]):.0f} J, "
            f"model (ii) {_absorbed(e.runs[MODEL_II]):.0f} J"),
    }


def _absorbed(result: Result) -> float:
    return result.dissipated_energy.get("absorber_damper", 0.0) + result.dissipated_energy.get("contact", 0.0)


def evaluate_claims(evidence: ClaimEvidence) -> list[ClaimVerdict]:
    """One verdict per qualitative claim of the paper."""
    checks = _checks()
    verdicts = []
    for claim in qualitative_claims():
        check = checks.get(claim.key)
        if check is None:
            verdicts.append(ClaimVerdict(claim, None, "no check implemented"))
            continue
        holds, text = check(evidence)
        verdicts.append(ClaimVerdict(claim, None if holds is None else bool(holds), text))
    return verdicts
