"""Numerical safety of a solve: the contact's time scales, solver-setting checks, stepped-over contacts.

Three questions, answered from the scene alone (before the solve) or from the step data (after it):

1. **How fast is each contact?**  :func:`estimate_contacts` linearises each contact's law at the
   expected maximum penetration: the undamped impact of the reduced mass of its two bodies
   (``m_red = M m / (M + m)``; the body's mass against the ground) at the approach speed ``v_imp``
   (the initial barrel speed v0: the absorbers start at rest, and across the hard-case grid no later
   impact approached faster) stops at ``p = ((n+1) m_red v_imp^2 / (2 k))^(1/(n+1))`` (n = 1 for
   Kelvin-Voigt).  There the contact has the tangent stiffness ``n k p^(n-1)``, the damping
   ``lambda k p^n`` (``c`` for Kelvin-Voigt; ``lambda = chi / v_imp`` for the restitution laws) and the
   natural frequency ``omega = sqrt(n k p^(n-1) / m_red)``; the impact lasts ``T = 2 (p / v_imp) I(n)``,
   ``I(n) = int_0^1 ds / sqrt(1 - s^(n+1))`` (``pi / omega`` for n = 1).  A hard bound is reported
   too: the elastic contact energy never exceeds the initial energy ``E0``, so
   ``p <= ((n+1) E0 / k)^(1/(n+1))`` (unless the ``literal_lambda_sign`` convention injects energy).
   :func:`estimate_contact` is the fastest contact's estimate.

2. **Is a solver setting safe?**  :func:`check_settings` (called by :func:`~mbs_models.simulate`
   before solving) linearises the whole mechanism, out of contact and in contact at ``p``, ``p/2``,
   ``p/4`` and ``p/16`` (with the penetration rate of the undamped impact there), and applies the
   one-step amplification of the chosen Exudyn solver (its stability polynomial, checked against
   Exudyn in ``tests/test_stability.py``).  For a fixed-step solver:

   * a step that amplifies the linearised motion by more than 1 % over the run (unstable), or that
     gives an impact fewer than :data:`MIN_STEPS_PER_CONTACT` steps (even an implicit solver then
     steps over the contact), raises :class:`~mbs_models.errors.SceneError` (key ``"step"``) with the
     reason and the safe limit: such runs blow up or return garbage (measured in the tests);
   * a step that gives an impact fewer than :data:`STEPS_PER_CONTACT` steps warns
     (:class:`AccuracyWarning`) with the step that would;
   * a step or ``max_step`` needing more than :data:`MAX_STEPS` steps raises: the run would not end.

   Adaptive solvers control their own step; what they can still do is step over a *whole* short
   contact (a grazing touch) between two stages.  That is checked after the solve (point 3).

3. **Was a contact stepped over?**  :func:`stepped_over_contacts` looks at every output interval in
   which the contact force is 0 at both ends and the bodies are apart at both ends, and finds the
   largest penetration of the cubic Hermite interpolant of the relative motion inside it: a positive
   value means the free motion crosses wall A between two steps -- a contact the solver never felt.
   :func:`~mbs_models.simulate` then re-solves with a smaller ``max_step`` (adaptive) or raises
   :class:`~mbs_models.errors.SimulationError` (fixed step).

4. **Was a contact only grazed?**  A contact whose deepest penetration is a tiny fraction of its bodies'
   displacement (:func:`grazed_contacts`: below :data:`GRAZING_PENETRATION_RATIO` of the largest |x| of
   its two bodies) has a peak force ``k p^n`` whose relative error is ``n`` times the position error over
   ``p``: the positions' error, which the tolerances bound relative to |x|, decides it.  The step-end
   samples of the presets' large maximum step leave that error near the tolerance where the motion is slow
   (the barrel turning at the absorber); :func:`~mbs_models.simulate` re-solves such a run once with a
   maximum step of at most :data:`GRAZING_MAX_STEP`, at which the hard cases' grazes meet the guarantee.

Finally :func:`check_energy_balance` refuses (SimulationError) a solve whose energy balance is off by
more than :data:`ENERGY_FAILURE` of the initial energy, whatever the settings were.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..elements.connector import GROUND
from ..errors import SceneError
from ..scene import Scene
from .accuracy import ADAPTIVE_SOLVERS, IMPLICIT_SOLVERS, SolverSettings
from .mechanism import Mechanism

#: A fixed-step solver should resolve an impact with at least this many steps (else a warning) ...
STEPS_PER_CONTACT = 10
#: ... and must give it at least this many (else SceneError: the contact would be stepped over).
MIN_STEPS_PER_CONTACT = 2
#: A solve whose energy balance is off by more than this fraction of the initial energy is refused ...
ENERGY_FAILURE = 0.1
#: ... and one off by more than this fraction gets an AccuracyWarning.
ENERGY_WARNING = 0.01
#: Largest tolerated amplification of the linearised motion over a whole run (1 %).
GROWTH_TOLERANCE = 0.01
#: More steps than this (end_time / step) are refused: the run would not finish in reasonable time.
MAX_STEPS = 100_000_000
#: A stepped-over contact matters when its free-motion peak force exceeds this fraction of the
#: impact threshold (and its penetration exceeds :data:`PENETRATION_NOISE`).
MISSED_CONTACT_FORCE_FRACTION = 0.01
#: Penetrations below this (m) are round-off of positions of order 1 m, not contacts.
PENETRATION_NOISE = 1e-12
#: A touched contact is *grazed* when its deepest penetration is below this fraction of the largest |x| (m) of
#: its two bodies over the run (point 4 of the module docstring).
GRAZING_PENETRATION_RATIO = 1e-4
#: The largest ``max_step`` (s) of the re-solve of a run with a grazed contact.
GRAZING_MAX_STEP = 5e-3
#: Penetration depths (fractions of the expected penetration) at which the contact is linearised.
_LINEARISATION_DEPTHS = (1.0, 0.5, 0.25, 0.0625)

# One-step amplification of Exudyn's explicit Runge-Kutta solvers for y' = lambda y: a polynomial
# R(z), coefficients in increasing powers.  RK67 is not the Taylor polynomial: its z^7 coefficient
# was measured on Exudyn 1.13.6 (tests/test_stability.py checks every entry against Exudyn).
_RK_POLYNOMIALS: dict[str, tuple[float, ...]] = {
    "ExplicitEuler": (1.0, 1.0),
    "ExplicitMidpoint": (1.0, 1.0, 1.0 / 2),
    "RK33": (1.0, 1.0, 1.0 / 2, 1.0 / 6),
    "RK44": (1.0, 1.0, 1.0 / 2, 1.0 / 6, 1.0 / 24),
    "RK67": (1.0, 1.0, 1.0 / 2, 1.0 / 6, 1.0 / 24, 1.0 / 120, 1.0 / 720, -4.4945388576386e-4),
}


class AccuracyWarning(UserWarning):
    """A setting is stable but too coarse to resolve the contact: the results may be inaccurate."""


@dataclass(frozen=True)
class ContactEstimate:
    """Time scales of the contact, estimated from the scene (SI units; see the module docstring).

    Attributes
    ----------
    energy: the initial energy E0 in J (kinetic + elastic contact energy of an initial interference; every
        stored energy counted by its magnitude: :meth:`~mbs_models.engine.mechanism.Mechanism.energy_scale`).
    reduced_mass: M m / (M + m) in kg.
    impact_speed: approach speed of the estimate in m/s (v0, plus what an initial interference adds).
    penetration: maximum penetration of the undamped impact at ``impact_speed``, in m.
    max_penetration: hard energy bound on the penetration, in m.
    stiffness: tangent stiffness n k_c p^(n-1) at ``penetration``, in N/m.
    damping: Hunt-Crossley damping lambda k_c p^n at ``penetration``, in N s/m.
    natural_frequency: sqrt(stiffness / reduced_mass) in rad/s.
    duration: duration of the undamped impact at ``impact_speed``, in s.
    """

    energy: float
    reduced_mass: float
    impact_speed: float
    penetration: float
    max_penetration: float
    stiffness: float
    damping: float
    natural_frequency: float
    duration: float

    def describe(self) -> str:
        """One line for messages."""
        return (f"contact natural frequency ~{self.natural_frequency:.3g} rad/s and duration ~{self.duration:.3g} s "
                f"(Hunt-Crossley linearised at the penetration {self.penetration:.3g} m of an impact at "
                f"{self.impact_speed:.3g} m/s)")


def _duration_integral(n: float) -> float:
    """I(n) = int_0^1 ds / sqrt(1 - s^(n+1)) = sqrt(pi) Gamma(1 + 1/(n+1)) / Gamma(1/2 + 1/(n+1))."""
    a = 1.0 / (n + 1.0)
    return math.sqrt(math.pi) * math.gamma(1.0 + a) / math.gamma(0.5 + a)


def initial_energy(scene: Scene) -> float:
    """Energy at t = 0 in J: kinetic, plus the stored energy of an initial interference."""
    return Mechanism(scene).initial_energy()


def _mechanism(scene) -> Mechanism:
    return scene if isinstance(scene, Mechanism) else Mechanism(scene)


def _reduced_mass(mechanism: Mechanism, connector) -> float:
    masses = [mechanism.bodies[mechanism.body_index[p]].mass for p in (connector.a, connector.b) if p != GROUND]
    return masses[0] if len(masses) == 1 else masses[0] * masses[1] / (masses[0] + masses[1])


def estimate_contacts(scene: Scene | Mechanism) -> dict[str, ContactEstimate]:
    """Each contact's penetration, stiffness, frequency and duration (see the module docstring), by name."""
    mechanism = _mechanism(scene)
    out = {}
    # the kinetic energy plus every initial stored energy's magnitude: the initial energy itself unless a
    # potential is negative at t = 0 (a gas spring's preload holding the barrel into a stop), where it may be
    # negative while the contact holds an interference's energy
    energy = mechanism.energy_scale()
    v0 = mechanism.scene.initial_velocity
    firing = getattr(mechanism.scene, "firing", None)
    if firing is not None and firing.pulse is not None:  # the barrel starts at rest: the pulse's momentum
        v0 = firing.shot_momentum / mechanism.scene.barrel.mass
        energy += 0.5 * mechanism.scene.barrel.mass * v0 ** 2
    for contact in mechanism.contacts:
        n, k = contact.exponent, contact.contact_stiffness
        m_red = _reduced_mass(mechanism, contact)
        interference = float(contact.stored_energy(mechanism.initial_relative(contact)))
        speed = math.sqrt(v0 ** 2 + 2.0 * interference / m_red)
        bound = ((n + 1.0) * energy / k) ** (1.0 / (n + 1.0))
        p = min(contact.impact_penetration(m_red, speed), bound)
        if p <= 0.0:  # nothing moves: a scene at rest never touches
            out[contact.name] = ContactEstimate(energy=energy, reduced_mass=m_red, impact_speed=0.0, penetration=0.0,
                                                max_penetration=bound, stiffness=0.0, damping=0.0,
                                                natural_frequency=0.0, duration=math.inf)
            continue
        stiffness = n * k * p ** (n - 1.0)
        _, damping = contact.tangent(p, 0.0, speed)
        out[contact.name] = ContactEstimate(
            energy=energy, reduced_mass=m_red, impact_speed=speed, penetration=p, max_penetration=bound,
            stiffness=stiffness, damping=damping, natural_frequency=math.sqrt(stiffness / m_red),
            duration=2.0 * p / speed * _duration_integral(n))
    return out


