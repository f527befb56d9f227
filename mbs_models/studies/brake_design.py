"""Design study: the recoil brake whose orifice makes the total resistance constant over the stroke.

The classical design rule of recoil mechanisms: for a given recoil length ``L`` the force on the mount is
the smallest possible when the total resistance to the recoil is constant over the stroke.  With the
shot's free-recoil velocity ``v0`` (the impulse model: ``v0 = I / M``, :attr:`Scene.initial_velocity`) the
work-energy balance of a constant resistance R over L gives::

    R = M v0^2 / (2 L)            v(x) = v0 sqrt(1 - x / L)          (x: barrel displacement, m)

The other elements resist too (recoil spring, recuperator, friction, gravity along the cradle):
``R_other(x, v)``, the force on the barrel of every connector to the ground and every constant load,
evaluated on the design motion.  The brake makes up the rest, ``F_b(x) = R - R_other(x, v(x))`` (must stay
> 0: else the recoil length asked for is too long for the other elements), and its law
``F_b = rho A^3 v^2 / (2 Cd^2 a^2)`` gives the orifice area::

    a(x) = A^(3/2) v(x) sqrt(rho / (2 F_b(x))) / Cd

tabulated at ``points`` strokes over ``[0, fraction L]`` (a -> 0 at L: the last area holds beyond).  The
designed scene is the scene with its recoil damper replaced by this brake (the brake's piston area,
Cd, density and counter-recoil area are the scene's brake's, or :data:`DEFAULT_BRAKE`).  The absorbers of
models (i)/(ii) are not part of the rule: a scene with absorbers is refused.  With a breech-force pulse
the design uses the pulse's momentum as an impulse (the pulse acts over milliseconds of a ~0.6 s stroke).

:func:`design_brake` computes the table; :func:`compare_with_linear_damper` simulates the designed scene
and the paper's linear damper scaled to the same recoil length, and reports the resistance over the
stroke and the peak support force of each.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import brentq

from ..elements.barrel import BARREL
from ..elements.connector import GROUND
from ..elements.recoil_brake import RecoilBrake
from ..elements.recoil_damper import RecoilDamper
from ..engine.mechanism import Mechanism
from ..errors import SceneError
from ..scene import Scene

#: The brake's other parameters when the scene has no [recoil_brake]: piston area (m^2), Cd, oil density.
DEFAULT_BRAKE = dict(piston_area=0.012, discharge_coefficient=0.7, fluid_density=870.0)
#: The paper's damper (N s/m): the shape of the linear damper compared when the scene has none.
PAPER_DAMPER = RecoilDamper(recoil=6239.0, counter_recoil=14050.0)


@dataclass
class BrakeDesign:
    """The designed brake: ``scene`` (ready to run), ``resistance`` R (N), ``recoil_length`` L (m),
    ``initial_velocity`` v0 (m/s), and the table ``strokes`` (m), ``areas`` (m^2), ``brake_forces`` (N)."""

    scene: Scene
    resistance: float
    recoil_length: float
    initial_velocity: float
    strokes: np.ndarray
    areas: np.ndarray
    brake_forces: np.ndarray


def _check(scene: Scene, recoil_length: float) -> None:
    if isinstance(recoil_length, bool) or not isinstance(recoil_length, (int, float)) \
            or not math.isfinite(recoil_length) or recoil_length <= 0:
        raise SceneError("recoil_length", f"must be a length > 0 m, got {recoil_length!r}")
    if scene.absorbers:
        raise SceneError("absorber", "the constant-resistance rule designs the brake of a barrel without absorbers; "
                                     "remove the [[absorber]] tables")
    if getattr(scene, "burst", None) is not None and scene.burst.shots > 1:
        raise SceneError("burst", "the design is for one shot: remove [burst] (the designed scene may add it back)")
    for contact in Mechanism(scene).stop_contacts:  # a stop the barrel would hit within the stroke
        if contact.a == GROUND and contact.b == BARREL and contact.offset <= recoil_length:
            raise SceneError("recoil_length", f"must be shorter than the position of [{contact.element}] "
                                              f"({contact.offset:g} m), got {recoil_length:g} m")


def other_resistance(scene: Scene, x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The resistance (N, opposing +x) of every element but a brake and a damper on the barrel moving at
    ``x`` (m), ``v`` (m/s): ground connectors' forces and constant loads (gravity pulls: negative)."""
    mechanism = Mechanism(scene.with_changes(recoil_damper=None, recoil_brake=None))
    total = np.zeros_like(x, dtype=float)
    for connector in mechanism.connectors:
        if {connector.a, connector.b} != {GROUND, BARREL}:
            continue
        sign = 1.0 if connector.b == BARREL else -1.0  # d = x_M (ground -> barrel) or -x_M
        total = total + sign * connector.force(sign * x, sign * v)
    for load in mechanism.loads:
        if load.body == BARREL and not load.needs_user_function:
            total = total - load.constant
    return total


