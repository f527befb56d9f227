"""A Simulator that reuses assembled systems gives results bit-identical to a fresh assembly.

Every point runs through one :class:`~mbs_models.engine.reuse.Simulator` after points of other
structures and numbers have run, and is compared with ``simulate(scene, ...)`` (a fresh assembly) by
``==`` on every array and metric of the Result (only the wall time and its split may differ).
"""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from mbs_models import Firing, Pulse, Simulator, load_scene, model_i, model_ii, simplified_model, simulate
from mbs_models.engine.assembly import assemble, refill, structure_key
from mbs_models.engine.mechanism import Mechanism
from mbs_models.scenes import list_scenes, scene_path

EARLY = ("max_barrel_displacement",)

PAPER_POINTS = [(factory, mass, gap) for gap in (0.0, 0.037, 0.12) for mass in (100.0, 1000.0, 500.0)
                for factory in (model_i, model_ii)]


def test_paper_models_over_masses_and_gaps_are_bit_identical(assert_results_identical):
    """The three models, several masses and gaps, interleaved: each point reuses a system of the others."""
    fresh = {}
    with Simulator() as simulator:
        simulator.simulate(simplified_model(), 10.0, "standard", stop_when_final=EARLY)
        for factory, mass, gap in PAPER_POINTS:
            scene = factory(mass, gap)
            reused = simulator.simulate(scene, 10.0, "standard", stop_when_final=EARLY)
            fresh = simulate(scene, 10.0, "standard", stop_when_final=EARLY)
            assert_results_identical(reused, fresh)
        # the simplified model after the others; a full run without the early stop
        assert_results_identical(simulator.simulate(simplified_model(), 10.0, "standard"),
                                 simulate(simplified_model(), 10.0, "standard"))
        assert_results_identical(simulator.simulate(model_ii(1000.0, 0.05), 10.0, "draft"),
                                 simulate(model_ii(1000.0, 0.05), 10.0, "draft"))
        assert simulator.assemblies == 3
        assert simulator.reuses == len(PAPER_POINTS) + 2 - 2


def test_python_user_functions_are_bit_identical_too(assert_results_identical):
    with Simulator() as simulator:
        for gap in (0.0, 0.05):
            scene = model_ii(500.0, gap)
            assert_results_identical(
                simulator.simulate(scene, 10.0, "draft", user_functions="python", stop_when_final=EARLY),
                simulate(scene, 10.0, "draft", user_functions="python", stop_when_final=EARLY))
        assert simulator.reuses == 1


#: Per shipped scene: a change of its numbers that keeps its structure (a second point to reuse with).
VARIANTS = {
    "two_absorbers": {"absorber.1.contact.gap": 0.03, "absorber.0.mass": 300.0},
    "burst": {"burst.interval": 0.9, "contact.gap": 0.01},
    "recuperator": {"recuperator.initial_pressure": 6.0e6},
    "realistic": {"recuperator.initial_pressure": 6.0e6, "cradle.elevation": 20.0},
    "breech_pulse": {"recoil_spring.stiffness": 3.0e5},
    "cradle": {"cradle.elevation": 10.0},
    "recoil_brake": {"recoil_spring.stiffness": 3.0e5},
}


def _variant(name: str, scene):
    changes = VARIANTS.get(name)
    if changes is None:
        changes = ({"contact.gap": 0.02} if scene.has_absorber else
                   {"recoil_spring.stiffness": 3.0e5} if scene.recoil_spring is not None else {})
    return scene.with_changes(**{"barrel.mass": scene.barrel.mass * 1.07, **changes})


@pytest.mark.slow
def test_shipped_scenes_are_bit_identical_after_other_points(assert_results_identical):
    """Every shipped scene and a variant of its numbers, the variants first, through one Simulator."""
    scenes = {name: load_scene(scene_path(name)) for name in list_scenes()}
    order = [(name, _variant(name, scene)) for name, scene in scenes.items()] + list(scenes.items())
    with Simulator(max_models=len(scenes) + 1) as simulator:
        for name, scene in order:
            reused = simulator.simulate(scene, 1.5, "draft")
            fresh = simulate(scene, 1.5, "draft")
            assert_results_identical(reused, fresh)
        assert simulator.reuses >= len(scenes)  # every scene at least reused its variant's system


def _pulse_scene(points: int, peak_time: float):
    """The simplified model under a breech pulse of ``points`` unevenly spaced table points (a triangle-like rise to
    ``peak_time`` s and decay over 12 ms, scaled to the paper's momentum): a segment per table point."""
    times = [0.012 * (i / (points - 1)) ** 1.3 for i in range(points)]
    forces = [t / peak_time if t < peak_time else math.exp(-(t - peak_time) / 0.003) for t in times]
    firing = Firing(projectile_mass=6.86, muzzle_velocity=564.0,
                    pulse=Pulse(times=times, forces=forces, scale_to_momentum=True))
    return simplified_model().with_changes(firing=firing, name=f"{points}-point pulse")


def test_pulses_of_hundreds_of_points_are_bit_identical(assert_results_identical):
    """A 401-point pulse (401 segments) after a 41-point one and another 401-point shape, through one Simulator;
    with and without the early stop."""
    with Simulator() as simulator:
        for scene in (_pulse_scene(41, 0.002), _pulse_scene(401, 0.003), _pulse_scene(401, 0.002)):
            for accuracy in ("draft", "reference"):
                assert_results_identical(simulator.simulate(scene, 1.0, accuracy), simulate(scene, 1.0, accuracy))
            assert_results_identical(simulator.simulate(scene, 2.0, "standard", stop_when_final=EARLY),
                                     simulate(scene, 2.0, "standard", stop_when_final=EARLY))
        assert simulator.assemblies == 1