def estimate_contact(scene: Scene | Mechanism) -> ContactEstimate | None:
    """The fastest contact's estimate (the shortest impact); None for a scene without contact."""
    estimates = estimate_contacts(scene)
    if not estimates:
        return None
    return min(estimates.values(), key=lambda e: e.duration)


# ------------------------------------------------------------------------------------------------
# Linearised mechanism

def linearised_systems(scene: Scene | Mechanism) -> list[tuple[str, np.ndarray]]:
    """State matrices ``A`` (x' = A x, x = [positions, velocities]) of the linearised mechanism.

    One out of contact (every spring and damper; an asymmetric damper with its larger coefficient), and
    for each contact in turn one in contact at each depth of :data:`_LINEARISATION_DEPTHS` times its
    expected penetration (:func:`estimate_contacts`).  Returns ``(label, A)`` pairs.
    """
    mechanism = _mechanism(scene)
    masses = mechanism.masses
    n = len(masses)
    base_k = np.zeros((n, n))
    base_c = np.zeros((n, n))
    for connector in mechanism.connectors:
        if connector.is_contact:
            continue
        g = mechanism.direction(connector)
        base_k += connector.linear_stiffness * np.outer(g, g)
        base_c += connector.linear_damping * np.outer(g, g)

    def state_matrix(K, C):
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -K / masses[:, None]
        A[n:, n:] = -C / masses[:, None]
        return A

    systems = [("free", state_matrix(base_k, base_c))]
    estimates = estimate_contacts(mechanism)
    several = len(estimates) > 1
    for contact in mechanism.contacts:
        estimate = estimates[contact.name]
        g = mechanism.direction(contact)
        for depth in _LINEARISATION_DEPTHS if estimate.penetration > 0 else ():
            # on the undamped impact at this depth the penetration rate is v_imp sqrt(1 - depth^(n+1))
            p = depth * estimate.penetration
            rate = estimate.impact_speed * math.sqrt(max(0.0, 1.0 - depth ** (contact.exponent + 1.0)))
            k_lin, c_lin = contact.tangent(p, rate, estimate.impact_speed)
            label = f"{contact.name} in contact at p = {p:.3g} m" if several else f"in contact at p = {p:.3g} m"
            systems.append((label, state_matrix(base_k + k_lin * np.outer(g, g), base_c + c_lin * np.outer(g, g))))
    return systems


