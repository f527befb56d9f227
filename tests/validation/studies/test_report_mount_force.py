"""The report's verdict on the force on the mount, from Table 2's rows (hand-made numbers)."""

from __future__ import annotations

from validation.studies.report import mount_force_sentences


def _row(model: str, mass: float, x_max: float, force: float | None) -> dict:
    return {"model": model, "absorber_mass": mass, "engine": x_max, "peak_support_force": force}


def test_lowest_force_and_the_trade_off_with_the_recoil_length_at_each_mass():
    rows = [_row("simplified", 100.0, 0.22, 7000.0), _row("model (i)", 100.0, 0.21, 6000.0),
            _row("model (ii)", 100.0, 0.16, 9000.0),
            _row("simplified", 500.0, 0.22, 7000.0), _row("model (i)", 500.0, 0.21, 8000.0),
            _row("model (ii)", 500.0, 0.16, 5000.0),
            _row("simplified", 1000.0, 0.22, 7000.0), _row("model (i)", 1000.0, 0.21, 6500.0)]  # (ii) missing
    assert mount_force_sentences(rows) == [
        ("m = 100 kg: model (i) moderates the force on the mount most, 6.00 kN (simplified 7.00 kN, model (ii) "
         "9.00 kN); model (ii) recoils least, 160.0 mm against 210.0 mm, but pushes 50.0 % harder on the mount."),
        ("m = 500 kg: model (ii) moderates the force on the mount most, 5.00 kN (simplified 7.00 kN, model (i) "
         "8.00 kN), and also recoils least (160.0 mm)."),
    ]  # two different models lowest: no sentence for every mass


def test_one_model_lowest_at_every_mass_with_a_trade_off_everywhere():
    rows = []
    for mass, force_i in ((100.0, 6900.0), (500.0, 6700.0), (1000.0, 6300.0)):
        rows += [_row("simplified", mass, 0.2215, 6950.0), _row("model (i)", mass, 0.21, force_i),
                 _row("model (ii)", mass, 0.15, 8000.0)]
    sentences = mount_force_sentences(rows)
    assert len(sentences) == 4
    assert sentences[-1] == ("At every absorber mass, model (i) moderates the force on the mount most; the shortest "
                             "recoil comes with a higher force on the mount: a lower displacement is not a lower "
                             "load on the support.")


def test_no_verdict_without_forces():
    rows = [_row(model, 100.0, 0.2, None) for model in ("simplified", "model (i)", "model (ii)")]
    assert mount_force_sentences(rows) == []
