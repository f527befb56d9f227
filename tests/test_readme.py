"""The README's numbers are the library's numbers (Table 2 is recomputed and compared)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from mbs_models import model_i, model_ii, simplified_model, simulate

README = Path(__file__).resolve().parent.parent / "README.md"
_ROW = re.compile(r"^\| (simplified|model \(i\)|model \(ii\)) \| (any|\d+) \| (0\.\d{4}) \| (0\.\d{4}) \| ([+−-]\d+\.\d+) \|$")


def _readme_table2():
    rows = [m.groups() for line in README.read_text().splitlines() if (m := _ROW.match(line))]
    assert len(rows) == 7, "README Table 2 must list the simplified model and 3 masses of each model"
    return rows


@pytest.mark.parametrize("row", _readme_table2(), ids=lambda r: f"{r[0]}-{r[1]}")
def test_readme_table2_matches_the_engine(row):
    model, mass, ours, paper, difference_mm = row
    if model == "simplified":
        scene = simplified_model()
    else:
        scene = (model_i if model == "model (i)" else model_ii)(float(mass), 0.0)
    x_max = simulate(scene, 10.0).max_barrel_displacement
    assert f"{x_max:.4f}" == ours
    assert float(difference_mm.replace("−", "-")) == pytest.approx((x_max - float(paper)) * 1e3, abs=0.006)


_GUARANTEE_ROW = re.compile(r"^\| `(draft|standard|reference)` \| (\S+) \(worst [^)]*\) \| (\S+) \(worst [^)]*\) \| "
                            r"(\S+) \(worst [^)]*\) \| (\S+) \(worst [^)]*\) \| (\d+) (ms|µs) \(worst [^)]*\) \|$")


def test_readme_guarantees_are_the_tested_tolerances():
    """The "What is guaranteed" table states exactly the bounds tests/test_hard_cases.py enforces."""
    from validation.studies.guarantee import TOLERANCES

    rows = [m.groups() for line in README.read_text().splitlines() if (m := _GUARANTEE_ROW.match(line))]
    assert [r[0] for r in rows] == list(TOLERANCES)
    for preset, energy, metric, force, impact_peak, time_value, unit in rows:
        tol = TOLERANCES[preset]
        assert (float(energy), float(metric), float(force), float(impact_peak)) == (
            tol["energy"], tol["metric"], tol["force"], tol["impact_peak"]), preset
        assert float(time_value) * (1e-3 if unit == "ms" else 1e-6) == pytest.approx(tol["time"], rel=1e-12), preset
