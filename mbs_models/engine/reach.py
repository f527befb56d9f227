"""Contacts that can never close: a gap or a stop position beyond the barrel's free-recoil travel.

A gap typed in millimetres (``gap = 40`` meant as 40 mm) gives a run without any contact, silently.
:func:`contacts_out_of_reach` finds such contacts from the scene alone, before any solve.

The bound
---------
The contact's relative coordinate ``d = g . x`` (``x_M - x_m`` for an absorber, ``x_M`` for a recoil stop)
closes the contact where ``d > offset`` (the gap, the stop's position).  Two bounds, both proofs, of which
the smaller is used (:func:`contact_reach_bounds`):

* **Free recoil** (no contact ever closes): until the first contact closes, the motion is that of the
  scene without contacts, whose bodies fall apart into groups joined by springs and dampers (the barrel
  with its spring, damper and any absorber mounted on it; each ground-mounted absorber alone).  Each
  group's energy ``E_c`` never exceeds its value at t = 0, so ``d <= sum_c sqrt(2 E_c g_c^T K_c^+ g_c)``
  (K_c: the group's linear springs' stiffness form; a group at rest at its equilibrium, ``E_c = 0``,
  stays there).  For a ground-mounted absorber at rest this is the barrel's ``sqrt(2 E0 / k)``: the
  travel of the undamped free recoil, never below the damped one.  If this bound keeps *every*
  contact open, none ever closes.
* **Energy** (whatever closes): the mechanical energy of the whole scene never exceeds its value at
  t = 0, so ``d <= sqrt(2 E0 g^T K^+ g)`` over all the springs (a potential well's end for a gas spring):
  :meth:`EnergyBounds.contact_reach <mbs_models.engine.energy_bounds.EnergyBounds.contact_reach>`, the
  bound the early stop uses.  A contact beyond it never closes, whatever the others do.

Both use the early stop's ``ENERGY_SLACK`` on the energies.  A contact reported here therefore truly never
closes -- no warning is ever given for a contact that closes.  The converse does not hold: damping keeps
a contact a little within the bound open too.

Scenes without that bound are never reported: energy injected by the paper's literal reading of the
Hunt-Crossley sign, a load acting for ever (gravity along a cradle), shots or pulses after t = 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..elements.connector import GROUND
from ..scene import Scene
from .energy_bounds import ENERGY_SLACK, EnergyBounds, dissipative
from .mechanism import Mechanism


@dataclass(frozen=True)
class OutOfReach:
    """A contact that cannot close: ``key`` and ``length`` (m) of the scene value that places it (an
    absorber's ``contact.gap``, a stop's ``position``), ``reach`` (m): the bound on the same length the
    barrel can travel to (the free-recoil travel bound)."""

    key: str
    length: float
    reach: float

    def message(self) -> str:
        """One line naming the key and both lengths."""
        return (f"{self.key} = {self.length:g} m is beyond the barrel's free-recoil travel ({self.reach:.4g} m, "
                f"an energy bound): this contact can never close (a length in mm instead of m?)")


def _scene_key(scene: Scene, element: str) -> tuple[str, str, object]:
    """(table key, field, table) of the scene value that places the contact of ``element``."""
    table = dict(scene.elements()).get(element)
    key = next((k for k, t in scene.tables() if t is table), element)
    if hasattr(table, "contact"):
        return f"{key}.contact.gap", "gap", table.contact
    if hasattr(table, "position"):
        return f"{key}.position", "position", table
    return key, "", table


def _free_recoil_reach(mechanism: Mechanism, bounds: EnergyBounds) -> list[float] | None:
    """Bound (m) on each contact's d while no contact has closed (module docstring), or None where the
    scene has a potential that is not a quadratic form (a gas spring)."""
    n = len(mechanism.bodies)
    springs = [c for c in mechanism.connectors if not c.is_contact]
    if any(c.stores_energy and not c.quadratic_potential for c in springs):
        return None
    group = list(range(n))  # union-find over the bodies joined by springs and dampers

    def root(i: int) -> int:
        while group[i] != i:
            group[i] = group[group[i]]
            i = group[i]
        return i

    index = mechanism.body_index
    for c in springs:
        if GROUND not in (c.a, c.b):
            group[root(index[c.a])] = root(index[c.b])
    x0, v0 = mechanism.initial_positions(), mechanism.initial_velocities()
    K = np.zeros((n, n))
    energy = np.zeros(n)  # per group root
    for i, body in enumerate(mechanism.bodies):
        energy[root(i)] += 0.5 * body.mass * v0[i] ** 2
    for c in springs:
        if c.stores_energy:
            g = mechanism.direction(c)
            K += c.quadratic_stiffness * np.outer(g, g)
            body = c.b if c.b != GROUND else c.a
            energy[root(index[body])] += 0.5 * c.quadratic_stiffness * mechanism.relative_at(c, x0) ** 2
    roots = sorted({root(i) for i in range(n)})
    members = {r: [i for i in range(n) if root(i) == r] for r in roots}
    out = []
    for contact in bounds.contacts:
        g = mechanism.direction(contact)
        reach = 0.0
        for r in roots:
            ids = members[r]
            g_c = g[ids]
            if not np.any(g_c):
                continue
            if energy[r] == 0.0:  # at rest with every spring relaxed: at equilibrium for ever
                reach += float(g_c @ np.asarray(x0)[ids])
                continue
            values, vectors = np.linalg.eigh(K[np.ix_(ids, ids)])
            scale = float(np.max(np.abs(values)))
            keep = values > 1e-12 * scale if scale > 0 else np.zeros(len(ids), dtype=bool)
            components = vectors.T @ g_c
            if np.any(np.abs(components[~keep]) > 1e-9 * float(np.max(np.abs(g_c)))):
                reach = math.inf  # a direction without a spring: no bound
                break
            with np.errstate(over="ignore"):  # a spring too weak for double precision: no bound (inf)
                coefficient = 2.0 * float(np.sum(components[keep] ** 2 / values[keep]))
            reach += math.sqrt(coefficient * energy[r] * (1.0 + ENERGY_SLACK))
        out.append(reach)
    return out


def contact_reach_bounds(scene: Scene | Mechanism) -> list[tuple[float, bool]]:
    """Per contact of the scene's :class:`Mechanism` (in its order): ``(reach m, closes_maybe)``, the
    smallest proven bound on its relative coordinate d and whether d may exceed the contact's offset
    (module docstring).  Every reach is inf for a scene without an energy bound."""
    mechanism = scene if isinstance(scene, Mechanism) else Mechanism(scene)
    bounds = EnergyBounds(mechanism)
    if not dissipative(mechanism) or mechanism.last_input_time > 0.0:
        return [(math.inf, True) for _ in bounds.contacts]
    energy = bounds.with_slack(bounds.energy(mechanism.initial_positions(), mechanism.initial_velocities()))
    reach = [bounds.contact_reach(j, energy) for j in range(len(bounds.contacts))]
    free = _free_recoil_reach(mechanism, bounds)
    if free is not None and all(f <= c.offset for f, c in zip(free, bounds.contacts)):
        reach = [min(a, b) for a, b in zip(reach, free)]  # nothing ever closes: the free recoil is the motion
    return [(r, r > c.offset) for r, c in zip(reach, bounds.contacts)]


def contacts_out_of_reach(scene: Scene | Mechanism) -> list[OutOfReach]:
    """The contacts of ``scene`` that can never close (module docstring), in assembly order; [] for a scene
    without an energy bound.  Builds the scene's :class:`Mechanism` unless one is given."""
    mechanism = scene if isinstance(scene, Mechanism) else Mechanism(scene)
    out = []
    for contact, (reach, closes) in zip(mechanism.contacts, contact_reach_bounds(mechanism)):
        if closes or not math.isfinite(reach):
            continue
        key, name, table = _scene_key(mechanism.scene, contact.element)
        length = float(getattr(table, name)) if name else contact.offset
        # the scene value is the offset or its negative (a battery stop's position, the literal gap sign)
        sign = 1.0 if length == contact.offset else -1.0
        out.append(OutOfReach(key, length, sign * reach))
    return out
