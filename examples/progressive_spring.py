"""A progressive recoil spring ``F = k1 x + k3 x^3``, written as a user would: outside the package.

This one module is the whole element (README, "Adding your own element"):

* its scene table ``[progressive_spring]`` (:class:`ProgressiveSpring`: ``linear_stiffness`` k1 in N/m and
  ``cubic_stiffness`` k3 in N/m^3, both >= 0), registered with :func:`mbs_models.register_element`;
* its connector, ground -> barrel, which gives **only its force law**: the stored energy
  ``U = k1 x^2 / 2 + k3 x^4 / 4``, the tangent stiffness and the force bound of the early stop are derived from
  the law by :class:`mbs_models.elements.Connector`;
* its outputs (``OUTPUTS``, :mod:`mbs_models.elements.declaration`): the spring's force history ``force`` (N,
  a panel of ``recoil run --plot``, a column of ``--csv``) and its largest magnitude ``peak_force`` (N: in
  ``Result.element_metrics``, ``recoil run --json`` as ``{"progressive_spring": {"peak_force": ...}}`` and the
  sweep column ``progressive_spring.peak_force``);
* its term of the independent reference (:mod:`validation.reference`), written from the equations above and
  registered with :func:`validation.reference.terms.register_term`.

Use it from Python (``import progressive_spring`` before loading a scene with the table) or on the command
line: ``recoil --plugin examples/progressive_spring.py run examples/progressive_spring.toml``.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from mbs_models import register_element
from mbs_models.elements import GROUND, Connector, Rule, Table
from mbs_models.elements.declaration import History, Metric, Outputs
from validation.reference import model as reference
from validation.reference.terms import register_term

BARREL = "barrel"


# ---------------------------------------------------------------------------------------------- the engine's side
@dataclass(frozen=True)
class ProgressiveSpring(Table):
    """A progressive recoil spring between the ground and the barrel, ``F = k1 x + k3 x^3`` (N).

    Attributes: linear_stiffness k1 in N/m, cubic_stiffness k3 in N/m^3 (both >= 0).
    """

    linear_stiffness: float
    cubic_stiffness: float
    TABLE: ClassVar[str] = "progressive_spring"
    ORDER: ClassVar[int] = 25
    SINCE_VERSION: ClassVar[int] = 2
    RULES: ClassVar = {"linear_stiffness": Rule(0.0, unit="N/m"), "cubic_stiffness": Rule(0.0, unit="N/m^3")}
    #: the spring's force F(x_M) (N) at the output times, and its largest magnitude over the run (N)
    OUTPUTS: ClassVar = Outputs(
        histories=(History("force", "N", lambda run: run.force(), panel="spring force [kN]", scale=1e-3),),
        metrics=(Metric("peak_force", "N", lambda run: float(np.max(np.abs(run.history("force"))))),))

    def bodies(self, scene, name: str) -> list:
        return []

    def connectors(self, scene, name: str) -> list:
        return [ProgressiveSpringConnector(name, name, GROUND, BARREL, self.linear_stiffness, self.cubic_stiffness)]


class ProgressiveSpringConnector(Connector):
    """``F(d) = k1 d + k3 d^3`` (N), ``d = x_M`` (m): the law, and nothing else."""

    def __init__(self, name: str, element: str, a: str, b: str, k1: float, k3: float):
        super().__init__(name, element, a, b)
        self.k1, self.k3 = float(k1), float(k3)

    def law(self, d, rate, ops):
        return self.k1 * d + self.k3 * d * d * d


register_element(ProgressiveSpring)


# ---------------------------------------------------------------------------------------------- the reference's side
class ReferenceProgressiveSpring(reference.Connector):
    """The reference's progressive spring, given by its law ``F = k1 d + k3 d^3`` (and ``dF/dt = (k1 + 3 k3 d^2)
    d'``): the stored energy ``k1 d^2 / 2 + k3 d^4 / 4``, the force at rest and the force bound of the early stop
    are derived from the law by :class:`validation.reference.model.Connector`."""

    dissipates = False
    nonlinear_potential = True  # not k d^2 / 2: the reference's early stop bounds it with the barrel's stops

    def __init__(self, name: str, a: str, b: str, k1: float, k3: float):
        super().__init__(name, a, b)
        self.k1, self.k3 = float(k1), float(k3)

    def law(self, d, rate, state=None):
        return self.k1 * d + self.k3 * d * d * d

    def force_rate(self, state, d, rate, acceleration):
        return (self.k1 + 3.0 * self.k3 * d * d) * rate


class ReferenceTerm:
    """The reference term of ``[progressive_spring]``."""

    TABLES = ("progressive_spring",)

    @staticmethod
    def build(builder, key: str, table) -> None:
        builder.add_connector(ReferenceProgressiveSpring(key, reference.GROUND, reference.BARREL,
                                                         table.linear_stiffness, table.cubic_stiffness))


register_term(ReferenceTerm)


if __name__ == "__main__":  # python examples/progressive_spring.py [scene.toml]
    from pathlib import Path

    from mbs_models import load_scene, simulate

    path = sys.argv[1] if len(sys.argv) > 1 else Path(__file__).with_name("progressive_spring.toml")
    result = simulate(load_scene(path), end_time=3.0)
    print(f"max barrel displacement {result.max_barrel_displacement:.6f} m, "
          f"peak force on the mount {result.peak_support_force:.1f} N, "
          f"peak spring force {result.element_metrics['progressive_spring']['peak_force']:.1f} N")
