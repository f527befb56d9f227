"""``recoil plot-sweep``: writes a PNG; bad input is one line on stderr and exit code 2."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from mbs_models.cli import main


@pytest.fixture
def table_file(tmp_path):
    rows = [{"absorber.mass": m, "contact.gap": g, "max_barrel_displacement": 0.2 - 1e-5 * m + 0.1 * g,
             "peak_support_force": 7000.0 - m, "status": "ok" if (m, g) != (500.0, 0.0) else "SimulationError",
             "error": "" if (m, g) != (500.0, 0.0) else "failed"}
            for m in (100.0, 500.0, 1000.0) for g in np.linspace(0.0, 0.12, 5)]
    path = tmp_path / "sweep.csv"
    pd.DataFrame(rows).to_csv(path, index=False)
    return path


@pytest.mark.parametrize("extra", [[], ["--kind", "map"], ["--kind", "tradeoff"],
                                   ["--x", "absorber.mass", "--hue", "contact.gap", "--y", "peak_support_force"]])
def test_writes_png(table_file, tmp_path, capsys, extra):
    out = tmp_path / "fig" / "plot.png"
    assert main(["plot-sweep", str(table_file), "--out", str(out), *extra]) == 0
    captured = capsys.readouterr()
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    from matplotlib.image import imread
    assert imread(out).shape[0] > 300  # decodes
    assert "skipped 1 failed row(s)" in captured.err
    assert f"wrote {out}" in captured.out


@pytest.mark.parametrize("args, text", [
    (["missing.csv", "--out", "a.png"], "no such file"),
    (["{table}", "--out", "a.pdf"], "--out: must be a .png file"),
    (["{table}", "--out", "a.png", "--x", "contact.gapp"],
     "--x: unknown column 'contact.gapp'; did you mean 'contact.gap'?"),
    (["{table}", "--out", "a.png", "--y", "peak_suport_force"], "did you mean 'peak_support_force'"),
    (["{table}", "--out", "a.png", "--kind", "pie"], "invalid choice"),
    (["{table}"], "--out"),
])
def test_bad_input_is_one_line_exit_2(table_file, tmp_path, capsys, monkeypatch, args, text):
    monkeypatch.chdir(tmp_path)
    args = [a.replace("{table}", str(table_file)) for a in args]
    assert main(["plot-sweep", *args]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and text in lines[0] and lines[0].startswith("recoil: error:"), captured.err
    assert captured.out == "" and not list(tmp_path.glob("*.png")) and not list(tmp_path.glob("*.pdf"))
