"""Force laws of the recoil mechanism, written once and evaluated by three backends.

* ``"python"``   -- plain floats, used by Exudyn's Python user functions (what people debug with);
* ``"symbolic"`` -- :mod:`exudyn.symbolic` expressions, recorded once and evaluated in C++;
* ``"numpy"``    -- arrays, used in post-processing (peak refinement, energies).

Because every backend runs the *same* law function, they cannot drift apart; a test checks that
the Python and symbolic user functions give the same simulation to 1e-9.

Laws
----
* Asymmetric recoil damper, Eqs. (2)-(3): ``F = c(v) v`` with ``c = recoil`` for ``v > 0`` and
  ``c = counter_recoil`` otherwise (N, v = barrel velocity in m/s).
* Hunt-Crossley contact, Eq. (6) with the sign conventions of DESIGN.md: with penetration ``p``
  (m) and its rate ``p_dot`` (m/s), ``F = k_c p^n_c (1 + lambda p_dot)`` for ``p > 0``, clipped to
  ``F >= 0`` (a contact never pulls).  :class:`~mbs_models.scene.Conventions` switch on the
  paper's literal readings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .scene import Contact, Conventions, RecoilDamper


@dataclass(frozen=True)
class _Ops:
    """The few operations a law needs, for one backend."""

    maximum: Callable[[Any, Any], Any]
    power: Callable[[Any, float], Any]
    choose: Callable[[Any, float, float], Any]  # choose(condition, value_if_true, value_if_false)


def _py_choose(condition, a, b):
    return a if condition else b


PYTHON_OPS = _Ops(maximum=max, power=math.pow, choose=_py_choose)
NUMPY_OPS = _Ops(maximum=np.maximum, power=np.power, choose=np.where)


def _symbolic_ops() -> _Ops:
    import exudyn

    esym = exudyn.symbolic

    def choose(condition, a, b):
        return esym.IfThenElse(condition, esym.Real(a), esym.Real(b))

    return _Ops(maximum=esym.max, power=esym.pow, choose=choose)


def recoil_damper_force(velocity, damper: RecoilDamper, ops: _Ops = PYTHON_OPS):
    """Asymmetric damper force in N (Eqs. 2-3): ``c(v) * v``, positive opposes positive velocity."""
    return ops.choose(velocity > 0, damper.recoil, damper.counter_recoil) * velocity


def contact_penetration(relative_position, contact: Contact, conventions: Conventions):
    """Penetration ``p`` in m from ``x_M - x_m``: ``- gap`` (DESIGN) or ``+ gap`` (literal Eq. 6)."""
    sign = 1.0 if conventions.literal_gap_sign else -1.0
    return relative_position + sign * contact.gap


def hunt_crossley_force(relative_position, relative_velocity, contact: Contact, conventions: Conventions,
                        ops: _Ops = PYTHON_OPS):
    """Hunt-Crossley contact force in N (Eq. 6), >= 0, pushing the absorber away from wall A.

    Parameters
    ----------
    relative_position: ``x_M - x_m`` in m (barrel minus absorber position).
    relative_velocity: ``p_dot = v_M - v_m`` in m/s.
    """
    penetration = ops.maximum(contact_penetration(relative_position, contact, conventions), 0.0)
    damping_sign = -1.0 if conventions.literal_lambda_sign else 1.0
    force = (contact.stiffness * ops.power(penetration, contact.exponent)
             * (1.0 + damping_sign * contact.damping_factor * relative_velocity))
    force = ops.maximum(force, 0.0)
    if conventions.compression_only:
        force = force * ops.choose(relative_velocity > 0, 1.0, 0.0)
    return force


def contact_elastic_energy(relative_position, contact: Contact, conventions: Conventions):
    """Elastic energy stored in the contact, ``k_c p^(n+1) / (n+1)`` in J (numpy backend)."""
    p = np.maximum(contact_penetration(np.asarray(relative_position, dtype=float), contact, conventions), 0.0)
    return contact.stiffness * p ** (contact.exponent + 1.0) / (contact.exponent + 1.0)


# -------------------------------------------------------------------------------------------------
# Exudyn user functions: signature of ObjectConnectorCoordinateSpringDamper.springForceUserFunction
# (mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset) -> force.
# For the contact connector the markers are [absorber, barrel], so displacement = x_M - x_m.

def recoil_damper_user_function(damper: RecoilDamper, ops: _Ops = PYTHON_OPS):
    """User function of the recoil-damper connector (markers [ground, barrel])."""

    def user_function(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        return recoil_damper_force(velocity, damper, ops)

    return user_function


def contact_user_function(contact: Contact, conventions: Conventions, ops: _Ops = PYTHON_OPS):
    """User function of the contact connector (markers [absorber, barrel])."""

    def user_function(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        return hunt_crossley_force(displacement, velocity, contact, conventions, ops)

    return user_function


def make_user_function(mbs, python_function, backend: str, item_index):
    """Return what to pass as ``springForceUserFunction``: the Python callable, or its symbolic record.

    ``backend`` is ``"python"`` or ``"symbolic"``.  The symbolic object must be kept alive as long as
    the system exists (the assembly keeps it).
    """
    if backend == "python":
        return python_function
    from exudyn.advancedUtilities import CreateSymbolicUserFunction

    return CreateSymbolicUserFunction(mbs, python_function, "springForceUserFunction", item_index)