def fastest_rate(scene: Scene) -> float:
    """Largest |eigenvalue| (1/s) of the linearised mechanism, in or out of contact."""
    return max(float(np.max(np.abs(np.linalg.eigvals(A)))) for _, A in linearised_systems(scene))


def amplification(solver: str, A: np.ndarray, step: float) -> float:
    """Spectral radius of the one-step propagation matrix of ``solver`` for x' = A x at ``step`` s.

    Explicit Runge-Kutta solvers: ``max |R(step * eig(A))|``; ``VelocityVerlet`` (Exudyn's
    kick-drift-kick with the force at the half-step velocity): its 2x2-block propagation matrix.
    Implicit solvers are A-stable: 1.
    """
    if solver in _RK_POLYNOMIALS:
        z = step * np.linalg.eigvals(A)
        coefficients = _RK_POLYNOMIALS[solver]
        return float(np.max(np.abs(np.polynomial.polynomial.polyval(z, coefficients))))
    if solver == "VelocityVerlet":
        n = A.shape[0] // 2
        Kq, Kv = A[n:, :n], A[n:, n:]  # acceleration = Kq q + Kv v
        identity = np.eye(n)
        # v_half = v + h/2 a(q, v); q1 = q + h v_half; v1 = v_half + h/2 a(q1, v_half)
        half = np.hstack([step / 2 * Kq, identity + step / 2 * Kv])
        q1 = np.hstack([identity, np.zeros((n, n))]) + step * half
        v1 = half + step / 2 * (Kq @ q1 + Kv @ half)
        return float(np.max(np.abs(np.linalg.eigvals(np.vstack([q1, v1])))))
    return 1.0


