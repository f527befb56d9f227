"""What a carriage scene's solve means: the carriage's motion, the ground reactions, stability, planar energies.

From the samples of the gun's tree (:mod:`mbs_models.engine.planar`: ``q = (X, Y, phi, x_1 .. x_n)`` and their
rates), with the geometry and the support law of :mod:`mbs_models.elements.carriage` (the same law the solver
applied, evaluated at the samples' states):

* ``carriage_position`` (CG x, y, m) ``= (X, Y) + R(phi) c`` and ``carriage_pitch`` ``phi`` (rad);
* per support: ``normal_force`` N (N, >= 0), ``tangential_force`` T (N, + = forward, on the carriage) and
  ``height`` ``y = Y + x_s sin(phi) + y_s cos(phi)`` (m; < 0: pressed into the ground);
* the metrics of DESIGN.md: ``max_carriage_pitch = max |phi - phi_static|`` (rad), ``max_lift = max(0, max y)``
  (m), ``lift_off_time`` (s, the first time after t = 0 that a support carrying load at rest has N = 0, None if never),
  ``max_carriage_displacement = max |x_cg - x_cg_static|`` (m) and ``stability_margin = min N_i(t) / N_i(static)``;
* planar energies: kinetic ``T = sum_k (m_k |v_k|^2 + I_k phi'^2) / 2`` with each CG's absolute velocity, gravity's
  potential ``sum_k m_k g (y_k - y_k(0))``, each support's stored (:func:`~mbs_models.elements.carriage.support_stored_energy`)
  and dissipated energy (``integral -(T u + N y') dt - (U - U(0))``, Gauss quadrature on the Hermite-interpolated
  state) and the work of a load on its body, ``integral F (x_i' - v_c . e') dt`` (its power ``Q . q'``).

The maxima of the motion (``max_carriage_pitch``, ``max_lift``, ``max_carriage_displacement``) are refined on
the cubic Hermite interpolant of the carriage's coordinates between the samples (:mod:`mbs_models.results.peaks`),
as the 1-D metrics are: the presets' maximum step leaves samples far apart where the carriage moves slowly.  The
support forces' minima (the stability margin) and the lift-off are taken at the output samples (the support
forces vary on the carriage's time scales, not an impact's; stated, and compared with the reference).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..elements.carriage import (AxisBody, StaticState, elevation_of, gravity_of, static_equilibrium,
                                 support_normal_force, support_stored_energy, support_tangential_force)
from ..elements.ops import NUMPY_OPS
from ..errors import SimulationError
from .energies import _GL_NODES, cumulative_quadrature
from .peaks import refine_function_maximum, refine_maximum
from .samples import Interpolant, Samples

_COORDINATES = ("carriage_x", "carriage_y", "carriage_pitch")


@dataclass(frozen=True)
class SupportOutput:
    """One support's histories (at the samples) and its loads (N): static, smallest and largest normal force."""

    name: str
    normal_force: np.ndarray
    tangential_force: np.ndarray
    height: np.ndarray
    static_normal_force: float
    min_normal_force: float
    max_normal_force: float

    def to_dict(self) -> dict:
        return {"name": self.name, "static_normal_force": self.static_normal_force,
                "min_normal_force": self.min_normal_force, "max_normal_force": self.max_normal_force}


@dataclass(frozen=True)
class CarriageOutput:
    """The carriage's histories and metrics (module docstring)."""

    position: np.ndarray
    pitch: np.ndarray
    static_pitch: float
    supports: dict[str, SupportOutput]
    max_carriage_pitch: float
    max_lift: float
    lift_off_time: float | None
    max_carriage_displacement: float
    stability_margin: float
    energies: dict = field(default_factory=dict)

    def metrics(self) -> dict:
        return {"max_carriage_pitch": self.max_carriage_pitch, "max_lift": self.max_lift,
                "lift_off_time": self.lift_off_time, "max_carriage_displacement": self.max_carriage_displacement,
                "stability_margin": self.stability_margin}


#: The scalar metrics of a carriage scene (top-level keys of ``--json``, sweep columns).
CARRIAGE_METRICS = ("max_carriage_pitch", "max_lift", "lift_off_time", "max_carriage_displacement",
                    "stability_margin")


