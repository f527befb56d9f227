"""Contact laws: the force of every contact (absorber against wall A, end stops), one family, one module.

A contact is a :class:`~mbs_models.elements.connector.Connector` whose penetration is
``p = d - offset`` (m; ``d = x_b - x_a``) and rate ``p' = d'``.  No force while ``p <= 0``; while
``p > 0`` the law below, clipped to ``F >= 0`` (a contact never pulls).  ``v-`` is the penetration
rate at the onset of the contact episode (the instant ``p`` turned positive), captured inside the
solve (:class:`OnsetCapture`).

========================  ============================================  ===========================================
``law``                   fields                                        force while p > 0
========================  ============================================  ===========================================
``hunt-crossley``         stiffness, exponent, damping_factor (s/m)     ``k p^n (1 + lambda p')``
``lankarani-nikravesh``   stiffness, exponent, restitution              ``k p^n (1 + 3 (1 - e^2) / 4 * p' / v-)``
``flores``                stiffness, exponent, restitution              ``k p^n (1 + 8 (1 - e) / (5 e) * p' / v-)``
``gonthier``              stiffness, exponent, restitution              ``k p^n (1 + (1 - e^2) / e * p' / v-)``
``hertz``                 stiffness, exponent                           ``k p^n``
``kelvin-voigt``          stiffness (N/m), damping (N s/m)              ``k p + c p'``
``exact-restitution``     stiffness, exponent, restitution              ``k p^n (1 + chi p' / v-)``, chi below
========================  ============================================  ===========================================

The four restitution laws share the form ``k p^n (1 + chi p' / v-)`` (:func:`restitution_factor` gives
``chi``).  For a free two-body impact (no other force, never clipped) the rebound ``-p'_out = e v-``
follows from ``m v dv/dp = -k p^n (1 + chi v / v-)``: with ``G(v) = v/a - ln(1 + a v)/a^2``, ``a = chi/v-``,
``G(-e v-) = G(v-)``, i.e. ``chi - ln(1 + chi) = -chi e - ln(1 - chi e)``, whatever k, n and the masses.
Lankarani-Nikravesh, Flores and Gonthier approximate the e asked for (Lankarani-Nikravesh gives 0.73
for 0.5); ``exact-restitution`` solves the relation for chi (:func:`exact_restitution_factor`), so a free
impact rebounds with exactly e.

Slow impacts: ``v-`` tends to 0 for a resting or grazing contact, and ``chi p'/v-`` with it to infinity.
The laws use ``max(v-, minimum_impact_velocity)`` (default :data:`DEFAULT_MINIMUM_IMPACT_VELOCITY`,
1 mm/s, a field of every restitution law): impacts slower than that are damped as if they came at
that speed -- Hunt-Crossley with ``lambda = chi / minimum_impact_velocity`` -- so the force stays finite
and non-negative.  Faster impacts get exactly the law.  The capture happens at the step starts of
the solve (:class:`OnsetCapture`); within the step in which a contact begins, the approach rate at the
step start stands in for ``v-`` (the force is then ~0).

Contact fields (the table of the absorber's contact, ``[contact]`` / ``[absorber.contact]``, and of the
end stops): ``law`` (default ``hunt-crossley``) and the law's fields above; fields of other laws are
errors.  Python: ``Contact(gap=0.0, stiffness=2.1e8, exponent=1.3, damping_factor=0.6)``.

Building block: :func:`add_contact` adds a contact of any law between two markers of a caller's own
Exudyn system (symbolic user function by default); see the user guide (docs/guide/building-blocks.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, ClassVar

import numpy as np

from ..errors import SceneError
from .connector import Connector
from .ops import NUMPY_OPS, PYTHON_OPS, Ops, SymbolicVariables
from .table import Rule, Table, check_choice, check_derived

#: Restitution-law impacts slower than this (m/s) are damped as if they came at this speed.
DEFAULT_MINIMUM_IMPACT_VELOCITY = 1e-3


# ================================================================================================ the laws
@dataclass(frozen=True)
class ContactLaw:
    """One law of the family: its name, its fields (required) and whether it uses ``v-``."""

    name: str
    fields: tuple[str, ...]
    restitution: bool = False      # the form k p^n (1 + chi p'/v-)
    power_law: bool = True         # elastic part k p^n (else k p: Kelvin-Voigt)

    @property
    def optional(self) -> tuple[str, ...]:
        return ("minimum_impact_velocity",) if self.restitution else ()


CONTACT_LAWS: dict[str, ContactLaw] = {law.name: law for law in (
    ContactLaw("hunt-crossley", ("stiffness", "exponent", "damping_factor")),
    ContactLaw("lankarani-nikravesh", ("stiffness", "exponent", "restitution"), restitution=True),
    ContactLaw("flores", ("stiffness", "exponent", "restitution"), restitution=True),
    ContactLaw("gonthier", ("stiffness", "exponent", "restitution"), restitution=True),
    ContactLaw("hertz", ("stiffness", "exponent")),
    ContactLaw("kelvin-voigt", ("stiffness", "damping"), power_law=False),
    ContactLaw("exact-restitution", ("stiffness", "exponent", "restitution"), restitution=True),
)}
#: Every field a law may have, and its allowed values.
LAW_FIELDS = ("stiffness", "exponent", "damping_factor", "restitution", "damping", "minimum_impact_velocity")
LAW_RULES: dict[str, Rule] = {
    "stiffness": Rule(0.0, strict=True, unit="N/m^exponent"),
    "exponent": Rule(0.0, strict=True),
    "damping_factor": Rule(0.0, unit="s/m"),
    "restitution": Rule(0.0, strict=True, maximum=1.0),
    "damping": Rule(0.0, unit="N s/m"),
    "minimum_impact_velocity": Rule(0.0, strict=True, unit="m/s"),
}
#: Units of the law's keys whose rule names none (the key reference): the law's name, and pure numbers.
LAW_KEY_UNITS: dict[str, str] = {"law": "text", "exponent": "1", "restitution": "1"}


def _g(z: float) -> float:
    """``z - ln(1 + z)`` for ``z > -1`` (series for small ``|z|``: no cancellation)."""
    if abs(z) < 1e-3:
        return sum((-1.0) ** k * z ** k / k for k in range(2, 14))
    return z - math.log1p(z)


def _exp_minus_one_minus(L: float) -> float:
    """``exp(L) - 1 - L`` (series for small ``|L|``: no cancellation)."""
    if abs(L) < 1e-3:
        term, total = L * L / 2.0, 0.0
        for k in range(3, 16):
            total += term
            term *= L / k
        return total
    return math.expm1(L) - L


def exact_restitution_factor(restitution: float) -> float:
    """``chi`` of ``exact-restitution``: the root in ``(0, 1/e)`` of ``g(chi) = g(-chi e)``, ``g(z) = z - ln(1 + z)``.

    Solved for ``L = ln(1 - chi e)`` (so ``chi = (1 - exp(L)) / e``): ``g(-chi e) = exp(L) - 1 - L``, and
    ``F(L) = g((1 - e^L)/e) - (e^L - 1 - L)`` is ``(1/e^2 - 1) L^2 / 2 > 0`` near 0 and negative at
    ``L = -(g(1/e) + 2)``.  For small e the root has ``chi e`` within round-off of 1, which this form
    still resolves.  ``e = 1`` gives 0.
    """
    e = float(restitution)
    if not 0.0 < e <= 1.0:
        raise ValueError(f"restitution must be in (0, 1], got {e!r}")
    if e == 1.0:
        return 0.0
    from scipy.optimize import brentq

    def F(L: float) -> float:
        return _g(-math.expm1(L) / e) - _exp_minus_one_minus(L)

    low = -(_g(1.0 / e) + 2.0)
    high = -1e-6 * (1.0 - e)
    L = brentq(F, low, high, xtol=1e-300, rtol=8.9e-16, maxiter=500)
    return -math.expm1(L) / e


def restitution_factor(law: str, restitution: float) -> float:
    """``chi`` of a restitution law (the factor of ``p'/v-``) for the requested restitution ``e``."""
    e = float(restitution)
    if law == "lankarani-nikravesh":
        return 3.0 * (1.0 - e * e) / 4.0
    if law == "flores":
        return 8.0 * (1.0 - e) / (5.0 * e)
    if law == "gonthier":
        return (1.0 - e * e) / e
    if law == "exact-restitution":
        return exact_restitution_factor(e)
    raise ValueError(f"{law!r} is not a restitution law")


def check_law_fields(table: Any, key: str) -> None:
    """Check the law and its fields of a contact table (``key`` names it in errors, e.g. ``contact``)."""
    law = CONTACT_LAWS[check_choice(f"{key}.law", table.law, CONTACT_LAWS, "law")]
    allowed = law.fields + law.optional
    for name in LAW_FIELDS:
        value = getattr(table, name)
        if value is None:
            if name in law.fields:
                raise SceneError(f"{key}.{name}", f"missing: law {law.name!r} needs it "
                                                  f"(its fields: {', '.join(allowed)})")
            continue
        if name not in allowed:
            raise SceneError(f"{key}.{name}", f"not a field of law {law.name!r} (its fields: {', '.join(allowed)})")


class LawFields:
    """Mixin of tables that carry a contact law (the absorber's contact, the end stops)."""

    RULES: ClassVar = LAW_RULES
    KEY_UNITS: ClassVar = LAW_KEY_UNITS
    CHOICES: ClassVar = {"law": tuple(CONTACT_LAWS)}

    def __post_init__(self):
        super().__post_init__()
        check_law_fields(self, self.TABLE)
        if self.law == "kelvin-voigt" and self.damping:  # the clipping surface p + (c/k) p' = 0
            check_derived({f"{self.TABLE}.stiffness": self.stiffness, f"{self.TABLE}.damping": self.damping},
                          "the relaxation time c / k", self.damping / self.stiffness, "s")
        if self.contact_law.restitution:
            keys = {f"{self.TABLE}.restitution": self.restitution}
            if self.law == "exact-restitution":  # chi lies in (0, 1/e): the root is bracketed with 1/e
                check_derived(keys, "1 / restitution (the bound of chi)", 1.0 / self.restitution)
            chi = check_derived(keys, "the restitution factor chi", self.restitution_factor)
            keys[f"{self.TABLE}.minimum_impact_velocity"] = self.impact_velocity_floor
            check_derived(keys, "the largest damping factor chi / minimum_impact_velocity",
                          chi / self.impact_velocity_floor, "s/m")

    @classmethod
    def from_mapping(cls, data, key, version):
        law = data.get("law", "hunt-crossley") if isinstance(data, dict) else "hunt-crossley"
        if version < 2 and isinstance(law, str) and law != "hunt-crossley" and law in CONTACT_LAWS:
            raise SceneError(f"{key}.law", f"law {law!r} needs a version-2 scene (put version = 2 at the top); "
                                           "version 1 has only 'hunt-crossley'")
        return super().from_mapping(data, key, version)

    @property
    def contact_law(self) -> ContactLaw:
        """The :class:`ContactLaw` of :attr:`law`."""
        return CONTACT_LAWS[self.law]

    @property
    def restitution_factor(self) -> float | None:
        """``chi`` of a restitution law, None for the others."""
        return restitution_factor(self.law, self.restitution) if self.contact_law.restitution else None

    @property
    def impact_velocity_floor(self) -> float:
        """``minimum_impact_velocity`` (m/s), or its default."""
        value = getattr(self, "minimum_impact_velocity", None)
        return DEFAULT_MINIMUM_IMPACT_VELOCITY if value is None else value


@dataclass(frozen=True)
class Contact(LawFields, Table):
    """The contact between wall A of the barrel and an absorber.

    With penetration ``p = (x_M - x_m) - gap`` (m) the force is the law's (module docstring) for
    ``p > 0``, never negative.  Version 1 has only ``hunt-crossley`` (Eq. 6 of the paper).

    Attributes
    ----------
    gap: initial clearance in m (>= 0).
    stiffness: k in N/m^exponent (N/m for kelvin-voigt), > 0; 2.1e8 in Table 1.
    exponent: n (> 0), 1.3 in Table 1 (not a field of kelvin-voigt).
    damping_factor: hunt-crossley's lambda = c_c / k_c in s/m (>= 0), 0.6 in Table 1.
    law: the contact law, ``"hunt-crossley"`` by default.
    restitution: e in (0, 1] of the restitution laws.
    damping: kelvin-voigt's c in N s/m (>= 0).
    minimum_impact_velocity: restitution laws: slower impacts are damped as at this speed (m/s, > 0).
    """

    gap: float
    stiffness: float
    exponent: float | None = None
    damping_factor: float | None = None
    law: str = "hunt-crossley"
    restitution: float | None = None
    damping: float | None = None
    minimum_impact_velocity: float | None = None
    TABLE: ClassVar[str] = "contact"
    RULES: ClassVar = {"gap": Rule(0.0, unit="m"), **LAW_RULES}


# ================================================================================================ the force
def law_force(d, rate, law: str, stiffness: float, exponent: float | None, offset: float, ops: Ops, *,
              damping_factor: float | None = None, damping: float | None = None, compression_only: bool = False,
              lam=None):
    """The contact force in N, >= 0, of ``law`` at ``d`` (m) and ``rate`` (m/s), over ``ops``.

    ``offset``: ``p = d - offset``.  ``damping_factor``: hunt-crossley's lambda (s/m; negative for the
    paper's literal sign reading).  ``lam``: restitution laws' ``chi / max(v-, floor)`` (s/m), a number,
    an array aligned with ``rate``, or a symbolic variable.  ``compression_only``: no force while
    ``p' <= 0`` (a reading of the paper, hunt-crossley only).
    """
    if law == "kelvin-voigt":
        raw = d - offset
        penetration = ops.maximum(raw, 0.0)
        force = ops.choose(raw > 0, 1.0, 0.0) * (stiffness * penetration + damping * rate)
        return ops.maximum(force, 0.0)
    penetration = ops.maximum(d - offset, 0.0)
    if law == "hertz":
        return stiffness * ops.power(penetration, exponent)
    factor = damping_factor if law == "hunt-crossley" else lam
    force = stiffness * ops.power(penetration, exponent) * (1.0 + factor * rate)
    force = ops.maximum(force, 0.0)
    if compression_only:
        force = force * ops.choose(rate > 0, 1.0, 0.0)
    return force


def elastic_energy(penetration, law: str, stiffness: float, exponent: float | None):
    """Elastic energy (J) at penetration ``p`` (m; numpy, 0 where ``p <= 0``): ``k p^(n+1) / (n+1)``,
    ``k p^2 / 2`` for kelvin-voigt."""
    p = np.maximum(np.asarray(penetration, dtype=float), 0.0)
    if law == "kelvin-voigt":
        return 0.5 * stiffness * p ** 2
    return stiffness * p ** (exponent + 1.0) / (exponent + 1.0)


def _first_root(a: float, b: float, c: float, upper: float) -> float:
    """Smallest root in ``[0, upper]`` of ``a t^2 + b t + c`` (``c <= 0``); else ``-c/b`` capped at ``upper``
    (``0`` if the motion does not approach).  Cancellation-free: ``q = -(b + sign(b) sqrt(b^2 - 4ac)) / 2``,
    roots ``q / a`` and ``c / q``."""
    if a != 0.0:
        disc = b * b - 4.0 * a * c
        if disc >= 0.0:
            q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
            roots = [r for r in ((q / a), (c / q) if q != 0.0 else math.inf) if 0.0 <= r <= upper]
            if roots:
                return min(roots)
    return min(-c / b, upper) if b > 0.0 else 0.0


class OnsetCapture(SymbolicVariables):
    """The penetration rate at the onset of each contact episode, captured at the step starts of a solve.

    :meth:`observe` is called with the state at the start of every step (Exudyn's pre-step function).
    While the bodies are apart (``p <= 0``) the contact is *armed* and the law uses the approach rate
    there, ``chi / max(p', floor)``.  At the first step start in contact after that, the onset lies in the
    step just taken: the free motion before it (position, rate and the rate's slope from the last two
    step starts apart) is extrapolated to ``p = 0``, its rate there is ``v-``, and the law uses
    ``chi / max(v-, floor)`` until the episode ends.  :attr:`history` records ``(time, lam)`` whenever
    the value changes, for post-processing (the force between steps).
    """

    def __init__(self, chi: float, floor: float, offset: float):
        self.chi, self.floor, self.offset = float(chi), float(floor), float(offset)
        self.lam = 0.0
        self.history: list[tuple[float, float]] = []
        self._variable = None     # the symbolic variable, if any
        self._holder = None
        self._armed = True
        self._apart: list[tuple[float, float, float]] = []   # last two step starts apart: (t, p, p')
        self._last: tuple[float, float, float] | None = None
        self.onsets: list[tuple[float, float]] = []           # (estimated onset time, v-)

    def start(self, d0: float, rate0: float) -> None:
        """The value at t = 0 (before the first step), from the initial state."""
        p0 = d0 - self.offset
        self._armed = p0 <= 0.0
        v = rate0 if p0 <= 0.0 else max(rate0, 0.0)
        self._set(0.0, self.chi / max(v, self.floor))
        if p0 > 0.0:  # an initial interference: the episode begins at t = 0
            self.onsets.append((0.0, v))

    def _set(self, t: float, lam: float) -> None:
        if self.history and self.history[-1][1] == lam:
            return
        self.lam = lam
        self.history.append((float(t), lam))
        if self._variable is not None:
            self._variable.SetValue(lam)

    def observe(self, t: float, d: float, rate: float) -> None:
        """The state at the step start ``t`` (s): relative coordinate ``d`` (m) and rate (m/s)."""
        if not self.history:
            self.start(d, rate)
        state = (t, d, rate)
        if state == self._last:      # a retried step: same start
            return
        self._last = state
        p = d - self.offset
        if p <= 0.0:
            self._armed = True
            if not self._apart or self._apart[-1][0] < t:
                self._apart = (self._apart + [(t, p, rate)])[-2:]
            self._set(t, self.chi / max(rate, self.floor))
            return
        if not self._armed:
            return
        self._armed = False
        v_onset, t_onset = self._onset_rate(t)
        self.onsets.append((t_onset, v_onset))
        self._set(t, self.chi / max(v_onset, self.floor))

    def _onset_rate(self, t_now: float) -> tuple[float, float]:
        """``(v-, onset time)`` from the free motion of the last step start(s) apart."""
        if not self._apart:
            return 0.0, t_now
        t0, p0, v0 = self._apart[-1]
        slope = 0.0
        if len(self._apart) == 2 and self._apart[1][0] > self._apart[0][0]:
            slope = (v0 - self._apart[0][2]) / (self._apart[1][0] - self._apart[0][0])
        h = max(t_now - t0, 0.0)
        tau = _first_root(0.5 * slope, v0, p0, h)
        return max(v0 + slope * tau, 0.0), t0 + tau

    def lam_at(self, t) -> np.ndarray:
        """``lam`` (s/m) in force at times ``t`` (s): the value set at the last step start before t."""
        times = np.array([h[0] for h in self.history])
        values = np.array([h[1] for h in self.history])
        index = np.clip(np.searchsorted(times, np.asarray(t, dtype=float), side="left") - 1, 0, len(values) - 1)
        return values[index]


class ContactConnector(Connector):
    """A contact of any law between points ``a`` and ``b``: ``p = (x_b - x_a) - offset``.

    ``spec`` is a table with the law's fields (:class:`Contact`, an end stop).  ``conventions``
    (hunt-crossley at wall A only) switch on the paper's literal readings: ``literal_lambda_sign``
    flips lambda's sign, ``compression_only`` drops the force while ``p' <= 0``.
    """

    needs_user_function = True
    records_force = True
    is_contact = True
    offset_in_item = True
    #: (the law reads the numbers copied from ``spec`` in __init__, never ``spec`` itself)
    law_state_ignores = frozenset({"spec"})

    def __init__(self, name: str, element: str, a: str, b: str, spec, offset: float, *, conventions=None):
        super().__init__(name, element, a, b)
        self.spec = spec
        self.law_name = spec.law
        self.offset = float(offset)
        self.contact_stiffness = float(spec.stiffness)
        self.exponent = 1.0 if spec.law == "kelvin-voigt" else float(spec.exponent)
        self.contact_damping = float(spec.damping or 0.0)
        literal = conventions is not None and conventions.literal_lambda_sign
        self.compression_only = conventions is not None and conventions.compression_only
        self.damping_factor = ((-1.0 if literal else 1.0) * spec.damping_factor
                               if spec.law == "hunt-crossley" else None)
        self.capture = None
        if spec.contact_law.restitution:
            self.capture = OnsetCapture(spec.restitution_factor, spec.impact_velocity_floor, self.offset)

    @property
    def kinks(self) -> tuple[float, ...]:
        """The offset (m): the force at rest is 0 before it, ``k p^n`` after."""
        return (self.offset,)

    # ------------------------------------------------------------------ the law
    def penetration(self, d):
        """p = d - offset (m), > 0 in contact."""
        return d - self.offset

    def law(self, d, rate, ops: Ops, lam=None, offset=None):
        """The force (N); ``offset``: the offset to use (m; the item's, in a user function), default :attr:`offset`."""
        if lam is None and self.capture is not None:
            lam = self.capture.lam
        return law_force(d, rate, self.law_name, self.contact_stiffness, self.exponent,
                         self.offset if offset is None else offset, ops, damping_factor=self.damping_factor,
                         damping=self.contact_damping, compression_only=self.compression_only, lam=lam)

    def user_function_law(self, ops: Ops) -> Callable:
        """:meth:`law` as Exudyn's user function ``f(d, d', offset)``, the offset the item holds
        (:attr:`~mbs_models.elements.connector.Connector.offset_in_item`: the law uses it only as ``d - offset``).
        Symbolic: ``select(d > offset, F(d, d'), 0)`` -- every law's force is 0 while the contact is open (``p <=
        0``: a zero penetration's power times a finite factor, clipped at 0), and Exudyn evaluates only the branch
        a selection takes, so an open contact costs a comparison instead of the law (its power function); in
        contact it is the law's own expression."""
        if self.capture is None:
            law = lambda d, rate, offset: self.law(d, rate, ops, offset=offset)  # noqa: E731
        elif ops.name == "symbolic":
            import exudyn
            variable = exudyn.symbolic.Real(f"lam_{self.name}_{id(self)}", self.capture.lam)
            self.capture._variable = variable
            law = lambda d, rate, offset: self.law(d, rate, ops, lam=variable, offset=offset)  # noqa: E731
        else:
            capture = self.capture
            law = lambda d, rate, offset: self.law(d, rate, ops, lam=capture.lam, offset=offset)  # noqa: E731
        if ops.name != "symbolic":
            return law
        return lambda d, rate, offset: ops.select(d > offset, law(d, rate, offset), 0.0)

    def force(self, d, rate, t=None):
        lam = None
        if self.capture is not None:
            lam = self.capture.lam_at(t) if t is not None else self.capture.lam
        return self.law(d, rate, NUMPY_OPS, lam=lam)

    def python_force(self, d: float, rate: float) -> float:
        """The force (N) at one state with the law's current ``v-`` (plain floats)."""
        return self.law(d, rate, PYTHON_OPS)

    def python_force_function(self) -> Callable[[float, float], float]:
        """:meth:`python_force` with the law's numbers looked up once, for callers that evaluate it at many
        states (the early stop's tracker): ``f(d, rate)`` in N, the same float as ``python_force(d, rate)``
        (the same :func:`law_force` call; ``v-`` still read from the capture at each call)."""
        law, stiffness, exponent, offset = self.law_name, self.contact_stiffness, self.exponent, self.offset
        damping_factor, damping, compression_only = self.damping_factor, self.contact_damping, self.compression_only
        capture = self.capture

        def force(d: float, rate: float) -> float:
            return law_force(d, rate, law, stiffness, exponent, offset, PYTHON_OPS, damping_factor=damping_factor,
                             damping=damping, compression_only=compression_only,
                             lam=capture.lam if capture is not None else None)

        return force

    def python_elastic(self, d: float) -> float:
        """Elastic energy (J) at ``d`` (plain floats): ``p^(n+1) / ((n+1)/k)`` for p > 0, else 0."""
        p = d - self.offset
        if p <= 0.0:
            return 0.0
        if self.law_name == "kelvin-voigt":
            return 0.5 * self.contact_stiffness * p * p
        return p ** (self.exponent + 1.0) / ((self.exponent + 1.0) / self.contact_stiffness)

    python_stored_energy = python_elastic

    # ------------------------------------------------------------------ energy
    @property
    def stores_energy(self) -> bool:
        return True

    @property
    def dissipates(self) -> bool:
        return True

    def stored_energy(self, d):
        return elastic_energy(self.penetration(np.asarray(d, dtype=float)), self.law_name, self.contact_stiffness,
                              self.exponent)

    def dissipated_energy(self, quadrature, d_nodes, rate_nodes, times_nodes, stored):
        """The contact work not stored elastically: ``integral F p' dt - (U - U(0))`` (J)."""
        force = self.force(d_nodes, rate_nodes, times_nodes)
        return quadrature(force * rate_nodes) - (stored - stored[0])

    # ------------------------------------------------------------------ bounds and time scales
    @property
    def linear_stiffness(self) -> float:
        return 0.0  # acts only in contact: not part of the quadratic form

    @property
    def largest_damping_factor(self) -> float:
        """The largest factor of ``p'`` in the law (s/m): lambda, or chi / floor for restitution laws."""
        if self.capture is not None:
            return self.capture.chi / self.capture.floor
        return abs(self.damping_factor or 0.0)

    def penetration_bound(self, energy: float) -> float:
        """Bound (m) on p from the contact's own potential: ``((n+1) E / k)^(1/(n+1))``, ``sqrt(2E/k)`` for KV."""
        return ((self.exponent + 1.0) / self.contact_stiffness * max(energy, 0.0)) ** (1.0 / (self.exponent + 1.0))

    def force_bound(self, d_bound: float, rate_bound: float, energy: float) -> float:
        """Bound (N) on F given a bound on the penetration (``d_bound``, m) and on |p'| (m/s)."""
        p = d_bound
        if p <= 0.0:
            return 0.0
        if self.law_name == "kelvin-voigt":
            return self.contact_stiffness * p + self.contact_damping * rate_bound
        return self.contact_stiffness * p ** self.exponent * (1.0 + self.largest_damping_factor * rate_bound)

    def peak_force_estimate(self, penetration: float) -> float:
        """The undamped force (N) at a penetration (m): ``k p^n`` (``k p``)."""
        return self.contact_stiffness * penetration ** self.exponent

    def elastic_force(self, d: float) -> float:
        """The force at rest (N, ``p' = 0``) at ``d`` (m, a float): ``k p^n`` (``k p`` for Kelvin-Voigt) for
        ``p = d - offset > 0``, else 0 -- the static force an initial interference starts from."""
        p = d - self.offset
        return self.peak_force_estimate(p) if p > 0.0 else 0.0

    def impact_penetration(self, reduced_mass: float, speed: float) -> float:
        """Maximum penetration (m) of an undamped impact of ``reduced_mass`` (kg) at ``speed`` (m/s):
        ``((n+1) m v^2 / (2 k))^(1/(n+1))``."""
        n = self.exponent
        return ((n + 1.0) * 0.5 * reduced_mass * speed ** 2 / self.contact_stiffness) ** (1.0 / (n + 1.0))

    def tangent(self, penetration: float, rate: float, impact_speed: float) -> tuple[float, float]:
        """Linearised (stiffness N/m, damping N s/m) at a penetration and rate, for an impact at
        ``impact_speed`` (m/s, the ``v-`` of restitution laws)."""
        k, n, p = self.contact_stiffness, self.exponent, penetration
        if self.law_name == "kelvin-voigt":
            return k, self.contact_damping
        if self.capture is not None:
            lam = self.capture.chi / max(impact_speed, self.capture.floor)
        else:
            lam = self.damping_factor or 0.0
        return n * k * p ** (n - 1.0) * max(0.0, 1.0 + lam * rate), abs(lam) * k * p ** n

    # ------------------------------------------------------------------ the onset of episodes
    def start(self, d0: float, rate0: float) -> None:
        """Initialise the onset capture from the initial state (no-op for laws without ``v-``)."""
        if self.capture is not None:
            self.capture.start(d0, rate0)

    def update(self, mbs, t: float | None = None) -> None:
        """For a caller's own pre-step function: capture the onset rate from the connector's state.

        Reads the connector's displacement and velocity (Exudyn output variables) at the step start.
        """
        if self.capture is None:
            return
        import exudyn

        ovt = exudyn.OutputVariableType
        if t is None:
            it = mbs.sys["dynamicSolver"].it
            t = it.currentTime - it.currentStepSize
        self.capture.observe(t, mbs.GetObjectOutput(self.index, ovt.Displacement),
                             mbs.GetObjectOutput(self.index, ovt.Velocity))


# ================================================================================================ building block
def add_contact(mbs, marker_a, marker_b, contact, *, offset: float | None = None, user_functions: str = "symbolic",
                name: str = "contact", sensor: bool = True, install_pre_step: bool = True) -> ContactConnector:
    """Add a contact of any law between two markers of your own Exudyn system; return its connector.

    The returned :class:`ContactConnector` keeps the user function alive: keep it as long as ``mbs``.
    Call ``mbs.Assemble()`` afterwards as usual.

    Parameters
    ----------
    mbs: your ``MainSystem``.
    marker_a, marker_b: coordinate markers (``MarkerNodeCoordinate``): the contact closes when
        ``x_b - x_a`` exceeds ``offset``; its force pushes ``b`` towards -x and ``a`` towards +x.
    contact: a :class:`Contact` (its ``gap`` is the offset) or any table with the law's fields.
    offset: ``p = (x_b - x_a) - offset`` (m); default: ``contact.gap``.
    user_functions: ``"symbolic"`` (C++, default) or ``"python"``.
    sensor: record the force (``connector.sensor``, ``mbs.GetSensorStoredData``).
    install_pre_step: restitution laws need ``v-`` at each contact onset: install a pre-step function
        that captures it (``connector.update(mbs)``).  If your model has its own pre-step function, pass
        False and call ``connector.update(mbs)`` from it.
    """
    offset = contact.gap if offset is None else float(offset)
    connector = ContactConnector(name, name, "a", "b", contact, offset)
    connector.add_items(mbs, marker_a, marker_b, user_functions)
    if sensor:
        import exudyn
        from exudyn.itemInterface import SensorObject
        connector.sensor = mbs.AddSensor(SensorObject(objectNumber=connector.index,
                                                      outputVariableType=exudyn.OutputVariableType.Force,
                                                      storeInternal=True))
    if connector.capture is not None and install_pre_step:
        def pre_step(mbs, t):
            connector.update(mbs)
            return True
        mbs.SetPreStepUserFunction(pre_step)
    return connector