def _growth_ok(solver: str, systems, step: float, end_time: float) -> bool:
    steps = max(1.0, end_time / step)
    allowed = math.log1p(GROWTH_TOLERANCE) / steps
    return all(math.log(max(amplification(solver, A, step), 1e-300)) <= allowed for _, A in systems)


def stable_step_limit(scene: Scene, solver: str, end_time: float) -> float:
    """Largest fixed step (s) for which ``solver`` amplifies the linearised mechanism by at most
    :data:`GROWTH_TOLERANCE` over ``end_time``; ``inf`` for implicit and adaptive solvers."""
    if solver in IMPLICIT_SOLVERS or solver in ADAPTIVE_SOLVERS:
        return math.inf
    systems = linearised_systems(scene)
    grid = np.geomspace(1e-10, 1.0, 201)
    ok = [_growth_ok(solver, systems, h, end_time) for h in grid]
    if not ok[0]:
        return 0.0
    if all(ok):
        return float(grid[-1])
    first_bad = ok.index(False)
    lo, hi = float(grid[first_bad - 1]), float(grid[first_bad])
    for _ in range(40):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if _growth_ok(solver, systems, mid, end_time) else (lo, mid)
    return lo


def contact_step_limits(scene: Scene) -> tuple[float, float]:
    """(hard, recommended) largest fixed steps (s) for the contact: an impact
    (:attr:`ContactEstimate.duration`) resolved by :data:`MIN_STEPS_PER_CONTACT` and by
    :data:`STEPS_PER_CONTACT` steps; ``inf`` without contact."""
    estimate = estimate_contact(scene)
    if estimate is None:
        return math.inf, math.inf
    return estimate.duration / MIN_STEPS_PER_CONTACT, estimate.duration / STEPS_PER_CONTACT


