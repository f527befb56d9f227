"""Result of the planar reference solve: the 1-D result's metrics of the axis, plus the carriage's.

:class:`PlanarResult` is a :class:`~validation.reference.result.ReferenceResult` whose model is the planar one
(:class:`.model.PlanarModel`): every history and metric of the axis (barrel displacement, contact forces,
``support_force`` = the force the recoil elements transmit along the axis, shots) is read the same way from the
planar state, and it adds (DESIGN.md, "The recoil axis on a carriage", outputs):

* histories: :meth:`carriage_position` (x, y of the carriage's CG, m), :meth:`carriage_pitch` (rad), per support
  :meth:`support_normal_force` (N >= 0), :meth:`support_tangential_force` (N), :meth:`support_height` (m, y of
  the point; < 0 pressed into the ground);
* metrics, refined on the dense output like every peak: ``max_carriage_pitch`` (max |phi - phi_static|, rad),
  ``max_lift`` (largest height of any support, m; 0 if none leaves the ground), ``lift_off_time`` (the first
  segment end after t = 0 at which the normal law of a support loaded at rest stops acting: it leaves the ground,
  or N reaches 0; None if never), ``max_carriage_displacement`` (max |x - x_static| of the CG, m), ``stability_margin``
  (min over the supports loaded at rest and time of ``N_i(t) / N_i(static)``) and :meth:`supports` (per support its static, min and
  max normal force);
* the energy balance with gravity's potential of every body and the supports' stored and dissipated energy.
"""

from __future__ import annotations

from functools import cached_property
from typing import Any

import numpy as np

from ..result import ReferenceResult, _peak


