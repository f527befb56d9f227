"""What each contact law does to an impact: the restitution it achieves, and its force-penetration loop.

``recoil contact-laws --out DIR`` writes ``contact_laws.png``, ``contact_laws.json`` and ``contact_laws.md``:

* **Restitution laws** (Lankarani-Nikravesh, Flores, Gonthier, exact-restitution): the restitution a free
  two-body impact achieves as a function of the one requested -- the closed form of the independent
  reference (:func:`validation.reference.closed_form.achieved_restitution`, a curve) and engine runs
  (points): a free impact of the barrel (5600 kg at 0.69 m/s) on an absorber (1000 kg) at rest, no other
  force, e = minus the ratio of the relative velocities after and before.
* **Hunt-Crossley**: the achieved restitution as a function of lambda v- (curve and engine points).
* **Kelvin-Voigt**: as a function of the damping ratio ``zeta = c / (2 sqrt(k m_red))`` (the force is
  clipped at the end of restitution, so e is not the classic ``exp(-zeta pi / sqrt(1 - zeta^2))``; both
  curves are drawn).
* **Loops**: force against penetration over one free impact for every law (Table 1's stiffness and
  exponent; restitution 0.5, lambda 0.6 s/m, Kelvin-Voigt with k = 4e7 N/m, c = 8e4 N s/m).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from mbs_models import Absorber, Barrel, Contact, RecoilDamper, RecoilSpring, Scene, simulate
from mbs_models.outputs import atomic_write_bytes, atomic_write_json, atomic_write_text, prepare_output_dir
from mbs_models.results.plotting import SERIES_COLOURS, figure_png, new_figure

from ..reference.closed_form import achieved_restitution, kelvin_voigt_restitution

#: The free impact: barrel mass (kg), absorber mass (kg), approach speed (m/s).
BARREL_MASS, ABSORBER_MASS, IMPACT_VELOCITY = 5600.0, 1000.0, 0.69
REDUCED_MASS = BARREL_MASS * ABSORBER_MASS / (BARREL_MASS + ABSORBER_MASS)
#: Table 1's stiffness (N/m^1.3) and exponent, the paper's lambda (s/m).
STIFFNESS, EXPONENT, DAMPING_FACTOR = 2.1e8, 1.3, 0.6
#: Kelvin-Voigt: the example scene's stiffness (N/m) and damping (N s/m).
KV_STIFFNESS, KV_DAMPING = 4.0e7, 8.0e4
RESTITUTION_LAWS = ("lankarani-nikravesh", "flores", "gonthier", "exact-restitution")
#: Requested restitutions of the engine points; lambda v- of Hunt-Crossley; damping ratios of Kelvin-Voigt.
ENGINE_RESTITUTIONS = (0.05, 0.3, 0.5, 0.8, 0.99)
ENGINE_LAMBDA_V = (0.05, 0.2, 0.5, 1.0, 3.0)
ENGINE_DAMPING_RATIOS = (0.02, 0.1, 0.3, 0.6, 0.9)


def free_impact(contact: Contact) -> Scene:
    """The barrel at :data:`IMPACT_VELOCITY` against an absorber at rest, no other force."""
    return Scene(barrel=Barrel(mass=BARREL_MASS, initial_velocity=IMPACT_VELOCITY), recoil_spring=RecoilSpring(0.0),
                 recoil_damper=RecoilDamper(0.0, 0.0),
                 absorber=Absorber(mass=ABSORBER_MASS, mount="ground", stiffness=0.0, damping=0.0), contact=contact,
                 name=f"free impact, {contact.law}")


def contact_of(law: str, restitution: float = 0.5, lambda_v: float | None = None,
               damping_ratio: float | None = None) -> Contact:
    """The contact of one point of the study."""
    if law in RESTITUTION_LAWS:
        return Contact(gap=0.0, stiffness=STIFFNESS, exponent=EXPONENT, law=law, restitution=restitution)
    if law == "hunt-crossley":
        factor = DAMPING_FACTOR if lambda_v is None else lambda_v / IMPACT_VELOCITY
        return Contact(gap=0.0, stiffness=STIFFNESS, exponent=EXPONENT, damping_factor=factor)
    if law == "hertz":
        return Contact(gap=0.0, stiffness=STIFFNESS, exponent=EXPONENT, law="hertz")
    damping = KV_DAMPING if damping_ratio is None else 2.0 * damping_ratio * math.sqrt(KV_STIFFNESS * REDUCED_MASS)
    return Contact(gap=0.0, stiffness=KV_STIFFNESS, law="kelvin-voigt", damping=damping)


def _run(contact: Contact, accuracy: str):
    """(restitution, result) of the engine's free impact; the impact is over well before the end."""
    result = simulate(free_impact(contact), 0.2, accuracy)
    if len(result.impacts) != 1:
        raise RuntimeError(f"{contact.law}: expected one impact, got {len(result.impacts)}")
    e = (result.absorber_velocity[-1] - result.barrel_velocity[-1]) / IMPACT_VELOCITY
    return float(e), result


