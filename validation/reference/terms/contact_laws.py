"""Building block: the contact-law family of every contact (absorbers against wall A, end stops).

DESIGN.md, "Contact laws".  Penetration ``p = d - offset`` (m), rate ``p' = d'`` (m/s).  No force while
``p <= 0``; while ``p > 0`` (an *episode*; ``v-`` is ``p'`` at its onset)::

    hunt-crossley         F = k p^n (1 + lambda p')                 lambda: damping_factor (s/m)
    lankarani-nikravesh   F = k p^n (1 + chi p'/v^)                 chi = 3 (1 - e^2) / 4
    flores                                                           chi = 8 (1 - e) / (5 e)
    gonthier                                                         chi = (1 - e^2) / e
    exact-restitution                                                chi: a free impact rebounds with e
    hertz                 F = k p^n
    kelvin-voigt          F = k p + c p'                            (jumps from 0 to c v- at the onset)

with ``v^ = max(v-, minimum_impact_velocity)`` (default 1e-3 m/s; an initial interference has
``v- = max(p'(0), 0)``); ``chi`` is :func:`validation.reference.closed_form.restitution_factor`.  Every
law is clipped to ``F >= 0``.  The power laws are one form, ``k p^n (1 + a p')`` with the episode's
*damping factor* ``a`` (s/m): lambda, ``chi / v^``, or 0 (hertz).

Elastic energy ``U = k max(p, 0)^(n+1) / (n+1)`` (n = 1 for Kelvin-Voigt: ``k p^2 / 2``); dissipated
power ``(F - k p^n) p'`` (W), >= 0 for every law: ``a k p^n p'^2`` or ``c p'^2`` while the law acts,
``-k p^n p' > 0`` while clipped (the clipped laws clip only at ``p' < 0``).

Discrete state (:class:`ContactMode`) and switching surfaces (events):

* ``p = 0`` -- onset (upwards: a new episode, ``v-`` captured) and release (downwards);
* the clipping surface, where the law's force crosses 0 while ``p > 0``: ``1 + a p' = 0`` for the power
  laws (none for hertz or a = 0), ``p + (c/k) p' = 0`` for Kelvin-Voigt (none for c = 0); below it the
  contact is *clipped* (``phase = off``, ``penetrated``, ``clipped``: no force);
* with the paper's ``compression_only`` reading (hunt-crossley, one absorber): ``p' = 0`` as well --
  the force ``k p^n (1 + lambda p')`` acts only while ``p' > 0``; when the other forces push the bodies
  together at ``p' = 0`` a Filippov sliding mode follows (``phase = stick``): ``p' = 0`` held by
  ``F = m_red (f_b/m_b - f_a/m_a)`` (``m_red = m_a m_b / (m_a + m_b)``, f the other forces), as long as
  ``0 < F < k p^n`` (events ``release``: F = 0, ``slip``: F = k p^n).

Energy bounds: the penetration is bounded by the contact's own potential, ``((n+1) E / k)^(1/(n+1))``,
and the force by ``k p^n (1 + a_max |p'|)`` (``a_max`` = |lambda|, ``chi / minimum_impact_velocity``,
or 0) or ``k p + c |p'|`` (Kelvin-Voigt).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..closed_form import restitution_factor
from ..model import Connector, Equations, ReferenceModelError
from ..switching import TOL_POS, TOL_S, TOL_VEL, heading

#: Contact phases.
OFF, ON, STICK = "off", "on", "stick"
#: Restitution-law impacts slower than this (m/s) are damped as if they came at this speed (DESIGN.md).
DEFAULT_MINIMUM_IMPACT_VELOCITY = 1e-3
RESTITUTION_LAWS = ("lankarani-nikravesh", "flores", "gonthier", "exact-restitution")
LAWS = ("hunt-crossley", *RESTITUTION_LAWS, "hertz", "kelvin-voigt")


@dataclass(frozen=True)
class Law:
    """One contact law with its numbers (SI): k (N/m^n), n, lambda (s/m), chi, c (N s/m), floor (m/s)."""

    name: str
    stiffness: float
    exponent: float = 1.0
    damping_factor: float = 0.0
    chi: float = 0.0
    damping: float = 0.0
    floor: float = DEFAULT_MINIMUM_IMPACT_VELOCITY

    @classmethod
    def from_table(cls, table, literal_lambda_sign: bool = False) -> "Law":
        """The law of a contact table (read as data); ``literal_lambda_sign`` flips hunt-crossley's lambda."""
        name = table.law
        if name not in LAWS:
            raise ReferenceModelError(f"no reference contact law {name!r}; known: {', '.join(LAWS)}")
        fields = dict(name=name, stiffness=float(table.stiffness))
        if name == "kelvin-voigt":
            fields["damping"] = float(table.damping or 0.0)
        else:
            fields["exponent"] = float(table.exponent)
        if name == "hunt-crossley":
            fields["damping_factor"] = (-1.0 if literal_lambda_sign else 1.0) * float(table.damping_factor)
        if name in RESTITUTION_LAWS:
            fields["chi"] = restitution_factor(name, table.restitution)
            floor = getattr(table, "minimum_impact_velocity", None)
            fields["floor"] = DEFAULT_MINIMUM_IMPACT_VELOCITY if floor is None else float(floor)
        return cls(**fields)

    @property
    def kelvin_voigt(self) -> bool:
        return self.name == "kelvin-voigt"

    def episode_factor(self, onset_rate: float) -> float:
        """The power-law damping factor a (s/m) of an episode with ``v- = onset_rate`` (m/s):
        lambda, ``chi / max(v-, floor)``, or 0 (hertz, Kelvin-Voigt)."""
        if self.name in RESTITUTION_LAWS:
            return self.chi / max(onset_rate, self.floor)
        return self.damping_factor

    @property
    def has_clipping_surface(self) -> bool:
        """Can the force cross 0 while p > 0?  (c > 0 for Kelvin-Voigt, a != 0 for the power laws)"""
        if self.kelvin_voigt:
            return self.damping > 0
        return self.damping_factor != 0 or self.chi > 0

    @property
    def largest_factor(self) -> float:
        """Bound (s/m) on |a| over all episodes: |lambda|, chi / floor, or 0."""
        return self.chi / self.floor if self.name in RESTITUTION_LAWS else abs(self.damping_factor)


