"""Firing (mbs_models.elements.firing): the gas after-effect, the breech-force pulse and bursts.

Closed forms are derived here, not taken from the code: a free barrel (no spring, no damper) under a
piecewise-linear force F(t) has ``v(t) = integral_0^t F / M`` and ``x(t) = integral_0^t v``; under a burst
of impulses it moves with ``v = k v0`` after the k-th shot.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mbs_models import Barrel, Firing, Scene, SceneError, load_scene, scene_from_dict, scene_to_toml, simplified_model, simulate
from mbs_models.cli import main
from mbs_models.elements.firing import Burst, Pulse
from mbs_models.engine.accuracy import ACCURACY_PRESETS
from mbs_models.engine.assembly import assemble
from mbs_models.engine.mechanism import Mechanism
from mbs_models.engine.simulation import segment_plan

PRESETS = ("draft", "standard", "reference")
#: the pulse of DESIGN.md's example (s, N)
TIMES, FORCES = (0.0, 0.002, 0.006, 0.012), (0.0, 2.0e6, 6.0e5, 0.0)
MASS = 5600.0


def pulse_mapping(**pulse) -> dict:
    return {"version": 2, "name": "pulse", "barrel": {"mass": MASS},
            "firing": {"projectile_mass": 6.86, "muzzle_velocity": 564.0,
                       "pulse": {"times": list(TIMES), "forces": list(FORCES), **pulse}},
            "recoil_spring": {"stiffness": 27500.0}, "recoil_damper": {"recoil": 6239.0, "counter_recoil": 14050.0}}


def free_barrel(firing: Firing, burst: Burst | None = None) -> Scene:
    return Scene(barrel=Barrel(MASS), firing=firing, burst=burst, name="free barrel")


def breech_pressure_table(points: int = 401) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """A measured-looking breech force (issue #19): the smooth rise and decay ``2 MN (t / t_p)^2 exp(2 (1 - t / t_p))``
    (peak 2 MN at t_p = 2 ms) sampled at ``points`` unevenly spaced times over 12 ms, ``t_i = 12 ms (i / n)^1.37``
    (n = points - 1; denser early, no point a multiple of the engine's steps).  It ends at 0.16 % of its peak: a
    small jump to 0."""
    times = tuple(0.012 * (i / (points - 1)) ** 1.37 for i in range(points))
    return times, tuple(2.0e6 * (t / 0.002) ** 2 * math.exp(2.0 * (1.0 - t / 0.002)) for t in times)


def exact_free_barrel(times, forces, t: float) -> tuple[float, float]:
    """``(x m, v m/s)`` at ``t`` of the free barrel (mass MASS, at rest at x = 0) under the force linear between the
    table's points and 0 outside: on ``[t_i, t_i+1]`` with slope ``s``, ``v`` gains ``(F_i h + s h^2 / 2) / M`` and
    ``x`` gains ``v_i h + (F_i h^2 / 2 + s h^3 / 6) / M`` (exact polynomial integration)."""
    v = x = 0.0
    for i in range(len(times) - 1):
        t0, t1 = times[i], times[i + 1]
        h = min(max(t - t0, 0.0), t1 - t0)
        slope = (forces[i + 1] - forces[i]) / (t1 - t0)
        x += v * h + (forces[i] * h ** 2 / 2 + slope * h ** 3 / 6) / MASS
        v += (forces[i] * h + slope * h ** 2 / 2) / MASS
    return x + v * max(t - times[-1], 0.0), v


# ------------------------------------------------------------------ the momentum
def test_the_gas_after_effect_adds_the_charge_momentum():
    firing = Firing(projectile_mass=6.86, muzzle_velocity=564.0, charge_mass=2.0, gas_velocity=1400.0)
    assert firing.momentum == pytest.approx(6.86 * 564.0 + 2.0 * 1400.0, rel=1e-15)
    scene = simplified_model().with_changes(firing=firing)
    assert scene.initial_velocity == pytest.approx((6.86 * 564.0 + 2800.0) / 5600.0, rel=1e-15)
    # no charge: exactly the paper's v0
    assert Firing(projectile_mass=6.86, muzzle_velocity=564.0).initial_velocity(5600.0) == 6.86 * 564.0 / 5600.0


def test_a_pulse_scaled_to_the_momentum_has_the_momentum_as_impulse():
    scene = scene_from_dict(pulse_mapping(scale_to_momentum=True))
    assert scene.initial_velocity == 0.0
    assert scene.firing.pulse.impulse == pytest.approx(0.5 * 0.002 * 2e6 + 0.5 * 0.004 * 2.6e6 + 0.5 * 0.006 * 6e5)
    load = Mechanism(scene).loads[0]
    t = np.linspace(-0.001, 0.013, 14001)
    impulse = np.trapezoid(load.force(t), t)
    assert impulse == pytest.approx(6.86 * 564.0, rel=1e-6)


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize("path, value, key, text", [
    ("firing.pulse.times", [0.0, 0.002, 0.002, 0.012], "firing.pulse.times.2", "must increase"),
    ("firing.pulse.times", [0.0, -0.002, 0.006, 0.012], "firing.pulse.times.1", ">= 0"),
    ("firing.pulse.forces", [0.0, 2e6, -1.0, 0.0], "firing.pulse.forces.2", ">= 0"),
    ("firing.pulse.forces", [0.0, 2e6, 0.0], "firing.pulse.forces", "one force per time"),
    ("firing.pulse.forces", [0.0, 0.0, 0.0, 0.0], "firing.pulse.forces", "all 0"),
    ("firing.pulse.forces", "2e6", "firing.pulse.forces", "list of numbers"),
    ("firing.pulse.times", [0.0], "firing.pulse.times", "at least two"),
    ("firing.pulse.scale_to_momentum", "yes", "firing.pulse.scale_to_momentum", "true or false"),
    ("firing.pulse.file", "x.csv", "firing.pulse.file", "not both"),
    ("firing.pulse.tims", [0.0, 1.0], "firing.pulse.tims", "did you mean 'times'"),
    ("firing.charge_mass", -1.0, "firing.charge_mass", ">= 0 kg"),
    ("firing.charge_mass", 2.0, "firing.gas_velocity", "missing"),
    ("firing.gas_velocity", 0.0, "firing.gas_velocity", "> 0 m/s"),
    ("burst", {"shots": 0, "interval": 1.0}, "burst.shots", "[1, 1000]"),
    ("burst", {"shots": 2.5, "interval": 1.0}, "burst.shots", "whole number"),
    ("burst", {"shots": True, "interval": 1.0}, "burst.shots", "whole number"),
    ("burst", {"shots": 3, "interval": 0.0}, "burst.interval", "> 0 s"),
    ("burst", {"shots": 3, "interval": 0.01}, "burst.interval", "must exceed the pulse's end"),
    ("burst", {"shots": 3}, "burst.interval", "missing required key"),
    ("burst", {"shots": 3, "intervall": 1.0}, "burst.intervall", "did you mean 'interval'"),
])
def test_bad_firing_input_is_one_line_naming_the_key(bad_input, changed, path, value, key, text):
    bad_input(changed(pulse_mapping(), path, value), key, text)


def test_a_pulse_needs_version_2_and_a_missing_projectile_is_named(bad_input, changed):
    mapping = pulse_mapping()
    del mapping["firing"]["projectile_mass"]
    bad_input(mapping, "firing.projectile_mass", "give both")  # half a projectile
    mapping = changed(pulse_mapping(scale_to_momentum=True), "firing.projectile_mass", "<delete>")
    bad_input(changed(mapping, "firing.muzzle_velocity", "<delete>"), "firing.projectile_mass", "scale_to_momentum")
    v1 = pulse_mapping()
    v1["version"] = 1
    with pytest.raises(SceneError) as info:
        scene_from_dict(v1)
    assert info.value.key == "firing.pulse" and "version-2" in info.value.message
    v1 = changed(pulse_mapping(), "firing.pulse", "<delete>")
    v1["version"], v1["burst"] = 1, {"shots": 2, "interval": 1.0}
    with pytest.raises(SceneError) as info:
        scene_from_dict(v1)
    assert info.value.key == "burst" and "version-2" in info.value.message


def test_a_pulse_from_a_csv_file_beside_the_scene_equals_the_inline_table(tmp_path):
    (tmp_path / "breech.csv").write_text("time,force\n" + "".join(f"{t},{f}\n" for t, f in zip(TIMES, FORCES)))
    mapping = pulse_mapping()
    mapping["firing"]["pulse"] = {"file": "breech.csv"}
    from mbs_models.scene.io import mapping_to_toml
    (tmp_path / "scene.toml").write_text(mapping_to_toml(mapping))
    from_file = load_scene(tmp_path / "scene.toml")
    inline = scene_from_dict(pulse_mapping())
    assert from_file.firing.pulse.table == inline.firing.pulse.table
    a, b = simulate(from_file, 1.0), simulate(inline, 1.0)
    assert a.max_barrel_displacement == b.max_barrel_displacement
    assert "file = \"breech.csv\"" in scene_to_toml(from_file)


@pytest.mark.parametrize("content, text", [("time,force\n0.0,1.0\n", "at least two rows"),
                                           ("time,force\n0.0,1.0\n0.1,x\n", "line 3"),
                                           ("time,force\n0.0,1.0,2\n0.1,1.0\n", "two columns")])
def test_a_bad_pulse_file_is_one_line(tmp_path, capsys, content, text):
    (tmp_path / "breech.csv").write_text(content)
    mapping = pulse_mapping()
    mapping["firing"]["pulse"] = {"file": "breech.csv"}
    from mbs_models.scene.io import mapping_to_toml
    (tmp_path / "scene.toml").write_text(mapping_to_toml(mapping))
    assert main(["run", str(tmp_path / "scene.toml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "firing.pulse.file" in err[0] and text in err[0]
    (tmp_path / "breech.csv").unlink()
    assert main(["run", str(tmp_path / "scene.toml")]) == 2
    assert "pulse file not found" in capsys.readouterr().err


def _scene_with_pulse_file(tmp_path, name: str):
    mapping = pulse_mapping()
    mapping["firing"]["pulse"] = {"file": name}
    from mbs_models.scene.io import mapping_to_toml
    (tmp_path / "scene.toml").write_text(mapping_to_toml(mapping))
    return tmp_path / "scene.toml"


def _one_line_naming_the_file(capsys, path, text: str) -> None:
    assert main(["run", str(path)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and "firing.pulse.file" in lines[0] and text in lines[0], captured.err
    assert "Traceback" not in captured.err and captured.out == ""


@pytest.mark.skipif(not __import__("os").path.exists("/dev/zero"), reason="needs /dev/zero")
def test_a_pulse_file_that_never_ends_or_is_no_file_is_refused_at_once(tmp_path, capsys):
    """/dev/zero (read without a limit: a MemoryError), a directory and a FIFO (reading it waits for a writer)
    are refused before a byte is read, in one line naming firing.pulse.file."""
    import os
    _one_line_naming_the_file(capsys, _scene_with_pulse_file(tmp_path, "/dev/zero"), "not a regular file")
    (tmp_path / "dir.csv").mkdir()
    _one_line_naming_the_file(capsys, _scene_with_pulse_file(tmp_path, "dir.csv"), "is a directory")
    os.mkfifo(tmp_path / "pipe.csv")
    _one_line_naming_the_file(capsys, _scene_with_pulse_file(tmp_path, "pipe.csv"), "not a regular file")


@pytest.mark.parametrize("content, text", [(b"time,force\n0.0,1.0\n\x00\x01,2\n", "a binary file"),
                                           ("time,force # \u00e9\n0.0,1.0\n".encode("latin-1"), "not UTF-8"),
                                           (b"time,force\n" + b"1" * 200_000 + b"\n", "not a CSV table")])
def test_a_binary_non_utf8_or_unparsable_pulse_file_is_one_line(tmp_path, capsys, content, text):
    """A NUL byte, Latin-1 text, a field beyond the csv module's limit (128 KiB): one line, no traceback."""
    (tmp_path / "breech.csv").write_bytes(content)
    _one_line_naming_the_file(capsys, _scene_with_pulse_file(tmp_path, "breech.csv"), text)


def test_a_pulse_file_beyond_the_input_limit_is_refused(tmp_path, monkeypatch):
    """Read with a limit (``MAX_INPUT_BYTES``, 64 MiB; a smaller one here): a longer file is refused, not read."""
    from mbs_models import inputs
    monkeypatch.setattr(inputs, "MAX_INPUT_BYTES", 1000)
    rows = "".join(f"{i * 1e-4:.4f},{1e6:.1f}\n" for i in range(100))  # about 1.5 kB
    (tmp_path / "long.csv").write_text("time,force\n" + rows)
    with pytest.raises(SceneError, match="larger than 1000 bytes") as info:
        load_scene(_scene_with_pulse_file(tmp_path, "long.csv"))
    assert info.value.key == "firing.pulse.file"


#: Magnitudes in range whose derived quantities double precision cannot hold (DESIGN.md, "Bad input beyond the
#: ranges"): (dotted path, value, the key named, the quantity named).  Each derived by hand: the products below
#: overflow past 1.8e308 or underflow below 4.9e-324.
BEYOND_DOUBLE = [
    # impulse 1e308 (0.5 + 1 + 0.5) = 2e308 N s
    ("firing.pulse", {"times": [0.0, 1.0, 2.0, 3.0], "forces": [0.0, 1e308, 1e308, 0.0]}, "firing.pulse.forces",
     "impulse"),
    # impulse 0.5 x 1e-320 x 1e-10 rounds to 0
    ("firing.pulse", {"times": [0.0, 1e-10, 2e-10], "forces": [0.0, 1e-320, 0.0]}, "firing.pulse.forces", "impulse"),
    # I / impulse = 3869 / (1e-310 x 1e-3) = 3.9e316
    ("firing.pulse", {"times": [0.0, 1e-3, 2e-3], "forces": [0.0, 1e-310, 0.0], "scale_to_momentum": True},
     "firing.pulse.forces", "scale of the pulse"),
    # I = 1e300 x 1e10 = 1e310 (the projectile mass farther from 1 than the velocity)
    ("firing.projectile_mass", 1e300, "firing.projectile_mass", None),
    # I = 1e-300 x 1e-30 = 1e-330 rounds to 0
    ("firing.projectile_mass", 1e-300, "firing.projectile_mass", None),
    # shots x interval = 1000 x 1e306
    ("burst", {"shots": 1000, "interval": 1e306}, "burst.interval", "shots x interval"),
]


@pytest.mark.parametrize("path, value, key, quantity", BEYOND_DOUBLE)
def test_a_magnitude_beyond_double_precision_is_one_line_naming_the_key(bad_input, changed, path, value, key,
                                                                        quantity):
    mapping = changed(pulse_mapping(), path, value)
    if path == "firing.projectile_mass":  # the velocity that takes the momentum beyond
        mapping = changed(mapping, "firing.muzzle_velocity", 1e10 if value > 1 else 1e-30)
        quantity = "firing momentum"
    bad_input(mapping, key, quantity)


def test_magnitudes_just_within_double_precision_load():
    """The same quantities just inside: an impulse of 1.5e308 N s, a momentum of 1e300 x 1e8 = 1e308 kg m/s."""
    Pulse(times=(0.0, 1.0, 2.0), forces=(0.0, 1.5e308, 0.0))
    Firing(projectile_mass=1e300, muzzle_velocity=1e8)
    Burst(shots=1000, interval=1e305)


def test_scenes_round_trip_through_toml(tmp_path):
    mapping = pulse_mapping(scale_to_momentum=True)
    mapping["burst"] = {"shots": 3, "interval": 0.6}
    mapping["firing"]["charge_mass"] = 1.5
    mapping["firing"]["gas_velocity"] = 1300.0
    scene = scene_from_dict(mapping)
    (tmp_path / "s.toml").write_text(scene_to_toml(scene))
    assert load_scene(tmp_path / "s.toml") == scene


# ------------------------------------------------------------------ what is simulated
def test_absent_inputs_add_no_load_and_no_segment():
    mechanism = Mechanism(simplified_model())
    assert mechanism.loads == [] and mechanism.impulses == [] and mechanism.breakpoints == []
    with assemble(simplified_model()) as assembly:
        assert assembly.loads == {} and assembly.mbs.systemData.NumberOfLoads() == 0
    with assemble(scene_from_dict(pulse_mapping())) as assembly:
        assert list(assembly.loads) == ["breech_force"] and assembly.mbs.systemData.NumberOfLoads() == 1


TABLES = {"design example": (TIMES, FORCES), "401 uneven points": breech_pressure_table(),
          "jumps at both ends": ((0.001, 0.003, 0.007, 0.010), (5.0e5, 2.0e6, 6.0e5, 1.0e5))}


@pytest.mark.parametrize("table", sorted(TABLES))
@pytest.mark.parametrize("accuracy", PRESETS)
def test_a_pulse_on_a_free_barrel_matches_the_closed_form(accuracy, table):
    """v(t) = I(t)/M with I the integral of the piecewise-linear force (exact with trapezoids of the
    quadratic pieces); x at the end of the pulse: sum over pieces of the exact double integral.  A table of
    hundreds of points too: the solve is split at every point (a kink of F inside a step escapes the adaptive
    solver's error estimate: 2.7e-8 at ``reference`` before issue #19); and a pulse that jumps at its start
    and end (the solver evaluates each segment's own piece at its end, not the value after the jump: the
    step collapsed there before, ``standard`` and ``reference`` stopped short of the jump)."""
    times, forces = TABLES[table]
    scene = free_barrel(Firing(pulse=Pulse(times=times, forces=forces)))
    result = simulate(scene, 0.05, accuracy)
    tolerance = {"draft": 1e-4, "standard": 1e-6, "reference": 1e-9}[accuracy]
    x_end, v_end = exact_free_barrel(times, forces, 0.05)
    assert result.barrel_velocity[-1] == pytest.approx(v_end, rel=tolerance)
    assert result.barrel_position[-1] == pytest.approx(x_end, rel=tolerance)
    for t in (0.001, 0.004, 0.009):
        k = int(np.argmin(np.abs(result.time - t)))
        x, v = exact_free_barrel(times, forces, result.time[k])
        assert result.barrel_velocity[k] == pytest.approx(v, rel=tolerance, abs=tolerance * v_end)
    # the work of the breech force is the kinetic energy it gave
    assert result.energy()["firing"]["work"] == pytest.approx(0.5 * MASS * v_end ** 2, rel=10 * tolerance)


def test_python_and_symbolic_user_functions_give_the_same_pulse():
    """The per-segment piece of the breech force (:meth:`BreechForce.user_function_law`) in both backends."""
    times, forces = TABLES["jumps at both ends"]
    scene = scene_from_dict(pulse_mapping()).with_changes(
        firing=Firing(projectile_mass=6.86, muzzle_velocity=564.0, pulse=Pulse(times=times, forces=forces)))
    symbolic = simulate(scene, 1.0, user_functions="symbolic")
    python = simulate(scene, 1.0, user_functions="python")
    assert len(python.time) == len(symbolic.time)
    np.testing.assert_allclose(python.barrel_position, symbolic.barrel_position, rtol=1e-12, atol=1e-15)
    assert python.energy()["firing"]["work"] == pytest.approx(symbolic.energy()["firing"]["work"], rel=1e-12)


def test_the_solve_is_split_at_every_point_of_the_table():
    """Every point of every shot's table (shifted by the shot time) inside (0, end) is a segment boundary, so every
    segment sees one linear piece of F; inside a pulse the step is at most a 40th of it, outside it is the preset's."""
    times, forces = breech_pressure_table()
    firing = Firing(projectile_mass=6.86, muzzle_velocity=564.0,
                    pulse=Pulse(times=times, forces=forces, scale_to_momentum=True))
    mechanism = Mechanism(simplified_model().with_changes(firing=firing, burst=Burst(shots=2, interval=0.5)))
    standard = ACCURACY_PRESETS["standard"]
    points = sorted({shot + t for shot in (0.0, 0.5) for t in times} - {0.0})
    assert len(points) == 2 * 401 - 1
    plan = segment_plan(mechanism, 1.0, standard)
    assert [t0 for t0, _, _ in plan] == [0.0] + points
    assert [t1 for _, t1, _ in plan] == points + [1.0]
    for t0, t1, settings in plan:
        in_pulse = any(shot <= t0 < shot + times[-1] for shot in (0.0, 0.5))
        assert settings.max_step == pytest.approx(0.012 / 40 if in_pulse else standard.max_step, rel=1e-12), (t0, t1)
    # a run that ends inside the pulse: the points before its end, then the end
    inside = [t for t in points if t < 0.005]
    assert [(t0, t1) for t0, t1, _ in segment_plan(mechanism, 0.005, standard)] == list(zip([0.0] + inside, inside + [0.005]))


@pytest.mark.parametrize("accuracy", PRESETS)
def test_a_burst_of_impulses_on_a_free_barrel_matches_the_closed_form(accuracy):
    """Shot k (k = 0, 1, ...) at k T adds v0: between shots v = (k+1) v0 and x = v0 (k+1) t - v0 T k (k+1)/2."""
    firing = Firing(projectile_mass=6.86, muzzle_velocity=564.0)
    v0 = 6.86 * 564.0 / MASS
    result = simulate(free_barrel(firing, Burst(shots=4, interval=0.25)), 1.2, accuracy)
    t = result.time
    k = np.minimum(np.floor(t / 0.25 + 1e-12), 3)
    after_jump = np.concatenate([[True], np.diff(t) > 0])  # the sample after each jump
    exact_x = v0 * (k + 1) * t - v0 * 0.25 * k * (k + 1) / 2
    np.testing.assert_allclose(result.barrel_position[after_jump], exact_x[after_jump], rtol=1e-9, atol=1e-12)
    assert result.barrel_velocity[-1] == pytest.approx(4 * v0, rel=1e-12)
    assert [s["time"] for s in result.shots] == [0.0, 0.25, 0.5, 0.75]
    assert result.energy()["burst"]["work"] == pytest.approx(0.5 * MASS * v0 ** 2 * (16 - 1), rel=1e-12)


def test_the_first_shot_of_a_burst_is_the_single_shot_run():
    single = simulate(simplified_model(), 10.0)
    burst = simulate(simplified_model().with_changes(burst=Burst(shots=3, interval=2.0)), 6.0)
    first = burst.shots[0]
    assert first["max_barrel_displacement"] == pytest.approx(single.max_barrel_displacement, rel=1e-9)
    assert first["time_of_max_barrel_displacement"] == pytest.approx(single.time_of_max_barrel_displacement, rel=1e-6)
    assert first["in_battery_at_next_shot"] is False and first["position_at_next_shot"] < 0  # still returning
    # the later shots start from a barrel moving back to battery: they recoil less
    assert all(s["max_barrel_displacement"] < first["max_barrel_displacement"] for s in burst.shots[1:])
    assert burst.shots[-1]["position_at_next_shot"] is None
    # time to battery: the first return within 1 mm of x = 0 after the first maximum
    t = single.time
    crossing = t[np.flatnonzero((t > single.time_of_max_barrel_displacement) & (np.abs(single.barrel_position) <= 1e-3))[0]]
    assert first["time_to_battery"] == pytest.approx(crossing, abs=2 * np.max(np.diff(t)))


@pytest.mark.parametrize("case", ["pulse", "burst", "pulse burst"])
def test_energy_balance_closes_element_by_element_with_the_work_of_the_shots(case):
    scene = simplified_model()
    if "pulse" in case:
        scene = scene_from_dict(pulse_mapping(scale_to_momentum=True))
    if "burst" in case:
        scene = scene.with_changes(burst=Burst(shots=3, interval=0.7))
    for accuracy, tolerance in (("standard", 5e-6), ("reference", 1e-8)):
        result = simulate(scene, 3.0, accuracy)
        energy = result.energy()
        total = sum(e["kinetic"] + e["stored"] + e["dissipated"] - e.get("work", 0.0) for e in energy.values())
        work = sum(e.get("work", 0.0) for e in energy.values())
        initial = 0.5 * MASS * scene.initial_velocity ** 2
        assert abs(total - initial) < tolerance * (initial + work), (accuracy, total, initial, work)
        assert np.max(np.abs(result.energy_error())) < tolerance * (initial + work)


@pytest.mark.parametrize("case", ["pulse", "burst"])
def test_the_early_stop_waits_for_the_last_shot_and_equals_the_full_run(case):
    scene = model = scene_from_dict(pulse_mapping(scale_to_momentum=True)) if case == "pulse" else simplified_model()
    from mbs_models import model_ii
    scene = model_ii(1000.0, 0.0).with_changes(firing=model.firing, burst=Burst(shots=2, interval=1.5))
    names = ["max_barrel_displacement", "peak_contact_force", "max_absorber_velocity", "impacts", "peak_support_force"]
    full = simulate(scene, 10.0)
    early = simulate(scene, 10.0, stop_when_final=names)
    assert early.stop_reason == "metrics_final" and 1.5 < early.end_time < 10.0
    for name in names[:3] + names[4:]:
        assert getattr(early, name) == getattr(full, name), name
    assert [i.peak_force for i in early.impacts] == [i.peak_force for i in full.impacts]


@pytest.mark.parametrize("accuracy", ["standard", "reference"])
def test_a_vanishing_pulse_converges_to_the_initial_velocity_model_at_second_order(accuracy):
    """A symmetric triangular pulse of duration tau with the paper's momentum I.  While the barrel recoils
    the simplified model is linear (damper c_recoil), so its response is the convolution
    ``x(t) = integral h(t - s) F(s) ds / I * I``; expanding h about the pulse's centroid ``t_c = tau / 2``
    gives ``x(t) = I h(t - t_c) + O(tau^2)``: the impulse model delayed by t_c.  A delay does not change a
    maximum, so the maximum displacement converges at order 2 and its time at order 1 (to t_c)."""
    reference = simulate(simplified_model(), 2.0, "reference")
    errors, delays = [], []
    for tau in (8e-3, 4e-3, 2e-3, 1e-3):
        firing = Firing(projectile_mass=6.86, muzzle_velocity=564.0,
                        pulse=Pulse(times=(0.0, tau / 2, tau), forces=(0.0, 1.0, 0.0), scale_to_momentum=True))
        result = simulate(simplified_model().with_changes(firing=firing), 2.0, accuracy)
        errors.append(abs(result.max_barrel_displacement - reference.max_barrel_displacement))
        delays.append((result.time_of_max_barrel_displacement - reference.time_of_max_barrel_displacement) / (tau / 2))
    orders = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
    assert errors[-1] < 2e-7 * reference.max_barrel_displacement
    assert all(1.9 < order < 2.1 for order in orders), (errors, orders)
    assert all(abs(delay - 1.0) < 0.05 for delay in delays), delays


def test_ten_shots_on_model_ii_stay_finite_and_balanced():
    from mbs_models import model_ii
    scene = model_ii(1000.0, 0.0).with_changes(burst=Burst(shots=10, interval=0.3))
    for accuracy in ("draft", "standard"):
        result = simulate(scene, 4.0, accuracy)
        assert len(result.shots) == 10 and all(np.isfinite(s["max_barrel_displacement"]) for s in result.shots)
        assert np.all(np.isfinite(result.support_force))
        work = result.energy()["burst"]["work"]
        bound = 1e-3 if accuracy == "draft" else 5e-6
        assert np.max(np.abs(result.energy_error())) < bound * (result.kinetic_energy_history[0] + work)


# ------------------------------------------------------------------ the engine against the reference
def _shipped(name: str) -> Scene:
    from mbs_models.scenes import scene_path
    return load_scene(scene_path(name))


def _short_pulse_on_model_ii() -> Scene:
    """A hard case: model (ii) at gap 0 driven by a 0.1 ms pulse, ~100x shorter than its contact (~10 ms)."""
    from mbs_models import model_ii
    firing = Firing(projectile_mass=6.86, muzzle_velocity=564.0,
                    pulse=Pulse(times=(0.0, 2e-5, 1e-4), forces=(0.0, 1.0, 0.0), scale_to_momentum=True))
    return model_ii(1000.0, 0.0).with_changes(firing=firing, name="model (ii), 0.1 ms pulse")


def _ten_shots() -> Scene:
    from mbs_models import model_ii
    return model_ii(1000.0, 0.0).with_changes(burst=Burst(shots=10, interval=0.3), name="model (ii), 10 shots")


def _many_point_pulse_on_model_ii() -> Scene:
    """Issue #19: model (ii) at gap 0 driven by the 401-point breech pressure table, scaled to the paper's momentum
    (before the solve was split at every table point: an energy error of 1.1e-7 at ``reference``, tolerance 5e-9)."""
    from mbs_models import model_ii
    times, forces = breech_pressure_table()
    firing = Firing(projectile_mass=6.86, muzzle_velocity=564.0,
                    pulse=Pulse(times=times, forces=forces, scale_to_momentum=True))
    return model_ii(1000.0, 0.0).with_changes(firing=firing, name="model (ii), 401-point pulse")


CASES = {"breech_pulse": lambda: _shipped("breech_pulse"), "burst": lambda: _shipped("burst"),
         "short_pulse": _short_pulse_on_model_ii, "ten_shots": _ten_shots,
         "many_point_pulse": _many_point_pulse_on_model_ii}


@pytest.mark.parametrize("accuracy", PRESETS)
@pytest.mark.parametrize("case", sorted(CASES))
def test_the_engine_agrees_with_the_reference(agrees_with_reference, case, accuracy):
    """The README's guarantee at every preset: pulses (one 100x shorter than the contact) and bursts."""
    agrees_with_reference(CASES[case](), 3.5 if case == "ten_shots" else 2.0, accuracy)


@pytest.mark.parametrize("case", ["burst", "ten_shots"])
def test_the_shots_agree_with_the_reference(case):
    from validation.reference import solve_reference
    scene = CASES[case]()
    end = 3.5 if case == "ten_shots" else 2.0
    engine, reference = simulate(scene, end, "reference"), solve_reference(scene, end)
    assert len(engine.shots) == len(reference.shots)
    for ours, theirs in zip(engine.shots, reference.shots):
        assert ours["max_barrel_displacement"] == pytest.approx(theirs["max_barrel_displacement"], rel=1e-7)
        assert ours["in_battery_at_next_shot"] == theirs["in_battery_at_next_shot"]
        if theirs["position_at_next_shot"] is not None:
            assert ours["position_at_next_shot"] == pytest.approx(theirs["position_at_next_shot"], abs=1e-8)
    assert engine.energy()["burst"]["work"] == pytest.approx(reference.work["burst"], rel=1e-7)


def test_a_pulse_table_has_a_stated_limit_named_by_its_key(tmp_path, capsys):
    """Each table point is a segment of the solve: beyond MAX_PULSE_POINTS the table is refused before anything
    runs, one line naming the key (a 600 000-point table once crashed the process)."""
    from mbs_models.elements.firing import MAX_PULSE_POINTS
    from mbs_models.scene.io import mapping_to_toml

    times, forces = breech_pressure_table(MAX_PULSE_POINTS)  # at the limit: accepted
    assert len(scene_from_dict(pulse_mapping(times=list(times), forces=list(forces))).firing.pulse.table[0]) \
        == MAX_PULSE_POINTS
    times, forces = breech_pressure_table(MAX_PULSE_POINTS + 1)
    with pytest.raises(SceneError) as info:
        scene_from_dict(pulse_mapping(times=list(times), forces=list(forces)))
    assert info.value.key == "firing.pulse.times" and f"more than {MAX_PULSE_POINTS} points" in info.value.message
    (tmp_path / "breech.csv").write_text("time,force\n" + "".join(f"{t!r},{f!r}\n" for t, f in zip(times, forces)))
    mapping = pulse_mapping()
    mapping["firing"]["pulse"] = {"file": "breech.csv"}
    (tmp_path / "scene.toml").write_text(mapping_to_toml(mapping))
    assert main(["run", str(tmp_path / "scene.toml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "firing.pulse.file" in err[0] and f"more than {MAX_PULSE_POINTS} points" in err[0]