@dataclass
class Point:
    """One engine run against the closed form: the law, its parameter, the restitutions."""

    law: str
    parameter: str          # "requested e", "lambda v-", "damping ratio"
    value: float
    oracle: float
    engine: float

    @property
    def error(self) -> float:
        return abs(self.engine - self.oracle)


@dataclass
class ContactLawStudy:
    """Engine points against the closed forms, and one force-penetration loop per law."""

    accuracy: str
    points: list[Point] = field(default_factory=list)
    loops: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict, repr=False)

    @property
    def worst_error(self) -> float:
        return max(p.error for p in self.points)

    def to_dict(self) -> dict:
        return {"accuracy": self.accuracy, "impact_velocity": IMPACT_VELOCITY, "barrel_mass": BARREL_MASS,
                "absorber_mass": ABSORBER_MASS, "worst_error": self.worst_error,
                "points": [dict(asdict(p), error=p.error) for p in self.points],
                "loop_peaks": {law: float(np.max(force)) for law, (_, force) in self.loops.items()}}

    def markdown(self) -> str:
        lines = ["# Contact laws: achieved restitution of a free impact", "",
                 f"Barrel {BARREL_MASS:g} kg at {IMPACT_VELOCITY:g} m/s on an absorber of {ABSORBER_MASS:g} kg at "
                 f"rest; engine at `{self.accuracy}` against the closed forms of the independent reference.", "",
                 "| law | parameter | value | closed form e | engine e | difference |", "|---|---|---:|---:|---:|---:|"]
        for p in self.points:
            lines.append(f"| {p.law} | {p.parameter} | {p.value:g} | {p.oracle:.6f} | {p.engine:.6f} | {p.error:.1e} |")
        return "\n".join(lines) + "\n"


def run_study(accuracy: str = "standard", progress=None) -> ContactLawStudy:
    """Every engine point and loop of the study (about 25 short runs)."""
    study = ContactLawStudy(accuracy)
    jobs = [(law, "requested e", e) for law in RESTITUTION_LAWS for e in ENGINE_RESTITUTIONS]
    jobs += [("hunt-crossley", "lambda v-", u) for u in ENGINE_LAMBDA_V]
    jobs += [("kelvin-voigt", "damping ratio", z) for z in ENGINE_DAMPING_RATIOS]
    for i, (law, parameter, value) in enumerate(jobs):
        if law in RESTITUTION_LAWS:
            contact, oracle = contact_of(law, restitution=value), achieved_restitution(law, value)
        elif law == "hunt-crossley":
            contact, oracle = contact_of(law, lambda_v=value), achieved_restitution(law, lambda_v=value)
        else:
            contact, oracle = contact_of(law, damping_ratio=value), achieved_restitution(law, damping_ratio=value)
        engine, _ = _run(contact, accuracy)
        study.points.append(Point(law, parameter, value, oracle, engine))
        if progress:
            progress(i + 1, len(jobs))
    for law in (*RESTITUTION_LAWS, "hunt-crossley", "hertz", "kelvin-voigt"):
        _, result = _run(contact_of(law), accuracy)
        penetration = result.barrel_position - result.absorber_position
        inside = result.contact_force > 0
        study.loops[law] = (penetration[inside], result.contact_force[inside])
    return study