def safe_step_limit(scene: Scene, solver: str, end_time: float) -> tuple[float, str]:
    """Largest safe fixed step (s) of ``solver`` for ``scene`` over ``end_time`` s, and why.

    The smaller of the stability limit (:func:`stable_step_limit`) and the step that still puts
    :data:`MIN_STEPS_PER_CONTACT` steps into an impact -- beyond it even an implicit solver steps over
    the contact and returns garbage.
    """
    stable = stable_step_limit(scene, solver, end_time)
    resolved, _ = contact_step_limits(scene)
    if stable <= resolved:
        return stable, (f"it would amplify the linearised motion by more than {GROWTH_TOLERANCE:.0%} over "
                        f"{end_time:g} s (fastest rate {fastest_rate(scene):.3g} 1/s)")
    return resolved, f"an impact would get fewer than {MIN_STEPS_PER_CONTACT} steps"


def check_settings(scene: Scene, settings: SolverSettings, end_time: float) -> None:
    """Refuse settings that cannot give a valid result; warn about ones that resolve contacts poorly.

    Raises :class:`SceneError` (key ``"step"`` or ``"max_step"``) with the reason and the safe limit;
    warns with :class:`AccuracyWarning`.  See the module docstring (point 2).
    """
    if settings.adaptive:
        if end_time / settings.max_step > MAX_STEPS:
            raise SceneError("max_step", f"{settings.max_step:g} s over {end_time:g} s would take more than "
                                         f"{MAX_STEPS:.0e} steps; use max_step >= {end_time / MAX_STEPS:.3g} s")
        return
    step = settings.step
    if end_time / step > MAX_STEPS:
        raise SceneError("step", f"{step:g} s over {end_time:g} s would take more than {MAX_STEPS:.0e} steps; "
                                 f"use step >= {end_time / MAX_STEPS:.3g} s")
    estimate = estimate_contact(scene)
    scales = f"; {estimate.describe()}" if estimate is not None else ""
    limit, reason = safe_step_limit(scene, settings.solver, end_time)
    if step > limit:
        raise SceneError("step", f"{settings.solver} with step {step:g} s is unsafe for this scene: {reason}"
                                 f"{scales}; the safe limit is step <= {limit:.3g} s (or use an adaptive solver, DOPRI5)")
    _, recommended = contact_step_limits(scene)
    if step > recommended:
        warnings.warn(f"{settings.solver} with step {step:g} s resolves an impact with fewer than {STEPS_PER_CONTACT} "
                      f"steps: peak forces and impacts may be inaccurate; use step <= {recommended:.3g} s{scales}",
                      AccuracyWarning, stacklevel=3)


