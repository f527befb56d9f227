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

tabulated at ``points`` strokes over ``[0, fraction L]`` (a -> 0 at L: the last area holds beyond).  A length
is refused (:class:`TooLongError`) when ``F_b`` reaches 0 or the area the piston's ``A`` on the table (an
orifice as large as the piston does not throttle: the law's least force is ``rho A v^2 / (2 Cd^2)``).  The
designed scene is the scene with its recoil damper replaced by this brake (the brake's piston area,
Cd, density and counter-recoil area are the scene's brake's, or :data:`DEFAULT_BRAKE`).  The absorbers of
models (i)/(ii) are not part of the rule: a scene with absorbers is refused.  With a breech-force pulse
the design uses the pulse's momentum as an impulse (the pulse acts over milliseconds of a ~0.6 s stroke).

:func:`design_brake` computes the table for a design length; the simulated recoil differs from it (the
tail beyond the table, the pulse, the preload), so :func:`~mbs_models.studies.brake_length.hit_recoil_length`
iterates the design length on the simulation until the simulated recoil is the asked one.
:func:`compare_with_linear_damper` does that, and simulates the paper's linear damper scaled to the same
recoil length, and reports the resistance over the stroke and the peak forces of each with their phase
(:mod:`~mbs_models.studies.recoil_peaks`).
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


class TooLongError(SceneError):
    """The closed form cannot be designed for this recoil length (key ``recoil_length``): a stop within the
    stroke, the other elements resisting more than R, or an orifice as large as the piston."""

    def __init__(self, message: str):
        super().__init__("recoil_length", message)


def check_recoil_length(recoil_length: float) -> None:
    if isinstance(recoil_length, bool) or not isinstance(recoil_length, (int, float)) \
            or not math.isfinite(recoil_length) or recoil_length <= 0:
        raise SceneError("recoil_length", f"must be a length > 0 m, got {recoil_length!r}")


def check_scene(scene: Scene) -> None:
    """What the rule designs: one shot on a barrel without absorbers (SceneError naming the table if not)."""
    if scene.absorbers:
        raise SceneError("absorber", "the constant-resistance rule designs the brake of a barrel without absorbers; "
                                     "remove the [[absorber]] tables")
    if getattr(scene, "burst", None) is not None and scene.burst.shots > 1:
        raise SceneError("burst", "the design is for one shot: remove [burst] (the designed scene may add it back)")
    if not free_recoil_velocity(scene) > 0:
        raise SceneError("firing", "the design needs a shot that drives the recoil (v0 > 0)")


def check_stops(scene: Scene, recoil_length: float) -> None:
    """TooLongError if a stop on the barrel sits within ``recoil_length`` (m)."""
    for contact in Mechanism(scene).stop_contacts:  # a stop the barrel would hit within the stroke
        if contact.a == GROUND and contact.b == BARREL and contact.offset <= recoil_length:
            raise TooLongError(f"must be shorter than the position of [{contact.element}] "
                               f"({contact.offset:g} m), got {recoil_length:g} m")


def free_recoil_velocity(scene: Scene) -> float:
    """v0 (m/s): the shot's free-recoil velocity, :attr:`Scene.initial_velocity`, or with a breech-force pulse
    its momentum over the barrel's mass (the pulse as an impulse)."""
    firing = scene.firing
    if firing is not None and firing.pulse is not None:
        return firing.momentum / scene.barrel.mass
    return scene.initial_velocity


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


def brake_fields(scene: Scene) -> dict:
    """The designed brake's piston area (m^2), Cd and oil density (kg/m^3): the scene's brake's, or
    :data:`DEFAULT_BRAKE`."""
    template = scene.recoil_brake
    return dict(DEFAULT_BRAKE) if template is None else dict(piston_area=template.piston_area,
                                                              discharge_coefficient=template.discharge_coefficient,
                                                              fluid_density=template.fluid_density)