def figure(study: ContactLawStudy):
    """Four panels: restitution laws, Hunt-Crossley, Kelvin-Voigt (closed forms and engine points), loops."""
    fig, axes = new_figure(2, 2, width=11.0, row_height=4.0)
    requested = np.linspace(0.02, 1.0, 200)
    ax = axes[0, 0]
    ax.plot(requested, requested, color="#999999", lw=0.8, ls="--", label="achieved = requested")
    for i, law in enumerate(RESTITUTION_LAWS):
        colour = SERIES_COLOURS[i]
        ax.plot(requested, [achieved_restitution(law, e) for e in requested], color=colour, lw=1.2, label=law)
        points = [p for p in study.points if p.law == law]
        ax.plot([p.value for p in points], [p.engine for p in points], "o", color=colour, ms=4, mfc="none")
    ax.set_xlabel("requested restitution e")
    ax.set_ylabel("achieved restitution")
    ax.set_title("restitution laws: closed form (lines), engine (circles)", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    u = np.geomspace(1e-3, 10.0, 200)
    ax.semilogx(u, [achieved_restitution("hunt-crossley", lambda_v=x) for x in u], color=SERIES_COLOURS[4], lw=1.2,
                label="closed form")
    points = [p for p in study.points if p.law == "hunt-crossley"]
    ax.plot([p.value for p in points], [p.engine for p in points], "o", color=SERIES_COLOURS[4], ms=4, mfc="none",
            label="engine")
    ax.axvline(DAMPING_FACTOR * IMPACT_VELOCITY, color="#999999", lw=0.8, ls=":", label="Table 1 at v0")
    ax.set_xlabel("lambda v- (dimensionless)")
    ax.set_ylabel("achieved restitution")
    ax.set_title("Hunt-Crossley", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    zeta = np.linspace(0.0, 0.99, 200)
    ax.plot(zeta, [kelvin_voigt_restitution(z, clipped=True) for z in zeta], color=SERIES_COLOURS[5], lw=1.2,
            label="closed form, force clipped to >= 0")
    ax.plot(zeta, [kelvin_voigt_restitution(z, clipped=False) for z in zeta], color=SERIES_COLOURS[5], lw=0.8,
            ls="--", label="classic exp(-zeta pi / sqrt(1 - zeta^2))")
    points = [p for p in study.points if p.law == "kelvin-voigt"]
    ax.plot([p.value for p in points], [p.engine for p in points], "o", color=SERIES_COLOURS[5], ms=4, mfc="none",
            label="engine")
    ax.set_xlabel("damping ratio c / (2 sqrt(k m_red))")
    ax.set_ylabel("achieved restitution")
    ax.set_title("Kelvin-Voigt", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    for i, (law, (penetration, force)) in enumerate(study.loops.items()):
        ax.plot(penetration * 1e3, force / 1e3, color=SERIES_COLOURS[i % len(SERIES_COLOURS)], lw=1.0, label=law)
    ax.set_xlabel("penetration [mm]")
    ax.set_ylabel("contact force [kN]")
    ax.set_title(f"one free impact at {IMPACT_VELOCITY:g} m/s (e = 0.5 asked, lambda = {DAMPING_FACTOR:g} s/m)",
                 fontsize=10)
    ax.legend(fontsize=7)
    fig.suptitle("Contact laws: restitution achieved and force-penetration loops", fontsize=11)
    return fig


def write(study: ContactLawStudy, out) -> Path:
    """Write ``contact_laws.png``, ``.json`` and ``.md`` to the directory ``out``."""
    out = prepare_output_dir(out)
    atomic_write_bytes(out / "contact_laws.png", figure_png(figure(study)))
    atomic_write_json(out / "contact_laws.json", study.to_dict())
    atomic_write_text(out / "contact_laws.md", study.markdown())
    return out