def check_energy_balance(scene: Scene, time: np.ndarray, error: np.ndarray, solver_label: str,
                         energy_scale: float | None = None) -> None:
    """Refuse a solve whose energy balance (``error`` in J at ``time``) is off by more than
    :data:`ENERGY_FAILURE` of the initial energy: its numbers would be garbage.  Warn (AccuracyWarning)
    above :data:`ENERGY_WARNING`.  ("The initial energy" is :meth:`Mechanism.energy_scale`: the initial
    kinetic energy plus the magnitude of every initial stored energy, which is the initial energy
    unless a preload makes a potential negative at t = 0; ``energy_scale`` J where external inputs add
    energy: that plus the largest work done.)"""
    from ..errors import SimulationError

    energy = max(_mechanism(scene).energy_scale() if energy_scale is None else energy_scale, 1e-300)
    relative = np.abs(np.asarray(error, dtype=float)) / energy
    k = int(np.argmax(relative))
    worst = float(relative[k])
    if not worst <= ENERGY_FAILURE:
        raise SimulationError(f"{solver_label}: the energy balance is off by {worst:.3g} of the initial energy at "
                              f"t = {time[k]:.6g} s (kinetic + stored + dissipated must equal the initial energy): "
                              "the solve did not resolve the dynamics; use a smaller step or tighter tolerances")
    if worst > ENERGY_WARNING:
        warnings.warn(f"{solver_label}: the energy balance is off by {worst:.3g} of the initial energy at "
                      f"t = {time[k]:.6g} s; results are inaccurate at that level", AccuracyWarning, stacklevel=3)


# ------------------------------------------------------------------------------------------------
# After the solve: contacts stepped over

@dataclass(frozen=True)
class SteppedOverContact:
    """A penetration of the free motion between two output samples that the solver did not feel.

    start, end (s): the output interval; time (s) and penetration (m) of the deepest point of the
    interpolated free motion; peak_force (N): the force that penetration would give (without damping);
    duration (s): how long the interpolated free motion stays penetrated.
    """

    start: float
    end: float
    time: float
    penetration: float
    peak_force: float
    duration: float


def _cubic_coefficients(y0, y1, d0, d1):
    """Coefficients (a, b, c, d) of the Hermite cubic a s^3 + b s^2 + c s + d on s in [0, 1] with end values
    y0, y1 and end slopes (per unit s) d0, d1."""
    return 2 * y0 + d0 - 2 * y1 + d1, -3 * y0 - 2 * d0 + 3 * y1 - d1, d0, y0


def _may_exceed_noise(y0, y1, d0, d1) -> np.ndarray:
    """False where the Hermite cubic with end values y0, y1 and end slopes d0, d1 (per unit s) surely stays at
    or below :data:`PENETRATION_NOISE` on [0, 1], also as evaluated in floating point.

    The cubic is ``H00 y0 + H01 y1 + H10 d0 + H11 d1`` with ``H00 + H01 = 1`` (both in [0, 1]) and
    ``|H10|, |H11| <= 4/27``, so it never exceeds ``max(y0, y1) + 4/27 (|d0| + |d1|)``; its evaluation
    through the coefficients of :func:`_cubic_coefficients` and Horner's rule adds less than 1e-14 of
    ``M = |y0| + |y1| + |d0| + |d1|``.  The test ``max(y0, y1) + (|d0| + |d1|) / 4 + 1e-12 M > noise / 2``
    keeps a margin far above both, so every interval it drops would have given a value <= the noise.
    """
    spread = np.abs(d0) + np.abs(d1)
    size = np.abs(y0) + np.abs(y1) + spread
    return np.maximum(y0, y1) + 0.25 * spread + 1e-12 * size > 0.5 * PENETRATION_NOISE


