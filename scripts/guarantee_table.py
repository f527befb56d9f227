#!/usr/bin/env python
"""The worst errors over the hard cases, per accuracy preset: the "worst" numbers of the guarantee table.

    python scripts/guarantee_table.py          # all hard cases, three presets (a few minutes)

For each preset: the largest of each error of :func:`validation.studies.guarantee.errors_against_reference`
over :data:`validation.studies.hard_cases.HARD_CASES` (the engine against the independent reference), and
the tolerance it is checked against.  Not a test: the tests check the tolerances; this measures the margin.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mbs_models import simulate  # noqa: E402
from validation.studies.guarantee import TOLERANCES, errors_against_reference, reference_for  # noqa: E402
from validation.studies.hard_cases import HARD_CASES  # noqa: E402

KEYS = {"energy": "energy", "x": "metric", "v": "metric", "dissipated": "metric", "F": "force", "S": "force",
        "peaks": "impact_peak", "time": "time"}


def main() -> int:
    for accuracy in TOLERANCES:
        worst = {key: (0.0, "") for key in KEYS}
        for case in HARD_CASES:
            result = simulate(case.scene, case.end_time, accuracy)
            end = min(case.end_time, case.reference_end_time or case.end_time)
            ref = reference_for(case.scene, end, tuple(sorted(case.reference_options.items())), accuracy)
            errors = errors_against_reference(result, ref, TOLERANCES[accuracy]["time"])
            for key in KEYS:
                if errors[key] > worst[key][0]:
                    worst[key] = (errors[key], case.name)
        print(f"{accuracy}:")
        for key, (value, name) in worst.items():
            print(f"  {key:10s} worst {value:.2g} ({name}), tolerance {TOLERANCES[accuracy][KEYS[key]]:g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