def design_brake(scene: Scene, recoil_length: float, points: int = 41, fraction: float = 0.95) -> BrakeDesign:
    """The orifice table for a constant total resistance over ``recoil_length`` (m); see the module docstring."""
    _check(scene, recoil_length)
    mass = scene.barrel.mass
    firing = scene.firing
    v0 = scene.initial_velocity
    if firing is not None and firing.pulse is not None:
        v0 = firing.momentum / mass  # the pulse's momentum as an impulse
    if not v0 > 0:
        raise SceneError("firing", "the design needs a shot that drives the recoil (v0 > 0)")
    resistance = mass * v0 ** 2 / (2.0 * recoil_length)
    strokes = np.linspace(0.0, fraction * recoil_length, points)
    speeds = v0 * np.sqrt(1.0 - strokes / recoil_length)
    brake_forces = resistance - other_resistance(scene, strokes, speeds)
    if np.any(brake_forces <= 0):
        x_bad = float(strokes[np.argmax(brake_forces <= 0)])
        raise SceneError("recoil_length", f"{recoil_length:g} m is too long: the other elements alone resist more "
                                          f"than the constant {resistance:.4g} N at x = {x_bad:.4g} m")
    template = scene.recoil_brake
    fields = DEFAULT_BRAKE if template is None else dict(piston_area=template.piston_area,
                                                         discharge_coefficient=template.discharge_coefficient,
                                                         fluid_density=template.fluid_density)
    A, cd, rho = fields["piston_area"], fields["discharge_coefficient"], fields["fluid_density"]
    areas = A ** 1.5 * speeds * np.sqrt(rho / (2.0 * brake_forces)) / cd
    brake = RecoilBrake(orifice_area=[[float(x), float(a)] for x, a in zip(strokes, areas)],
                        counter_recoil_orifice_area=None if template is None else template.counter_recoil_orifice_area,
                        **fields)
    designed = scene.with_changes(recoil_damper=None, recoil_brake=brake,
                                  name=f"{scene.name}: brake designed for constant resistance over {recoil_length:g} m")
    return BrakeDesign(designed, resistance, float(recoil_length), float(v0), strokes, areas, brake_forces)


@dataclass
class Comparison:
    """The designed brake against the paper's linear damper at the same recoil length.

    ``designed`` and ``linear``: :class:`~mbs_models.results.result.Result`; ``damper_scale``: the factor
    on the linear damper's coefficients giving the recoil length; ``stroke``/``resistance`` per case:
    the resistance ``-M a`` (N) over the recoil stroke (m); ``flatness``: the largest relative deviation of
    the designed resistance from R over ``[0.05 L, 0.95 L]`` (the 90 % of the stroke the rule is judged on)."""

    design: BrakeDesign
    designed: object
    linear: object
    damper_scale: float
    flatness: float

    def to_dict(self) -> dict:
        return {"recoil_length_asked": self.design.recoil_length,
                "constant_resistance": self.design.resistance,
                "designed": {"recoil_length": self.designed.max_barrel_displacement,
                             "peak_support_force": self.designed.peak_support_force,
                             "peak_support_force_in_recoil": peak_support_force_in_recoil(self.designed)},
                "linear_damper": {"recoil_length": self.linear.max_barrel_displacement,
                                  "peak_support_force": self.linear.peak_support_force,
                                  "peak_support_force_in_recoil": peak_support_force_in_recoil(self.linear),
                                  "recoil": self.linear.scene.recoil_damper.recoil,
                                  "counter_recoil": self.linear.scene.recoil_damper.counter_recoil},
                "resistance_flatness_over_90_percent": self.flatness,
                "strokes": self.design.strokes.tolist(), "orifice_areas": self.design.areas.tolist()}