@dataclass(frozen=True)
class ContactMode:
    """A contact's discrete state in one segment.

    ``phase``: ``off`` (no force), ``on`` (the law, unclipped: a smooth extension for the event
    functions), ``stick`` (sliding, compression_only); ``penetrated``: on the ``p > 0`` side (an episode is
    going on); ``clipped``: penetrated but below the clipping surface; ``factor``: the episode's damping
    factor a (s/m); ``onset_rate``: the episode's v- (m/s).
    """

    phase: str
    penetrated: bool = False
    clipped: bool = False
    factor: float = 0.0
    onset_rate: float | None = None


class ContactConnector(Connector):
    """A contact of any law between ``a`` and ``b``: ``p = (x_b - x_a) - offset`` (module docstring)."""

    is_contact = True
    dissipates = True
    stores_energy = True
    classify_pass = 1

    def __init__(self, name: str, a: str, b: str, offset: float, law: Law, compression_only: bool = False):
        super().__init__(name, a, b)
        self.offset, self.contact_law = float(offset), law
        self.compression_only = bool(compression_only)
        if self.compression_only and law.name != "hunt-crossley":
            raise ReferenceModelError(f"{name}: compression_only is a reading of the hunt-crossley law")
        self.injects_energy = law.damping_factor < 0

    # ------------------------------------------------------------------ the law
    @property
    def kinks(self) -> tuple[float, ...]:
        """The offset (m): no force at rest before it, ``k p^n`` after."""
        return (self.offset,)

    def law(self, d, rate, state: ContactMode | None = None):
        """The physical force (N, floats or arrays; module docstring): 0 while ``p <= 0``; while ``p > 0`` the
        law clipped to >= 0 -- ``k p^n (1 + a p')`` with the damping factor a of the episode ``state`` (None: the
        largest, an onset at or below the floor), ``k p + c p'``, ``k p^n``; under ``compression_only`` only while
        ``p' > 0``."""
        law = self.contact_law
        factor = state.factor if state is not None else (law.largest_factor if law.name in RESTITUTION_LAWS
                                                         else law.damping_factor)
        if np.ndim(d) == 0 and np.ndim(rate) == 0:
            p = d - self.offset
            if p <= 0.0 or (self.compression_only and rate <= 0.0):
                return 0.0
            raw = law.stiffness * p + law.damping * rate if law.kelvin_voigt else \
                law.stiffness * p ** law.exponent * (1.0 + factor * rate)
            return max(raw, 0.0)
        p = np.asarray(d, dtype=float) - self.offset + 0.0 * np.asarray(rate, dtype=float)
        rate = np.asarray(rate, dtype=float) + 0.0 * p
        positive = np.maximum(p, 0.0)
        if law.kelvin_voigt:
            raw = law.stiffness * positive + law.damping * rate
        else:
            raw = law.stiffness * positive ** law.exponent * (1.0 + factor * rate)
        acting = (p > 0.0) & (rate > 0.0) if self.compression_only else p > 0.0
        return np.where(acting, np.maximum(raw, 0.0), 0.0)

    def surface(self, p, rate, factor):
        """The clipping surface's function: ``1 + a p'`` (power laws), ``p + (c/k) p'`` (m, Kelvin-Voigt)."""
        if self.contact_law.kelvin_voigt:
            return p + self.contact_law.damping / self.contact_law.stiffness * rate
        return 1.0 + factor * rate

    def surface_rate(self, rate, acceleration, factor):
        """Its time derivative: ``a p''`` or ``p' + (c/k) p''`` (only its sign is read: an extreme factor's product
        may overflow to +-inf, without a warning)."""
        with np.errstate(over="ignore"):
            if self.contact_law.kelvin_voigt:
                return rate + self.contact_law.damping / self.contact_law.stiffness * acceleration
            return factor * acceleration

    def equations(self, state: ContactMode) -> Equations | None:
        """The force of ``state``; the dissipated power ``(F - k p^n) p'`` (``k p^n`` continued oddly to
        p < 0, ``sign(p) |p|^n``, so that the law stays smooth across the segment's end)."""
        if state.phase == OFF and not state.penetrated:
            return None
        law = self.contact_law
        constants = dict(k=law.stiffness, n=law.exponent, offset=self.offset)
        elastic = """
            p = {xb} - {xa} - {offset}
            rate = {vb} - {va}
            elastic = {k} * copysign(abs(p) ** {n}, p)"""
        if state.phase == OFF:  # clipped (or released, compression_only): the vanishing elastic energy
            return Equations(elastic + """
                {F} = 0.0
                {P} = (0.0 - elastic) * rate""", constants)
        if state.phase == STICK:  # p' = 0 held: F = m_red (f_b/m_b - f_a/m_a) of the other forces
            ma, mb = self.mass_a, self.mass_b
            return Equations("""
                {F} = {m_red} * ({fb} / {mb} - {fa} / {ma})""" + elastic + """
                {P} = ({F} - elastic) * rate""", dict(constants, m_red=mb * ma / (mb + ma), ma=ma, mb=mb),
                             constraint=True)
        if law.kelvin_voigt:
            return Equations(elastic + """
                {F} = elastic + {c} * rate
                {P} = ({F} - elastic) * rate""", dict(constants, c=law.damping))
        return Equations(elastic + """
            {F} = elastic * (1.0 + {a} * rate)
            {P} = ({F} - elastic) * rate""", dict(constants, a=state.factor))

    def reported(self, force):
        """The physical force: the law clipped to >= 0 (N)."""
        return np.maximum(force, 0.0)

    def force_rate(self, state: ContactMode, d, rate, acceleration):
        """dF/dt (N/s) while the law acts: ``k [n p^(n-1) p' (1 + a p') + p^n a p'']`` or ``k p' + c p''``;
        0 without force; None in the sliding mode (no closed form: the peak is found numerically)."""
        if state.phase == OFF:
            return 0.0 * rate
        if state.phase == STICK:
            return None
        k, n = self.contact_law.stiffness, self.contact_law.exponent
        if self.contact_law.kelvin_voigt:
            return k * rate + self.contact_law.damping * acceleration
        pp = np.maximum(d - self.offset, 0.0)
        dpow = n * np.where(pp > 0, pp, 1.0) ** (n - 1.0) * (pp > 0)
        return k * (dpow * rate * (1.0 + state.factor * rate) + pp ** n * state.factor * acceleration)

    def stored_energy(self, d):
        """``U = k max(p, 0)^(n+1) / (n+1)`` (J)."""
        n = self.contact_law.exponent
        return self.contact_law.stiffness * np.maximum(d - self.offset, 0.0) ** (n + 1.0) / (n + 1.0)

    def static_force(self, d: float) -> float:
        """The force at rest (p' = 0): ``k max(p, 0)^n`` (N), every law (the damping terms vanish)."""
        p = d - self.offset
        return self.contact_law.stiffness * p ** self.contact_law.exponent if p > 0.0 else 0.0

    # ------------------------------------------------------------------ modes
    def _episode(self, rate: float, previous: ContactMode | None) -> tuple[float, float]:
        """(factor, v-) of the episode going on: the previous segment's, or a new one with v- = max(p', 0)."""
        if previous is not None and previous.penetrated:
            return previous.factor, previous.onset_rate
        onset = max(rate, 0.0)
        return self.contact_law.episode_factor(onset), onset

    def provisional(self, s, previous):
        """The previous state, or at t = 0 the law acting iff p > 0."""
        if previous is not None:
            return previous
        if s[self.ib] - s[self.ia] - self.offset <= 0:
            return ContactMode(OFF)
        factor, onset = self._episode(s[self.ib + 1] - s[self.ia + 1], None)
        return ContactMode(ON, True, False, factor, onset)

    def classify(self, restart) -> ContactMode:
        """The state at a restart: which side of ``p = 0`` and of the clipping surface, by the signs or,
        on a surface, by the direction the free motion (this contact's force left out) is heading."""
        s = restart.s
        p = s[self.ib] - s[self.ia] - self.offset
        rate = s[self.ib + 1] - s[self.ia + 1]
        free = restart.free_relative_acceleration(self)
        hints = restart.hints_for(self)
        if not (hints["p"] if "p" in hints else heading(p, rate, free)):
            return ContactMode(OFF)
        factor, onset = self._episode(rate, restart.previous_state(self))
        if self.contact_law.has_clipping_surface:
            tol = TOL_POS if self.contact_law.kelvin_voigt else TOL_S
            if not (hints["s"] if "s" in hints else heading(self.surface(p, rate, factor),
                                                             self.surface_rate(rate, free, factor), tol=tol)):
                return ContactMode(OFF, True, True, factor, onset)
        phase = self._compression_only(hints, p, rate, free) if self.compression_only else ON
        return ContactMode(phase, True, False, factor, onset)

    def _compression_only(self, hints, p, rate, free) -> str:
        """The phase under ``compression_only`` at p > 0 above the clipping surface (three-way at p' = 0)."""
        if "release" in hints:
            return OFF
        if "slip" in hints:
            return ON
        if "pd" not in hints and abs(rate) > TOL_VEL:
            return ON if rate > 0 else OFF
        # on the surface p' = 0: the force is k p^n (1 + lambda 0) if compressing, 0 otherwise
        m_red = self.mass_b * self.mass_a / (self.mass_b + self.mass_a)
        with_force = free - self.contact_law.stiffness * max(p, 0.0) ** self.contact_law.exponent / m_red
        if with_force > 0:
            return ON       # even with the force the bodies keep approaching
        if free <= 0:
            return OFF      # even without the force they separate
        return STICK        # both sides push onto p' = 0: Filippov sliding

    def events(self, state: ContactMode, restart):
        """The switching surfaces watched in ``state`` (module docstring)."""
        d_of, rate_of, offset, dy = self.d_of, self.rate_of, self.offset, restart.dy
        if state.phase == STICK:
            sliding_force = restart.force_function(self)
            k, n = self.contact_law.stiffness, self.contact_law.exponent

            def slip(t, y):
                return sliding_force(t, y) - k * np.maximum(d_of(y) - offset, 0.0) ** n
            return [("release", sliding_force, True, None, 0.0), ("slip", slip, False, None, 0.0)]
        items = [("p", lambda t, y: d_of(y) - offset, state.penetrated, d_of(dy), restart.position_noise(offset))]
        if state.penetrated and self.contact_law.has_clipping_surface:
            factor, surface = state.factor, self.surface
            if self.contact_law.kelvin_voigt:
                noise = restart.position_noise(offset) + self.contact_law.damping / self.contact_law.stiffness * restart.velocity_noise
            else:
                noise = restart.velocity_noise * max(1.0, abs(factor))
            items.append(("s", lambda t, y: surface(d_of(y) - offset, rate_of(y), factor), not state.clipped,
                          self.surface_rate(d_of(dy), rate_of(dy), factor), noise))
            if self.compression_only and not state.clipped:
                items.append(("pd", lambda t, y: rate_of(y), state.phase == ON, rate_of(dy), restart.velocity_noise))
        return items

    def rough_events(self, state: ContactMode):
        """The release ``p = 0`` of a penetrated power law: ``k p^n`` (n != 1) is only C^1 at p = 0, so the
        solver's step that crosses it may be long and its error estimate blind (seen: a 1 ms step losing
        3e-6 of the restitution of a free Flores impact)."""
        return ("p",) if state.penetrated and self.contact_law.exponent != 1.0 else ()

    # ------------------------------------------------------------------ bounds
    def penetration_bound(self, energy: float) -> float:
        """``((n+1) E / k)^(1/(n+1))`` (m): the contact's own potential cannot exceed E (J)."""
        n = self.contact_law.exponent
        return ((n + 1.0) * max(energy, 0.0) / self.contact_law.stiffness) ** (1.0 / (n + 1.0))

    def force_bound(self, d_bound: float, rate_bound: float, penetration_bound: float) -> float:
        """``k p^n (1 + a_max |p'|)`` or ``k p + c |p'|`` (N) at the bounds; 0 if p cannot become > 0."""
        p = penetration_bound
        if p <= 0:
            return 0.0
        if self.contact_law.kelvin_voigt:
            return self.contact_law.stiffness * p + self.contact_law.damping * rate_bound
        return self.contact_law.stiffness * p ** self.contact_law.exponent * (1.0 + self.contact_law.largest_factor * rate_bound)
