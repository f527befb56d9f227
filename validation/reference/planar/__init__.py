"""The planar reference: the gun on its carriage (DESIGN.md, "The recoil axis on a carriage: the planar model").

The axis model of the 1-D reference (every element's connector, mode and event, unchanged) is carried by a
rigid carriage that rests on the ground through supports and may pitch, lift and slide; the equations are
Lagrange's, derived by hand in :mod:`.kinematics` (mass matrix, velocity terms, gravity, point forces).

* :mod:`.kinematics` -- M(q), c(q, q'), gravity, the breech force and the points of the carriage;
* :mod:`.supports` -- a support's normal contact law, friction or dug-in spade, modes and events;
* :mod:`.statics` -- the initial static equilibrium on the supports;
* :mod:`.model` -- the planar state, the right-hand side (with constraint multipliers), energies, shots;
* :mod:`.switching` -- the mode at a restart; :mod:`.solver` -- :func:`solve_planar`;
* :mod:`.result` -- :class:`PlanarResult` (the 1-D metrics plus the carriage's);
* :mod:`.closed_form` -- the quasi-static front load (the oracle of the tests).

:func:`validation.reference.solve_reference` dispatches here for a scene with ``[carriage]``.
"""

from .closed_form import quasi_static_front_load
from .result import PlanarResult
from .solver import build_planar_model, solve_planar

__all__ = ["solve_planar", "build_planar_model", "PlanarResult", "quasi_static_front_load"]