def peak_support_force_in_recoil(result) -> float:
    """The largest |support force| (N, samples) from t = 0 to the maximum displacement: the recoil stroke
    alone (the peak over a run may come later, when the barrel returns onto its battery buffer)."""
    end = int(np.searchsorted(result.time, result.time_of_max_barrel_displacement))
    return float(np.max(np.abs(result.support_force[:end + 1])))


def recoil_stroke(result, until: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(x m, resistance N) of the barrel from t = 0 to its maximum displacement (or to ``until`` s): ``-M a``
    plus the external loads on the barrel that are inputs (the breech force), i.e. what the mechanism and
    gravity resist with."""
    end = int(np.searchsorted(result.time, result.time_of_max_barrel_displacement if until is None else until))
    mass = result.scene.barrel.mass
    t = result.time[:end + 1]
    resistance = -mass * result.barrel_acceleration[:end + 1]
    for load in Mechanism(result.scene).loads:
        if load.body == BARREL and load.needs_user_function:
            resistance = resistance + load.force(t)
    return result.barrel_position[:end + 1], resistance


def resistance_flatness(result, resistance: float, recoil_length: float) -> float:
    """Largest |R(x) - R| / R over ``0.05 L <= x <= 0.95 L`` of the recoil stroke."""
    x, r = recoil_stroke(result)
    window = (x >= 0.05 * recoil_length) & (x <= 0.95 * recoil_length)
    return float(np.max(np.abs(r[window] - resistance)) / resistance)


def compare_with_linear_damper(scene: Scene, recoil_length: float, accuracy: str = "standard",
                               end_time: float = 3.0, points: int = 41) -> Comparison:
    """Design the brake, simulate it, and simulate the linear damper (the scene's, or the paper's shape)
    scaled so that its recoil length is the designed scene's (brentq on the scale, metrics to 1e-6 m)."""
    from ..engine.simulation import simulate

    design = design_brake(scene, recoil_length, points)
    designed = simulate(design.scene, end_time, accuracy)
    damper = scene.recoil_damper or PAPER_DAMPER
    base = scene.with_changes(recoil_brake=None)
    target = designed.max_barrel_displacement

    def linear(scale: float):
        changed = base.with_changes(recoil_damper=replace(damper, recoil=damper.recoil * scale,
                                                          counter_recoil=damper.counter_recoil * scale))
        return simulate(changed, end_time, accuracy, stop_when_final=["max_barrel_displacement", "peak_support_force"])

    lo, hi = 1e-3, 1e3
    scale = brentq(lambda s: linear(s).max_barrel_displacement - target, lo, hi, xtol=1e-9, rtol=1e-9)
    linear_result = simulate(base.with_changes(recoil_damper=replace(damper, recoil=damper.recoil * scale,
                                                                     counter_recoil=damper.counter_recoil * scale)),
                             end_time, accuracy)
    return Comparison(design, designed, linear_result, scale,
                      resistance_flatness(designed, design.resistance, recoil_length))


def plot_comparison(comparison: Comparison):
    """Resistance vs stroke of the designed brake and the linear damper (peak support force in the legend)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for result, label, style in ((comparison.designed, "designed brake (constant resistance)", "-"),
                                 (comparison.linear, f"linear damper x {comparison.damper_scale:.3g}", "--")):
        x, r = recoil_stroke(result)
        left.plot(1e3 * x, r / 1e3, style, label=f"{label}: peak support {result.peak_support_force / 1e3:.2f} kN "
                                                 f"({peak_support_force_in_recoil(result) / 1e3:.2f} kN in recoil)")
        right.plot(result.time, result.support_force / 1e3, style, label=label)
    left.axhline(comparison.design.resistance / 1e3, color="grey", lw=0.8, ls=":",
                 label=f"R = M v0^2 / (2 L) = {comparison.design.resistance / 1e3:.2f} kN")
    left.set_xlabel("barrel displacement (mm)")
    left.set_ylabel("resistance to recoil (kN)")
    left.set_title(f"recoil length {1e3 * comparison.designed.max_barrel_displacement:.1f} mm")
    left.legend(fontsize=7, loc="lower center")
    right.set_xlabel("time (s)")
    right.set_ylabel("support force (kN)")
    right.set_title("force on the mount")
    right.legend(fontsize=8)
    fig.tight_layout()
    return fig
