"""The engine: assembly of a scene's elements into Exudyn, the solve, and the checks around it.

* :mod:`.mechanism` -- the scene as bodies and connectors (what every stage iterates over);
* :mod:`.assembly` -- the Exudyn system;
* :mod:`.simulation` -- :func:`simulate`, the one entry point;
* :mod:`.accuracy` -- solver settings and the accuracy presets;
* :mod:`.stability` -- contact time scales, unsafe steps refused, stepped-over contacts, energy balance;
* :mod:`.guard` -- the step budget and the cap on stored samples of adaptive solves;
* :mod:`.time_scales` -- springs and dampers too stiff for the budget, refused before the solve;
* :mod:`.energy_bounds` -- energy bounds on what a dissipative scene can still do; :mod:`.finality` -- the early
  stop once they prove the peak metrics final (:mod:`.final_metrics` re-exports both);
* :mod:`.reach` -- contacts that can never close (a gap beyond the barrel's free-recoil travel).

This package imports Exudyn, choosing its fast compiled module first (:mod:`.exudyn_build`).
"""

from .exudyn_build import load_exudyn as _load_exudyn

_load_exudyn()  # before any module of the engine imports Exudyn