class PlanarGeometry:
    """The geometry of a scene's gun as arrays: every CG and support point from the tree coordinates."""

    def __init__(self, mechanism):
        scene = mechanism.scene
        self.scene, self.carriage = scene, scene.carriage
        self.theta, self.gravity = elevation_of(scene), gravity_of(scene)
        inertia = self.carriage.barrel_inertia
        self.bodies = [AxisBody(b.name, b.mass, inertia if i == 0 else 0.0, b.initial_position)
                       for i, b in enumerate(mechanism.bodies)]
        self.e = np.array([math.cos(self.theta), math.sin(self.theta)])

    def static(self) -> StaticState:
        return static_equilibrium(self.carriage, self.theta, self.gravity, self.bodies)

    @staticmethod
    def _place(X, Y, phi, a):
        """World point and its derivative by phi of carriage-frame points ``a`` (arrays of x, y)."""
        c, s = np.cos(phi), np.sin(phi)
        return X + c * a[0] - s * a[1], Y + s * a[0] + c * a[1], -s * a[0] - c * a[1], c * a[0] - s * a[1]

    def point(self, q: dict, r):
        """World position (x, y) of the carriage-frame point ``r``."""
        x, y, _, _ = self._place(q["carriage_x"], q["carriage_y"], q["carriage_pitch"], (r[0], r[1]))
        return x, y

    def point_velocity(self, q: dict, v: dict, r):
        """World velocity (u, w) of the carriage-frame point ``r``."""
        _, _, dx, dy = self._place(q["carriage_x"], q["carriage_y"], q["carriage_pitch"], (r[0], r[1]))
        return v["carriage_x"] + dx * v["carriage_pitch"], v["carriage_y"] + dy * v["carriage_pitch"]

    def body_state(self, q: dict, v: dict, name: str):
        """An axis body's CG (x, y) and velocity (u, w) (m, m/s)."""
        along = self.carriage.barrel_center_of_mass - q[name]
        a = (self.carriage.trunnion[0] + along * self.e[0], self.carriage.trunnion[1] + along * self.e[1])
        x, y, dx, dy = self._place(q["carriage_x"], q["carriage_y"], q["carriage_pitch"], a)
        phi = q["carriage_pitch"]
        c, s = np.cos(phi), np.sin(phi)
        rear = (-(c * self.e[0] - s * self.e[1]), -(s * self.e[0] + c * self.e[1]))  # d r / d x_i = -R e
        u = v["carriage_x"] + dx * v["carriage_pitch"] + rear[0] * v[name]
        w = v["carriage_y"] + dy * v["carriage_pitch"] + rear[1] * v[name]
        return x, y, u, w, rear

    def kinetic(self, q: dict, v: dict) -> dict:
        """Kinetic energy (J) of the carriage and of each axis body (absolute velocities)."""
        cu, cw = self.point_velocity(q, v, self.carriage.center_of_mass)
        out = {"carriage": 0.5 * self.carriage.mass * (cu ** 2 + cw ** 2)
                           + 0.5 * self.carriage.inertia * v["carriage_pitch"] ** 2}
        for body in self.bodies:
            _, _, u, w, _ = self.body_state(q, v, body.name)
            out[body.name] = 0.5 * body.mass * (u ** 2 + w ** 2) + 0.5 * body.inertia * v["carriage_pitch"] ** 2
        return out


def coordinate_samples(s: Samples) -> Samples:
    """The carriage's three coordinates as Samples (for their Hermite interpolation)."""
    return Samples(time=s.time, positions={k: s.planar[f"{k}_position"] for k in _COORDINATES},
                   velocities={k: s.planar[f"{k}_velocity"] for k in _COORDINATES},
                   accelerations={k: s.planar[f"{k}_acceleration"] for k in _COORDINATES})


def carriage_output(mechanism, s: Samples, interp: Interpolant, energies=None) -> CarriageOutput:
    """The carriage's histories and metrics from a solve's samples (module docstring); with ``energies`` (the
    1-D :class:`~mbs_models.results.energies.Energies` of the same samples), they are made planar in place:
    kinetic energies of absolute velocities, gravity's potential, the supports' stored and dissipated energy and the
    loads' planar work."""
    geometry = PlanarGeometry(mechanism)
    static = geometry.static()
    carriage = geometry.carriage
    q = {k: s.planar[f"{k}_position"] for k in _COORDINATES}
    v = {k: s.planar[f"{k}_velocity"] for k in _COORDINATES}
    q.update(s.positions)
    v.update(s.velocities)
    cg = np.column_stack(geometry.point(q, carriage.center_of_mass))
    static_cg = geometry.point({"carriage_x": 0.0, "carriage_y": static.height, "carriage_pitch": static.pitch},
                               carriage.center_of_mass)
    supports = {}
    for support in carriage.supports:  # the law at the samples' states: the forces the solver applied there
        x, height = geometry.point(q, support.position)
        u, w = geometry.point_velocity(q, v, support.position)
        lam = s.planar.get(f"support_{support.name}_lam")
        normal = np.asarray(support_normal_force(support, height, w, NUMPY_OPS, lam), dtype=float)
        anchor = s.planar.get(f"support_{support.name}_anchor", static.anchors[support.name])
        tangential = np.asarray(support_tangential_force(support, normal, x, u, anchor, NUMPY_OPS, height),
                                dtype=float) + 0.0 * normal
        load = static.loads[support.name]
        supports[support.name] = SupportOutput(support.name, normal, tangential, np.asarray(height),
                                               static_normal_force=load, min_normal_force=float(np.min(normal)),
                                               max_normal_force=float(np.max(normal)))
    t = s.time
    lift_off = None
    for output in supports.values():
        if not output.static_normal_force > 0.0:  # carried nothing at rest: it cannot leave the ground
            continue
        off = np.flatnonzero((output.normal_force <= 0.0) & (t > 0.0))
        if len(off):
            lift_off = float(t[off[0]]) if lift_off is None else min(lift_off, float(t[off[0]]))
    with np.errstate(all="ignore"):
        margin = min(o.min_normal_force / o.static_normal_force if o.static_normal_force > 0 else math.inf
                     for o in supports.values())
    if not math.isfinite(margin):
        loads = ", ".join(f"{o.name} {o.static_normal_force:.3g} N" for o in supports.values())
        raise SimulationError(f"the stability margin (least load / static load) is beyond double precision: the "
                              f"static loads ({loads}) are too small against the loads of the run")
    coordinates = Interpolant(coordinate_samples(s))

    def refined(sampled: np.ndarray, of_time) -> float:
        """The largest |value| of a sampled quantity, refined near its largest sample on ``of_time(t)`` (the same
        quantity on the interpolated coordinates, sign included)."""
        k = int(np.argmax(np.abs(sampled)))
        sign = 1.0 if sampled[k] >= 0 else -1.0
        value, _ = refine_function_maximum(lambda times: sign * of_time(coordinates.state(times)[0]), t, k)
        return float(max(abs(sampled[k]), value))

    pitch = np.asarray(q["carriage_pitch"]) - static.pitch
    rate = np.asarray(v["carriage_pitch"])
    max_pitch = max(refine_maximum(t, pitch, rate)[0], refine_maximum(t, -pitch, -rate)[0])
    lifts = [refined(np.maximum(o.height, 0.0), lambda c, r=support.position: geometry.point(c, r)[1])
             for o, support in zip(supports.values(), carriage.supports)]
    displacement = refined(cg[:, 0] - static_cg[0],
                           lambda c: geometry.point(c, carriage.center_of_mass)[0] - static_cg[0])
    output = CarriageOutput(position=cg, pitch=np.asarray(q["carriage_pitch"]), static_pitch=static.pitch,
                            supports=supports, max_carriage_pitch=float(max_pitch),
                            max_lift=float(max(0.0, *lifts)), lift_off_time=lift_off,
                            max_carriage_displacement=displacement, stability_margin=float(margin))
    if energies is not None:
        _planar_energies(mechanism, geometry, static, s, interp, q, v, supports, energies)
    return output