def stepped_over_contacts(contact, time: np.ndarray, relative_position: np.ndarray,
                          relative_velocity: np.ndarray, contact_force: np.ndarray,
                          impact_threshold: float) -> list[SteppedOverContact]:
    """Contacts the solver stepped over: see the module docstring (point 3).

    ``contact`` is a contact connector (or a scene with one absorber: its contact);
    ``relative_position`` is its d (m; x_M - x_m for an absorber), ``relative_velocity`` its rate
    (m/s), at the output times ``time`` (s); ``contact_force`` the force (N) the solver recorded there.
    Only touches whose free-motion peak force exceeds ``MISSED_CONTACT_FORCE_FRACTION * impact_threshold``
    and whose penetration exceeds :data:`PENETRATION_NOISE` are reported.  The intervals whose cubic
    surely stays below the noise (:func:`_may_exceed_noise`: nearly all of them) are not searched.
    """
    if isinstance(contact, Scene):
        contacts = Mechanism(contact).absorber_contacts
        if not contacts:
            return []
        contact = contacts[0]
    if len(time) < 2:
        return []
    penetration = contact.penetration(np.asarray(relative_position, dtype=float))
    apart = (contact_force <= 0) & (penetration <= 0)
    quiet = np.flatnonzero(apart[:-1] & apart[1:])  # force 0 and bodies apart at both ends
    h = time[quiet + 1] - time[quiet]
    y0, y1 = penetration[quiet], penetration[quiet + 1]
    d0, d1 = relative_velocity[quiet] * h, relative_velocity[quiet + 1] * h
    searched = np.flatnonzero(_may_exceed_noise(y0, y1, d0, d1))
    if not len(searched):
        return []
    candidates, h = quiet[searched], h[searched]
    a, b, c, d = _cubic_coefficients(y0[searched], y1[searched], d0[searched], d1[searched])
    # maximum of the cubic on (0, 1): roots of 3a s^2 + 2b s + c, in the cancellation-free form
    # q = -(B + sign(B) sqrt(B^2 - 4AC)) / 2, s = q / A and C / q (a may be ~0: a parabola)
    A, B, C = 3 * a, 2 * b, c
    best_s = np.full(len(candidates), np.nan)
    best_p = np.full(len(candidates), -np.inf)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        disc = B * B - 4 * A * C
        q = -0.5 * (B + np.copysign(np.sqrt(np.where(disc >= 0, disc, np.nan)), B))
        for s in (q / A, C / q):
            value = ((a * s + b) * s + c) * s + d
            better = (s > 0) & (s < 1) & np.isfinite(value) & (value > best_p)
            best_p = np.where(better, value, best_p)
            best_s = np.where(better, s, best_s)
    floor_force = MISSED_CONTACT_FORCE_FRACTION * impact_threshold
    found = []
    for j in np.flatnonzero(best_p > PENETRATION_NOISE):
        i = candidates[j]
        p = float(best_p[j])
        force = contact.peak_force_estimate(p)
        if force <= floor_force:
            continue
        # how long the cubic stays above 0 (grid estimate, enough for choosing a step)
        s = np.linspace(0.0, 1.0, 513)
        values = ((a[j] * s + b[j]) * s + c[j]) * s + d[j]
        duration = float(np.count_nonzero(values > 0) / (len(s) - 1) * h[j])
        found.append(SteppedOverContact(start=float(time[i]), end=float(time[i + 1]),
                                        time=float(time[i] + best_s[j] * h[j]), penetration=p,
                                        peak_force=float(force), duration=max(duration, float(h[j]) / 512)))
    return found


# ------------------------------------------------------------------------------------------------
# After the solve: contacts only grazed

def grazed_contacts(mechanism: Mechanism, positions: dict) -> list[tuple[str, float, float]]:
    """``(name, deepest penetration m, position scale m)`` of every contact grazed in a solve (module docstring,
    point 4): touched (penetration above :data:`PENETRATION_NOISE` at some output sample) but never deeper than
    :data:`GRAZING_PENETRATION_RATIO` times the largest |x| of its two bodies.  ``positions``: the bodies'
    positions (m) at the output samples, by name."""
    found = []
    for contact in mechanism.contacts:
        deepest = float(np.max(contact.penetration(mechanism.relative(contact, positions)), initial=-np.inf))
        scale = max((float(np.max(np.abs(positions[body]), initial=0.0)) for body in (contact.a, contact.b)
                     if body != GROUND), default=0.0)
        if PENETRATION_NOISE < deepest < GRAZING_PENETRATION_RATIO * scale:
            found.append((contact.name, deepest, scale))
    return found