def test_a_kept_system_starts_each_solve_with_its_own_first_step(assert_results_identical):
    """A brake stiff enough to limit the first step (orifices at 0.3 times the shipped areas: its time constant
    below the 20 ms maximum step), then the shipped brake (no limit), then the stiff one again, through one system
    whose Exudyn settings are kept per key: each solve is the fresh one's."""
    from mbs_models.engine.mechanism import Mechanism

    shipped = load_scene(scene_path("recoil_brake"))
    brake = shipped.recoil_brake
    stiff = shipped.with_changes(recoil_brake=replace(
        brake, orifice_area=tuple((x, 0.3 * a) for x, a in brake.orifice_area)))
    limits = {name: Mechanism(scene).connector["recoil_brake"].first_step_limit
              for name, scene in (("stiff", stiff), ("shipped", shipped))}
    assert limits["stiff"] < 0.02 < limits["shipped"]  # the stiff one's first step is limited, the shipped one's not
    with Simulator() as simulator:
        for scene in (stiff, shipped, stiff):
            assert_results_identical(simulator.simulate(scene, 1.0, "draft"), simulate(scene, 1.0, "draft"))
        assert simulator.assemblies == 1


def test_refill_refuses_another_structure_and_the_cache_falls_back_to_a_fresh_build(assert_results_identical):
    mechanism = Mechanism(model_ii(500.0, 0.0))
    assembly = assemble(mechanism.scene, "symbolic", mechanism)
    try:
        other = Mechanism(simplified_model())
        assert structure_key(other, "symbolic") != assembly.structure
        with pytest.raises(ValueError, match="structure"):
            refill(assembly, other.scene, other)
    finally:
        assembly.close()
    with Simulator(max_models=1) as simulator:
        for scene in (model_ii(500.0, 0.0), simplified_model(), model_ii(500.0, 0.02)):
            assert_results_identical(simulator.simulate(scene, 10.0, "draft", stop_when_final=EARLY),
                                     simulate(scene, 10.0, "draft", stop_when_final=EARLY))
        assert (simulator.assemblies, simulator.reuses) == (3, 0)  # one kept: model (ii) was dropped


def test_a_failed_solve_discards_its_system(monkeypatch, assert_results_identical):
    from mbs_models import SimulationError
    from mbs_models.engine import driver

    with Simulator() as simulator:
        simulator.simulate(model_ii(500.0, 0.0), 10.0, "draft", stop_when_final=EARLY)
        original = driver._solve

        def failing(*args, **kwargs):
            raise SimulationError("made to fail")

        monkeypatch.setattr(driver, "_solve", failing)
        with pytest.raises(SimulationError, match="made to fail"):
            simulator.simulate(model_ii(500.0, 0.01), 10.0, "draft", stop_when_final=EARLY)
        monkeypatch.setattr(driver, "_solve", original)
        assembled = simulator.assemblies
        scene = model_ii(500.0, 0.02)
        assert_results_identical(simulator.simulate(scene, 10.0, "draft", stop_when_final=EARLY),
                                 simulate(scene, 10.0, "draft", stop_when_final=EARLY))
        assert simulator.assemblies == assembled + 1


def test_bad_max_models():
    with pytest.raises(ValueError, match="max_models"):
        Simulator(max_models=0)


def test_the_module_docstring_example_runs():
    import doctest

    from mbs_models.engine import reuse

    assert doctest.testmod(reuse).failed == 0


def test_each_process_has_its_own_simulator(monkeypatch):
    from mbs_models.engine import reuse

    first = reuse.process_simulator()
    assert reuse.process_simulator() is first
    monkeypatch.setattr(reuse.os, "getpid", lambda: -1)  # as in a forked worker
    assert reuse.process_simulator() is not first


def test_a_sweep_reuses_per_process_and_gives_the_points_of_fresh_runs():
    """run_scenes' points (serial: this process's Simulator; and in 2 worker processes) are those of
    ``simulate``; a failing point between them changes nothing."""
    from mbs_models import Conventions, SimulationError
    from mbs_models.engine import reuse
    from mbs_models.studies.sweep import run_scenes

    scenes = [model_i(500.0, 0.0), model_ii(1000.0, 0.0, Conventions(compression_only=True)),  # fails
              model_ii(100.0, 0.03), model_i(1000.0, 0.08), model_ii(500.0, 0.11), model_i(100.0, 0.01)]
    before = reuse.process_simulator().reuses
    for workers in (1, 2):
        points = run_scenes(scenes, 10.0, "standard", workers=workers, stop_when_final=EARLY)
        assert points[1].error is not None and "step budget" in points[1].error
        for scene, point in zip(scenes, points):
            if point.error is not None:
                with pytest.raises(SimulationError):
                    simulate(scene, 10.0, "standard", stop_when_final=EARLY)
                continue
            fresh = simulate(scene, 10.0, "standard", stop_when_final=EARLY)
            assert (point.max_barrel_displacement, point.time_of_max_barrel_displacement, point.peak_contact_force,
                    point.max_absorber_velocity, point.impacts, point.end_time, point.stop_reason,
                    point.peak_support_force) == \
                (fresh.max_barrel_displacement, fresh.time_of_max_barrel_displacement, fresh.peak_contact_force,
                 fresh.max_absorber_velocity, None if fresh.impacts is None else len(fresh.impacts),
                 fresh.end_time, fresh.stop_reason, fresh.peak_support_force)
    assert reuse.process_simulator().reuses > before  # the serial sweep reused this process's systems