def _planar_energies(mechanism, geometry, static, s, interp, q, v, supports, energies) -> None:
    """Make the 1-D energies of a carriage scene planar, in place (:func:`carriage_output`)."""
    t = s.time
    nodes_t = t[:-1] + _GL_NODES[:, None] * np.diff(t)
    coordinates = Interpolant(coordinate_samples(s))
    cq, cv = coordinates.at_fractions(_GL_NODES)
    bq, bv = interp.at_fractions(_GL_NODES)
    qn, vn = {**cq, **bq}, {**cv, **bv}
    kinetic = geometry.kinetic(q, v)
    energies.kinetic.clear()
    energies.kinetic.update(kinetic)
    zero_v = {k: 0.0 * val for k, val in v.items()}
    potential = _potential(geometry, q, zero_v)
    energies.stored["gravity"] = potential - potential[0]
    for support in geometry.carriage.supports:
        anchor = s.planar.get(f"support_{support.name}_anchor", static.anchors[support.name])
        x, height = geometry.point(q, support.position)
        stored = support_stored_energy(support, height, x, anchor)
        xn, yn = geometry.point(qn, support.position)
        un, wn = geometry.point_velocity(qn, vn, support.position)
        lam = s.planar.get(f"support_{support.name}_lam")
        normal = support_normal_force(support, yn, wn, NUMPY_OPS, None if lam is None else np.asarray(lam)[1:])
        anchor_n = anchor if np.ndim(anchor) == 0 else np.asarray(anchor)[1:]  # the step's: set at its start
        tangential = support_tangential_force(support, normal, xn, un, anchor_n, NUMPY_OPS, yn)
        power = -(tangential * un + normal * wn)  # into the support
        key = f"support.{support.name}"
        energies.stored[key] = stored
        energies.dissipated[key] = cumulative_quadrature(t, power) - (stored - stored[0])
    for load in mechanism.loads:
        _, _, un, wn, rear = geometry.body_state(qn, vn, load.body)
        speed = un * rear[0] + wn * rear[1]  # the body's absolute velocity along its rearward axis
        energies.work[load.name] = cumulative_quadrature(t, load.force(nodes_t) * speed)
    for t_shot, body, _ in mechanism.impulses:  # a shot's work: the jump of the planar kinetic energy
        name = mechanism.impulse_element[(t_shot, body)]
        if name not in energies.work:
            continue
        history = np.zeros_like(t)
        total = sum(kinetic.values())
        for j in np.flatnonzero((t[:-1] == t_shot) & (t[1:] == t_shot)) + 1:
            history[j:] += total[j] - total[j - 1]
        energies.work[name] = history


def _potential(geometry: PlanarGeometry, q: dict, zero_v: dict):
    """``sum m g y`` (J) of every body at the samples."""
    _, y = geometry.point(q, geometry.carriage.center_of_mass)
    total = geometry.carriage.mass * geometry.gravity * np.asarray(y)
    for body in geometry.bodies:
        _, yb, _, _, _ = geometry.body_state(q, zero_v, body.name)
        total = total + body.mass * geometry.gravity * yb
    return total