def design_brake(scene: Scene, recoil_length: float, points: int = 41, fraction: float = 0.95) -> BrakeDesign:
    """The orifice table for a constant total resistance over ``recoil_length`` (m); see the module docstring.

    :class:`TooLongError` when the length cannot be designed: a stop within it, ``F_b(x) <= 0`` somewhere (the
    other elements alone resist more than R), or an area ``a(x) >= A`` (an orifice as large as the piston
    does not throttle: the law assumes a jet much faster than the piston)."""
    check_recoil_length(recoil_length)
    check_scene(scene)
    check_stops(scene, recoil_length)
    mass = scene.barrel.mass
    v0 = free_recoil_velocity(scene)
    resistance = mass * v0 ** 2 / (2.0 * recoil_length)
    strokes = np.linspace(0.0, fraction * recoil_length, points)
    speeds = v0 * np.sqrt(1.0 - strokes / recoil_length)
    brake_forces = resistance - other_resistance(scene, strokes, speeds)
    if np.any(brake_forces <= 0):
        x_bad = float(strokes[np.argmax(brake_forces <= 0)])
        raise TooLongError(f"{recoil_length:g} m is too long: the other elements alone resist more "
                           f"than the constant {resistance:.4g} N at x = {x_bad:.4g} m")
    fields = brake_fields(scene)
    A, cd, rho = fields["piston_area"], fields["discharge_coefficient"], fields["fluid_density"]
    areas = A ** 1.5 * speeds * np.sqrt(rho / (2.0 * brake_forces)) / cd
    if np.any(areas >= A):
        x_bad = float(strokes[np.argmax(areas >= A)])
        raise TooLongError(f"{recoil_length:g} m is too long: the orifice would be as large as the piston "
                           f"(a >= A = {A:g} m^2) at x = {x_bad:.4g} m")
    template = scene.recoil_brake
    brake = RecoilBrake(orifice_area=[[float(x), float(a)] for x, a in zip(strokes, areas)],
                        counter_recoil_orifice_area=None if template is None else template.counter_recoil_orifice_area,
                        **fields)
    designed = scene.with_changes(recoil_damper=None, recoil_brake=brake,
                                  name=f"{scene.name}: brake designed for constant resistance over {recoil_length:g} m")
    return BrakeDesign(designed, resistance, float(recoil_length), float(v0), strokes, areas, brake_forces)


def designable(scene: Scene, recoil_length: float, points: int = 41, fraction: float = 0.95) -> bool:
    """Whether :func:`design_brake` gives a table for ``recoil_length`` (m) (False: TooLongError)."""
    try:
        design_brake(scene, recoil_length, points, fraction)
    except TooLongError:
        return False
    return True


def longest_design_length(scene: Scene, shorter: float, points: int = 41, fraction: float = 0.95,
                          rtol: float = 1e-9, upto: float = 1e3) -> float | None:
    """The longest design length (m) :func:`design_brake` accepts, bisected to ``rtol`` from ``shorter`` (a
    designable length); None when every length up to ``upto`` m is designable (nothing limits it).  The
    limit is one of :class:`TooLongError`'s: with longer designs R shrinks and the brake force
    ``R - R_other`` reaches 0, or the orifice the piston's size, somewhere on the stroke."""
    lo = float(shorter)
    hi = 2.0 * lo
    while designable(scene, hi, points, fraction):
        lo, hi = hi, 2.0 * hi
        if lo > upto:
            return None
    while hi - lo > rtol * lo:
        middle = 0.5 * (lo + hi)
        lo, hi = (middle, hi) if designable(scene, middle, points, fraction) else (lo, middle)
    return lo