class PlanarResult(ReferenceResult):
    """Dense planar reference solution (module docstring); ``model`` is a :class:`.model.PlanarModel`."""

    # ---------------------------------------------------------------- histories
    def _support_index(self, name: str) -> int:
        names = [s.name for s in self.model.supports]
        if name not in names:
            raise KeyError(f"no support {name!r}; the carriage has: {', '.join(names)}")
        return names.index(name)

    def _cg(self, y):
        g = self.model.geometry
        X, Y, phi, *_ = self.model.carriage(y)
        return g.place(X, Y, phi, g.center_of_mass)

    def carriage_position(self, t):
        """(x, y) of the carriage's CG (m), shape (2,) or (2, len(t))."""
        return self._per_segment(t, lambda mode, y, ts: np.array(self._cg(y)), 2)

    def carriage_pitch(self, t):
        """phi (rad, counter-clockwise, nose up)."""
        slot = self.model.carriage_slot + 2
        return self._per_segment(t, lambda mode, y, ts: y[slot], None)

    def _support_value(self, name: str, t, pick):
        k = self._support_index(name)
        model = self.model
        return self._per_segment(t, lambda mode, y, ts: pick(model.evaluate(mode, y, t=ts), k, y), None)

    def support_normal_force(self, name: str, t):
        """N (N, >= 0) of support ``name``."""
        return self._support_value(name, t, lambda ev, k, y: np.maximum(ev.normal[k], 0.0))

    def support_tangential_force(self, name: str, t):
        """T (N, ground frame, + forward) of support ``name``."""
        return self._support_value(name, t, lambda ev, k, y: ev.tangential[k])

    def support_height(self, name: str, t):
        """y of support ``name``'s point (m)."""
        k = self._support_index(name)
        motion = self.model.support_motion(self.model.supports[k])
        return self._per_segment(t, lambda mode, y, ts: motion(y)[1], None)

    # ---------------------------------------------------------------- energy
    def energy_components(self, t) -> dict[str, np.ndarray]:
        """The 1-D components (kinetic energies now of the carriage and of every axis body in the plane), plus
        ``potential:gravity`` (``g sum m_k y_k``), ``stored:support.NAME`` and ``dissipated:support.NAME`` (J)."""
        model = self.model
        keys: list[str] = []

        def parts(mode, y, ts):
            found = {**{f"kinetic:{k}": v for k, v in model.kinetic_energies(y).items()},
                     **{f"stored:{k}": v for k, v in model.axis.stored_energies(y).items()},
                     **{f"stored:{k}": v for k, v in model.support_energies(mode, y).items()},
                     "potential:gravity": model.gravity_potential(y),
                     **{f"dissipated:{k}": v for k, v in model.axis.dissipated_energies(y).items()},
                     **{f"dissipated:{k}": v for k, v in model.support_dissipation(y).items()}}
            keys[:] = list(found)
            return np.array([np.broadcast_to(np.asarray(v, dtype=float), np.shape(y[0])) for v in found.values()])
        rows = len(parts(self.segments[0].mode, self.segments[0].sol(0.0), 0.0))
        values = self._per_segment(t, parts, rows)
        return dict(zip(keys, values))

    # ---------------------------------------------------------------- metrics
    @cached_property
    def _static(self) -> dict:
        return self.model.static

    @cached_property
    def _pitch_max(self) -> tuple[float, float]:
        slot, phi0 = self.model.carriage_slot, self._static["phi"]
        return _peak(self.segments, lambda mode, y, t: np.abs(y[slot + 2] - phi0),
                     lambda mode, y, t: np.sign(y[slot + 2] - phi0) * y[slot + 5])

    @cached_property
    def _displacement_max(self) -> tuple[float, float]:
        g, model = self.model.geometry, self.model
        x0 = float(g.place(0.0, self._static["Y"], self._static["phi"], g.center_of_mass)[0])

        def velocity(y):
            X, Y, phi, dX, dY, dphi = model.carriage(y)
            return g.point_velocity(phi, dX, dY, dphi, g.center_of_mass)[0]
        return _peak(self.segments, lambda mode, y, t: np.abs(self._cg(y)[0] - x0),
                     lambda mode, y, t: np.sign(self._cg(y)[0] - x0) * velocity(y))

    @cached_property
    def _lift_max(self) -> tuple[float, float]:
        best = (0.0, 0.0)
        for s in self.model.supports:
            motion = self.model.support_motion(s)
            t_peak, height = _peak(self.segments, lambda mode, y, t: motion(y)[1], lambda mode, y, t: motion(y)[3])
            if height > best[1]:
                best = (t_peak, height)
        return best

    @cached_property
    def _normal_extremes(self) -> list[dict[str, Any]]:
        """Per support: static, min and max normal force (N)."""
        model, out = self.model, []
        for k, s in enumerate(model.supports):
            def normal(mode, y, t, k=k):
                return np.maximum(model.evaluate(mode, y, t=t).normal[k], 0.0)
            largest = _peak(self.segments, normal, lambda mode, y, t: None)[1]
            smallest = -_peak(self.segments, lambda mode, y, t: -normal(mode, y, t), lambda mode, y, t: None)[1]
            out.append({"name": s.name, "static_normal_force": float(self._static["normal"][k]),
                        "min_normal_force": float(smallest), "max_normal_force": float(largest)})
        return out

    @property
    def max_carriage_pitch(self) -> float:
        """max |phi(t) - phi_static| (rad)."""
        return float(self._pitch_max[1])

    @property
    def max_carriage_displacement(self) -> float:
        """max |x(t) - x_static| of the carriage's CG (m)."""
        return float(self._displacement_max[1])

    @property
    def max_lift(self) -> float:
        """Largest height of any support above the ground (m); 0 if none leaves it."""
        return max(float(self._lift_max[1]), 0.0)

    @property
    def lift_off_time(self) -> float | None:
        """First time (s) after t = 0 at which a support loaded at rest (``N_i(static) > 0``, as the stability
        margin counts them) has its normal force reach 0 (its law stops acting); None if never."""
        loaded = [m["static_normal_force"] > 0.0 for m in self._normal_extremes]
        before = None
        for seg in self.segments:
            holding = [s.holding for s in seg.mode.supports]
            if before is not None and seg.t0 > 0.0 and any(
                    b and not h and k for b, h, k in zip(before, holding, loaded)):
                return float(seg.t0)
            before = holding
        return None

    @property
    def stability_margin(self) -> float:
        """min over the supports with a static load ``N_i(static) > 0`` and time of ``N_i(t) / N_i(static)`` (1: never
        unloads; 0: a support lets go); a support carrying nothing at rest is not part of it."""
        return min(m["min_normal_force"] / m["static_normal_force"] for m in self._normal_extremes
                   if m["static_normal_force"] > 0.0)

    def supports(self) -> list[dict[str, Any]]:
        """Per support: ``{name, static_normal_force, min_normal_force, max_normal_force}`` (N)."""
        return [dict(m) for m in self._normal_extremes]

    def metrics(self) -> dict[str, Any]:
        """The 1-D metrics of the axis plus the carriage's (module docstring) and ``supports``."""
        return {**super().metrics(), "max_carriage_pitch": self.max_carriage_pitch, "max_lift": self.max_lift,
                "lift_off_time": self.lift_off_time, "max_carriage_displacement": self.max_carriage_displacement,
                "stability_margin": self.stability_margin, "supports": self.supports()}

    def sample(self, n=None) -> dict[str, np.ndarray]:
        """The 1-D samples plus ``carriage_x``, ``carriage_y`` (m), ``carriage_pitch`` (rad) and per support
        ``N:NAME``, ``T:NAME`` (N), ``y:NAME`` (m)."""
        out = super().sample(n)
        t = out["t"]
        out["carriage_x"], out["carriage_y"] = self.carriage_position(t)
        out["carriage_pitch"] = self.carriage_pitch(t)
        for s in self.model.supports:
            out[f"N:{s.name}"] = self.support_normal_force(s.name, t)
            out[f"T:{s.name}"] = self.support_tangential_force(s.name, t)
            out[f"y:{s.name}"] = self.support_height(s.name, t)
        return out
