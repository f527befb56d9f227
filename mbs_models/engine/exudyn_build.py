"""Which of Exudyn's two compiled modules the engine runs on, chosen once, before Exudyn is first imported.

Exudyn ships ``exudynCPP`` (baseline instruction set, range-checked) and ``exudynCPPfast`` (no range checks, AVX2
vector code).  The engine asks for the fast one (``sys.exudynFast = True``) unless

* the environment says ``RECOIL_EXUDYN_BUILD=checked`` (the range-checked module: to debug, or to compare), or
* the process already chose (``sys.exudynFast`` set by the caller) or already imported Exudyn (then that module
  stays: one process has one Exudyn).

Exudyn itself falls back to the checked module on a CPU without AVX2.  The fast module prints a line to stdout
when it loads; it is swallowed here (``recoil run --json`` prints JSON only).  The same runs give the same
numbers on both modules (measured bit-identical on the paper's cases and the carriage scenes; a test checks
every shipped scene within the guarantee), at ~10 % less time per step (``scripts/bench.py``).
"""

from __future__ import annotations

import contextlib
import io
import os
import sys

#: The environment variable that selects the module: ``fast`` (default) or ``checked``.
BUILD_VARIABLE = "RECOIL_EXUDYN_BUILD"


def load_exudyn():
    """Import Exudyn with the module chosen as the module docstring says; return the ``exudyn`` package."""
    if "exudyn" not in sys.modules and not hasattr(sys, "exudynFast"):
        sys.exudynFast = os.environ.get(BUILD_VARIABLE, "fast").strip().lower() != "checked"
    with contextlib.redirect_stdout(io.StringIO()):
        import exudyn
    return exudyn


def exudyn_build() -> str:
    """``"fast"`` or ``"checked"``: the module this process runs on."""
    return "fast" if "exudyn.exudynCPPfast" in sys.modules else "checked"


__all__ = ["load_exudyn", "exudyn_build", "BUILD_VARIABLE"]