@dataclass
class Comparison:
    """The designed brake against the paper's linear damper at the same recoil length.

    ``length``: the design that hits the asked recoil length in the simulation
    (:class:`~mbs_models.studies.brake_length.LengthDesign`: asked, achieved, tolerance, iterations);
    ``design`` its table (for the design length L_d); ``designed`` and ``linear``:
    :class:`~mbs_models.results.result.Result`; ``damper_scale``: the factor on the linear damper's
    coefficients giving the designed recoil length; ``flatness``: the largest relative deviation of the
    designed resistance ``-M a`` from R over ``[0.05 L_d, 0.95 L_d]`` (the 90 % of the stroke the rule is
    judged on)."""

    length: object
    designed: object
    linear: object
    damper_scale: float
    flatness: float

    @property
    def design(self) -> BrakeDesign:
        return self.length.design

    def to_dict(self) -> dict:
        from .recoil_peaks import peak_forces

        def case(result) -> dict:
            return {"recoil_length": result.max_barrel_displacement,
                    "peak_support_force": result.peak_support_force,
                    "peak_support_force_in_recoil": peak_support_force_in_recoil(result),
                    "peaks": {name: peak.to_dict() for name, peak in peak_forces(result).items()}}

        return {**self.length.to_dict(),
                "constant_resistance": self.design.resistance,
                "designed": case(self.designed),
                "linear_damper": {**case(self.linear),
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
                               end_time: float = 3.0, points: int = 41, tolerance: float | None = None) -> Comparison:
    """Design the brake whose simulated recoil is ``recoil_length`` (m) within ``tolerance`` (m; see
    :func:`~mbs_models.studies.brake_length.hit_recoil_length`), and simulate the linear damper (the scene's,
    or the paper's shape) scaled so that its recoil length is the designed scene's (brentq on the scale,
    metrics to 1e-6 m); every run to ``end_time`` (s) at ``accuracy``."""
    from ..engine.simulation import simulate
    from .brake_length import hit_recoil_length

    length = hit_recoil_length(scene, recoil_length, tolerance, accuracy, end_time, points)
    designed = length.result
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
    design = length.design
    return Comparison(length, designed, linear_result, scale,
                      resistance_flatness(designed, design.resistance, design.recoil_length))


def plot_comparison(comparison: Comparison):
    """Resistance vs stroke of the designed brake and the linear damper (peak support force in the legend), drawn on
    the densified histories (:meth:`~mbs_models.results.result.Result.densified`: at most 1 ms apart; ``-M a``
    there from the velocity's interpolant).  A matplotlib ``Figure`` of its own (no pyplot state: nothing is left
    open, the caller's backend unchanged)."""
    from matplotlib.figure import Figure

    from .recoil_peaks import RECOIL, peak_forces

    fig = Figure(figsize=(11, 4.2))
    left, right = fig.subplots(1, 2)
    for result, label, style in ((comparison.designed, "designed brake (constant resistance)", "-"),
                                 (comparison.linear, f"linear damper x {comparison.damper_scale:.3g}", "--")):
        dense = result.densified()  # drawn at most 1 ms apart (the solver's steps reach 20 ms)
        x, r = recoil_stroke(dense)
        mount = peak_forces(result)["mount"]
        in_recoil = "" if mount.phase == RECOIL else \
            f"; {peak_support_force_in_recoil(result) / 1e3:.2f} kN in recoil"
        left.plot(1e3 * x, r / 1e3, style, label=f"{label}: mount peak {mount.force / 1e3:.2f} kN "
                                                 f"{mount.where}{in_recoil}")
        right.plot(dense.time, dense.support_force / 1e3, style, label=label)
    left.axhline(comparison.design.resistance / 1e3, color="grey", lw=0.8, ls=":",
                 label=f"R = M v0^2 / (2 L_d) = {comparison.design.resistance / 1e3:.2f} kN, "
                       f"L_d = {comparison.design.recoil_length:.4g} m")
    left.set_xlabel("barrel displacement (mm)")
    left.set_ylabel("resistance to recoil (kN)")
    left.set_title(f"recoil length {1e3 * comparison.designed.max_barrel_displacement:.2f} mm "
                   f"(asked {1e3 * comparison.length.asked:.2f} mm)")
    left.legend(fontsize=7, loc="lower center")
    right.set_xlabel("time (s)")
    right.set_ylabel("support force (kN)")
    right.set_title("force on the mount")
    right.legend(fontsize=8)
    fig.tight_layout()
    return fig
