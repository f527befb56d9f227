"""The contact-law study (`recoil contact-laws`): engine points on the closed forms, files written."""

from __future__ import annotations

import json

import pytest

from mbs_models.cli import main
from validation.studies.contact_laws import run_study


@pytest.fixture(scope="module")
def study():
    return run_study("standard")


def test_every_engine_point_lies_on_the_closed_form(study):
    assert {p.law for p in study.points} == {"lankarani-nikravesh", "flores", "gonthier", "exact-restitution",
                                             "hunt-crossley", "kelvin-voigt"}
    assert study.worst_error < 5e-5, max(study.points, key=lambda p: p.error)
    for p in study.points:
        if p.law == "exact-restitution":
            assert p.oracle == pytest.approx(p.value, rel=1e-12)  # exactly what was asked


def test_every_law_has_a_loop(study):
    assert set(study.loops) == {"lankarani-nikravesh", "flores", "gonthier", "exact-restitution", "hunt-crossley",
                                "hertz", "kelvin-voigt"}
    for penetration, force in study.loops.values():
        assert len(force) > 10 and force.min() >= 0 and penetration.max() > 0


def test_the_command_writes_the_figure_and_tables(tmp_path, capsys):
    assert main(["contact-laws", "--out", str(tmp_path / "laws")]) == 0
    assert (tmp_path / "laws" / "contact_laws.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    data = json.loads((tmp_path / "laws" / "contact_laws.json").read_text())
    assert data["worst_error"] < 5e-5 and len(data["points"]) == 30
    assert "exact-restitution" in (tmp_path / "laws" / "contact_laws.md").read_text()
    assert "worst engine - closed form" in capsys.readouterr().out


def test_an_unwritable_out_is_refused_before_any_work(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["contact-laws", "--out", str(blocker)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "--out" in err
