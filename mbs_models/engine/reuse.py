"""Reuse the assembled Exudyn system across the points of a sweep: :class:`Simulator`.

Many points of a sweep, an optimisation or a study have the same *structure* -- the same bodies,
connectors, loads and user-function backend (:func:`~mbs_models.engine.assembly.structure_key`) -- and
differ only in numbers: masses, stiffnesses, gaps, a law's constants, the initial state.  A
:class:`Simulator` keeps one assembled system per structure and, for the next scene of that structure,
writes the new numbers into it in place (:func:`~mbs_models.engine.assembly.refill`: each body's mass and
initial state, each connector's and load's ``update_items``, which records its user function anew), then
solves it exactly as :func:`~mbs_models.simulate` does.  A scene of a structure not seen yet is assembled
fresh and kept for the next one.

Contract: ``Simulator().simulate(scene, end_time, accuracy, ...)`` returns the same
:class:`~mbs_models.results.result.Result` as ``simulate(scene, end_time, accuracy, ...)`` -- every array and
metric bit for bit (``==``), whatever ran before it (tests/engine/test_reuse.py) -- and raises the same
errors.  Only ``wall_time`` and ``timings`` differ.  A solve that raises discards its system (the next scene
of that structure is assembled fresh).  What is kept is bounded (:attr:`Simulator.max_models` structures,
the least recently used dropped) and released by :meth:`Simulator.close`.

Nothing Exudyn builds can be pickled: a Simulator lives in one process (:func:`process_simulator` gives
each worker process of a sweep its own).

Example::

    >>> from mbs_models import Simulator, model_ii
    >>> with Simulator() as simulator:
    ...     displacements = [simulator.simulate(model_ii(500.0, gap), 10.0, "draft",
    ...                                         stop_when_final=("max_barrel_displacement",)).max_barrel_displacement
    ...                      for gap in (0.0, 0.05, 0.1)]
    >>> len(displacements), simulator.assemblies, simulator.reuses
    (3, 1, 2)
"""

from __future__ import annotations

import os
from collections import OrderedDict
from typing import Sequence

from ..results.result import Result
from ..scene import Scene
from .accuracy import SolverSettings
from .assembly import Assembly, assemble, refill, structure_key
from .mechanism import Mechanism
from .simulation import FreshModels, simulate_with

#: Structures kept by default (each an assembled Exudyn system of a few kB).
DEFAULT_MAX_MODELS = 8


class Simulator(FreshModels):
    """:func:`~mbs_models.simulate` that keeps the assembled systems for the next scenes (module docstring).

    Attributes
    ----------
    max_models: structures kept at most (least recently used dropped first).
    assemblies: how many systems were assembled fresh; ``reuses``: how many solves reused one.
    """

    def __init__(self, max_models: int = DEFAULT_MAX_MODELS):
        if isinstance(max_models, bool) or not isinstance(max_models, int) or max_models < 1:
            raise ValueError(f"max_models must be a whole number >= 1, got {max_models!r}")
        self.max_models = max_models
        self._models: OrderedDict[tuple, Assembly] = OrderedDict()
        self.assemblies = 0
        self.reuses = 0

    def simulate(self, scene: Scene, end_time: float = 10.0, accuracy: str | SolverSettings = "standard", *,
                 user_functions: str | None = None, impact_threshold: float = 1000.0,
                 stop_when_final: Sequence[str] = (), stop_at_rest: bool = True) -> Result:
        """:func:`mbs_models.simulate` (same arguments, result and errors) on a kept system where one fits."""
        return simulate_with(self, scene, end_time, accuracy, user_functions=user_functions,
                             impact_threshold=impact_threshold, stop_when_final=stop_when_final,
                             stop_at_rest=stop_at_rest)

    # ------------------------------------------------------------------ what simulate_with calls
    def acquire(self, scene: Scene, user_functions: str, mechanism: Mechanism) -> Assembly:
        """The kept system of the scene's structure with the scene's numbers written in, or a fresh one."""
        key = structure_key(mechanism, user_functions)
        kept = self._models.pop(key, None)
        if kept is None:
            self.assemblies += 1
            return assemble(scene, user_functions, mechanism)
        try:
            assembly = refill(kept, scene, mechanism, key)
        except BaseException:
            kept.close()
            raise
        self.reuses += 1
        return assembly

    def release(self, assembly: Assembly, failed: bool) -> None:
        """Keep the system for the next scene of its structure, unless its solve raised."""
        if failed or assembly.planar is not None:  # a carriage scene is assembled anew for every solve
            assembly.close()
            return
        self._models[assembly.structure] = assembly
        while len(self._models) > self.max_models:
            _, oldest = self._models.popitem(last=False)
            oldest.close()

    # ------------------------------------------------------------------ lifetime
    def close(self) -> None:
        """Release every kept system."""
        while self._models:
            _, assembly = self._models.popitem()
            assembly.close()

    def __enter__(self) -> "Simulator":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self):  # pragma: no cover - depends on the garbage collector
        try:
            self.close()
        except Exception:
            pass


_PROCESS_SIMULATOR: tuple[int, Simulator] | None = None


def process_simulator() -> Simulator:
    """This process's own :class:`Simulator` (a forked worker gets a new one, never its parent's systems)."""
    global _PROCESS_SIMULATOR
    pid = os.getpid()
    if _PROCESS_SIMULATOR is None or _PROCESS_SIMULATOR[0] != pid:
        if _PROCESS_SIMULATOR is not None and _PROCESS_SIMULATOR[0] != pid:
            _PROCESS_SIMULATOR[1]._models.clear()  # the parent's systems: not ours to release
        _PROCESS_SIMULATOR = (pid, Simulator())
    return _PROCESS_SIMULATOR[1]
