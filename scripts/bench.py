#!/usr/bin/env python
"""Benchmark of the ``standard`` path, in one process, printed as ratios measured in the same run.

    python scripts/bench.py                      # model_ii (m = 1000 kg, gap 0), 10 s, everything
    python scripts/bench.py --memory-runs 1000   # shorter memory test
    python scripts/bench.py --scene model_i --skip-memory

What it measures (not a timed test: the numbers depend on the machine; the ratios much less so):

1. **Against scipy LSODA at equal accuracy**: the ``standard`` preset's errors (max barrel displacement,
   peak contact force, max absorber velocity) against a tight truth (:func:`validation.studies.precision.compute_truth`);
   then the loosest LSODA tolerance (on the same equations, :func:`validation.studies.precision.solve_plain`) whose
   worst error is no larger; ratio of median wall times, complete runs and integration alone.
2. **Against a compiled fixed-structure yardstick**: ``scripts/recoil_dopri5.c``, the same equations and
   the same adaptive scheme (Dormand-Prince 5(4), Hairer's step control) at the preset's rtol, atol and
   max step, compiled at run time with the system ``cc`` into a temporary directory and called through
   ctypes: the physical limit of what an integrator of these equations costs.  Skipped (and said so)
   without a C compiler.  Beside it, Exudyn's floor: the same Exudyn system with built-in linear laws only, no
   sensors and no pre-step function, per step, at the standard run's step count (what no change of this
   product can go below); and what a step adds to that floor, one layer at a time (:data:`STEP_LAYERS`: the laws'
   symbolic user functions, the pre-step function, the stored sensors), per accepted step and per attempt.
3. **Single-run cost breakdown**: import (in a fresh interpreter), assembly, solve, post-processing (and
   its parts), as fractions of one complete run.
4. **Memory**: RSS over N consecutive runs in this process (Exudyn keeps models alive unless reset;
   ``simulate`` resets them): growth between the first 10 % and the end must be ~0.
5. **Elements**: the cost of 1, 2, 4 and 8 absorbers (model (ii)'s absorber split into n equal parts of
   mass m/n, k_r/n, c_r/n, k_c/n: the same motion, so the steps hardly change and the cost is what the
   elements add), and of capturing the onset rate ``v-`` of the restitution laws inside the solve
   (``exact-restitution`` against Hunt-Crossley with the lambda it gives at v0: per step of the solve).

6. **Sweeps** (issue #11, :mod:`bench_throughput`, :mod:`bench_reuse`): the paper's Figs 4/5 grid (726 points,
   with the early stop, as the report runs it) in fresh interpreters: points per second before issue #11
   (commit ``c952992`` in a temporary git worktree) and now, serial; now with 2 workers (the speed-up from 1 to
   2); on a 2-worker Dask ``LocalCluster``; and, in this process, a fresh ``simulate`` per point against one
   reused :class:`~mbs_models.Simulator` (and, with the memory test, RSS over 10 000 reused points).
7. **The whole-paper job**: wall time of a full ``recoil paper`` before issue #11 and now (``--paper``).
8. **The planar model** (issue #22, :mod:`bench_carriage`): each shipped carriage scene against the same hardware
   without ``[carriage]``, per simulated second, and Exudyn's floor (a bare tree against a bare 1-D mass, per step).
9. **Issue #24** (:mod:`bench_scipy`, about a minute; ``--issue24-quick`` about 20 s): a plain scipy
   script of model (ii) written from the equations (``scripts/plain_scipy.py``) at equal accuracy on *each*
   metric separately against ``standard`` and ``draft`` (section 1 matches the worst of the three), and a complete
   run, an early-stopped sweep point, the fixed cost of a call, the paper's ``compression_only`` reading and import
   to the first result now / before issue #24 (the serial ``recoil paper``'s CPU: ``bench_scipy.py --paper``).

It ends with issue #11's targets, each ratio beside its target.  Absolute times are printed only in
brackets beside the ratios, for context.
"""

from __future__ import annotations

import argparse
import ctypes
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))  # bench_throughput, bench_reuse, profile_solve

from bench_reuse import rss_bytes  # noqa: E402

C_SOURCE = Path(__file__).resolve().parent / "recoil_dopri5.c"


def ms(seconds: float) -> str:
    return f"{seconds * 1e3:.3g} ms"


# ------------------------------------------------------------------------------------------------ import

def import_cost() -> dict[str, float]:
    """Import times (s) in a fresh interpreter: numpy, Exudyn (its fast module, as the engine loads it), and
    everything else a run needs, with the package compiled to bytecode first (as installed; see
    :mod:`bench_before`)."""
    import bench_before

    bench_before.compile_tree(ROOT)
    code = ("import contextlib, io, sys, time; t0 = time.perf_counter(); import numpy; t1 = time.perf_counter(); "
            "sys.exudynFast = True\nwith contextlib.redirect_stdout(io.StringIO()): import exudyn\n"
            "t2 = time.perf_counter(); import mbs_models.engine.simulation; t3 = time.perf_counter(); "
            "print(t1 - t0, t2 - t1, t3 - t2)")
    runs = []
    for _ in range(3):
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT,
                             env={**os.environ, "PYTHONPATH": str(ROOT)}, check=True).stdout.split()
        runs.append([float(x) for x in out])
    numpy_t, exudyn_t, rest_t = (statistics.median(r[i] for r in runs) for i in range(3))
    return {"numpy": numpy_t, "exudyn": exudyn_t, "mbs_models.engine.simulation and what it imports": rest_t}


# ------------------------------------------------------------------------------------------------ breakdown

def breakdown_round(scene, end_time: float, stages: dict[str, list[float]]) -> None:
    """One ``standard`` run called stage by stage as ``simulate`` does; appends each stage's time (s)."""
    import importlib

    from mbs_models.engine import stability
    from mbs_models.engine.accuracy import solver_settings_for
    from mbs_models.engine.assembly import assemble
    from mbs_models.engine.mechanism import Mechanism
    from mbs_models.results.postprocess import Interpolant, analyse, energies, find_impacts

    engine = importlib.import_module("mbs_models.engine.driver")
    readout = importlib.import_module("mbs_models.engine.readout")
    settings = solver_settings_for("standard")

    def timed(name, function, *args):
        start = time.perf_counter()
        value = function(*args)
        stages.setdefault(name, []).append(time.perf_counter() - start)
        return value

    timed("settings check (stability)", stability.check_settings, scene, settings, end_time)
    mechanism = timed("mechanism (elements)", Mechanism, scene)
    assembly = timed("assembly (incl. symbolic user functions)", assemble, scene, settings.user_functions, mechanism)
    try:
        accelerations = timed("initial accelerations", engine._initial_accelerations, assembly)
        timed("solve (Exudyn SolveDynamic)", engine._solve, assembly, settings, end_time)
        samples = timed("collect sensor data", readout.collect, assembly, end_time, settings, accelerations)
    finally:
        timed("release model (Reset)", assembly.close)
    timed("stepped-over-contact check", engine._settings_after_stepped_over_contacts, mechanism, samples, settings,
          1000.0, 0)
    metrics = timed("metrics (analyse)", analyse, mechanism, samples, 1000.0)
    for contact in mechanism.contacts:
        timed("  of which: impacts (find_impacts)", find_impacts, mechanism, contact, samples,
              samples.forces[contact.name], Interpolant(samples), 1000.0)
    timed("  of which: energies", energies, mechanism, samples, Interpolant(samples))
    e = metrics.energies
    error = e.kinetic_total + (e.stored_total if e.stored else 0.0) + sum(e.dissipated.values()) \
        - mechanism.initial_energy()
    timed("energy-balance check", stability.check_energy_balance, scene, samples.time, error, "bench")


# ------------------------------------------------------------------------------------------------ compiled yardstick

class CompiledDopri5:
    """``scripts/recoil_dopri5.c`` compiled with the system C compiler and loaded with ctypes."""

    def __init__(self, directory: Path):
        compiler = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc") or shutil.which("clang")
        if compiler is None:
            raise RuntimeError("no C compiler (cc, gcc, clang) on PATH")
        library = directory / "librecoil_dopri5.so"
        subprocess.run([compiler, "-O2", "-shared", "-fPIC", "-o", str(library), str(C_SOURCE), "-lm"], check=True,
                       capture_output=True)
        self.compiler = compiler
        self.lib = ctypes.CDLL(str(library))
        d = ctypes.POINTER(ctypes.c_double)
        self.lib.dopri5_recoil.argtypes = [d, ctypes.c_double, ctypes.c_double, ctypes.c_double, ctypes.c_double,
                                           ctypes.c_double, ctypes.c_int, d, d, d, ctypes.POINTER(ctypes.c_long)]
        self.lib.dopri5_recoil.restype = ctypes.c_int

    def prepare(self, scene, end_time: float, rtol: float, atol: float, max_step: float):
        """Allocate once; return a zero-argument callable that integrates and returns the sample count."""
        from validation.studies.precision import Parameters

        P = Parameters.from_scene(scene)
        params = np.array([P.M, P.k, P.c_recoil, P.c_counter, float(P.has_absorber), P.m, float(P.on_barrel), P.kr,
                           P.cr, P.kc, P.n, P.lam, P.gap_offset], dtype=float)
        capacity = int(50 * end_time / max_step) + 200_000
        self.t = np.zeros(capacity)
        self.y = np.zeros((capacity, 4))
        self.f = np.zeros((capacity, 4))
        self.stats = (ctypes.c_long * 2)()
        ptr = lambda a: a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))  # noqa: E731
        args = (ptr(params), P.v0, float(end_time), rtol, atol, max_step, capacity, ptr(self.t), ptr(self.y),
                ptr(self.f), self.stats)
        self._keep = params

        def run() -> int:
            count = self.lib.dopri5_recoil(*args)
            if count < 0:
                raise RuntimeError(f"compiled DOPRI5 failed with code {count}")
            return count
        return run

    def samples(self, count: int, scene):
        """The compiled run's samples as the engine's post-processing takes them (bodies, contact force)."""
        from mbs_models.results.postprocess import Samples
        from validation.studies.precision import Parameters, plain_contact_force

        y, f = self.y[:count], self.f[:count]
        names = ["barrel"] + (["absorber"] if scene.has_absorber else [])
        samples = Samples(time=self.t[:count].copy(),
                          positions={n: y[:, 2 * i].copy() for i, n in enumerate(names)},
                          velocities={n: y[:, 2 * i + 1].copy() for i, n in enumerate(names)},
                          accelerations={n: f[:, 2 * i + 1].copy() for i, n in enumerate(names)})
        if scene.has_absorber:
            samples.forces["contact"] = plain_contact_force(Parameters.from_scene(scene), y[:, :4].T)
        return samples


# ------------------------------------------------------------------------------------------------ elements

def split_absorbers(scene, n: int):
    """The scene's one absorber as n equal absorbers (mass, k_r, c_r and k_c divided by n): the same motion."""
    from dataclasses import replace

    a = scene.absorber
    part = replace(a, mass=a.mass / n, stiffness=a.stiffness / n, damping=a.damping / n,
                   contact=replace(a.contact, stiffness=a.contact.stiffness / n))
    return scene.with_changes(absorbers=(part,) * n, name=f"{n} absorbers")


def restitution_pair(scene):
    """(exact-restitution e = 0.5, Hunt-Crossley with lambda = chi / v0): the same first impact."""
    from mbs_models import Contact
    from mbs_models.elements.contact_laws import exact_restitution_factor

    c = scene.contact
    chi = exact_restitution_factor(0.5)
    law = Contact(gap=c.gap, stiffness=c.stiffness, exponent=c.exponent, law="exact-restitution", restitution=0.5)
    hc = Contact(gap=c.gap, stiffness=c.stiffness, exponent=c.exponent, damping_factor=chi / scene.initial_velocity)
    return scene.with_changes(contact=law), scene.with_changes(contact=hc)


def element_costs(scene, end_time: float, repeats: int) -> tuple[dict, dict]:
    """Median wall times (s) and steps: ``{n absorbers: (run, solve, steps)}`` and ``{law: (run, solve, steps)}``."""
    from mbs_models import simulate

    scenes = {n: split_absorbers(scene, n) for n in (1, 2, 4, 8)}
    law, hc = restitution_pair(scene)
    laws = {"exact-restitution (captures v-)": law, "hunt-crossley (lambda = chi/v0)": hc}
    times: dict = {}
    for _ in range(repeats):
        for key, s in [*scenes.items(), *laws.items()]:
            result = simulate(s, end_time, "standard")
            times.setdefault(key, []).append((result.wall_time, result.timings["solve"], result.steps))

    def med(rows):
        return tuple(statistics.median(r[i] for r in rows) for i in range(3))

    return {n: med(times[n]) for n in scenes}, {k: med(times[k]) for k in laws}


def exudyn_floor_round(scene, end_time: float, fold: bool = False) -> tuple[float, int]:
    """Exudyn's own cost per step for this scene's system, nothing of the product's: one item per connector (``fold``
    False, as issue #24 measured it; True: connectors on the same ends folded into one item, as the engine assembles
    them) with Exudyn's built-in linear law in place of every user function, no sensor stored, no pre-step function,
    the ``standard`` settings (:func:`profile_solve.run`).  Returns (solve wall time s, steps): the motion differs
    from the scene's, so compare per step."""
    import profile_solve

    return profile_solve.run(scene, "symbolic", pre_step=False, sensors=False, laws=False, end_time=end_time,
                             fold=fold)


#: What a step of the standard solve adds to Exudyn's floor, one thing at a time (:func:`step_layers_round`): name ->
#: (user functions for the laws, pre-step function, stored sensors).
STEP_LAYERS = {
    "Exudyn's floor (built-in linear laws, no pre-step, no sensors)": (False, False, False),
    "the laws as symbolic user functions": (True, False, False),
    "... and the pre-step function (the step budget)": (True, True, False),
    "... and the stored sensors: the product's solve": (True, True, True),
}


def step_layers_round(scene, end_time: float) -> dict[str, tuple[float, int, int]]:
    """One ``standard`` solve per :data:`STEP_LAYERS` entry, folded items as the engine assembles them: name ->
    (solve wall time s, accepted steps, rejected steps).  Without the user functions the contact is gone and the
    motion differs (fewer steps, fewer rejected): compare per step."""
    import profile_solve

    return {name: profile_solve.run_counted(scene, "symbolic", pre_step=pre, sensors=sensors, laws=laws,
                                            end_time=end_time)
            for name, (laws, pre, sensors) in STEP_LAYERS.items()}


# ------------------------------------------------------------------------------------------------ memory

def memory_test(scene, runs: int, end_time: float, progress) -> list[tuple[int, int]]:
    """RSS after each tenth of ``runs`` consecutive ``simulate`` calls: [(runs done, bytes)]."""
    from mbs_models import simulate

    marks = sorted({max(1, runs * k // 10) for k in range(1, 11)})
    out = [(0, rss_bytes())]
    for i in range(1, runs + 1):
        simulate(scene, end_time, "standard")
        if i in marks:
            out.append((i, rss_bytes()))
            progress(f"memory: {i} runs, RSS {out[-1][1] / 2**20:.1f} MiB")
    return out


# ------------------------------------------------------------------------------------------------ main

def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default="model_ii", help="shipped scene or TOML file (default model_ii)")
    parser.add_argument("--end-time", type=float, default=10.0, help="simulated time in s (default 10)")
    parser.add_argument("--repeats", type=int, default=9,
                        help="interleaved timing rounds, medians taken (default 9)")
    parser.add_argument("--memory-runs", type=int, default=10_000, help="consecutive runs of the memory test")
    parser.add_argument("--memory-end-time", type=float, default=0.05,
                        help="simulated time of each memory-test run in s (default 0.05: the first impact)")
    parser.add_argument("--skip-memory", action="store_true")
    parser.add_argument("--skip-elements", action="store_true", help="skip the absorber-count and onset-capture costs")
    parser.add_argument("--skip-sweeps", action="store_true", help="skip the Figs 4/5 sweep throughput")
    parser.add_argument("--skip-carriage", action="store_true",
                        help="skip the carriage scenes against their 1-D twins (section 8)")
    parser.add_argument("--skip-issue24", action="store_true",
                        help="skip issue #24's section (scipy at equal accuracy per metric, now / before #24)")
    parser.add_argument("--issue24-quick", action="store_true", help="the shorter issue #24 section")
    parser.add_argument("--gap-count", type=int, default=121,
                        help="gaps of the Figs 4/5 sweep per model and mass (default 121: 726 points)")
    parser.add_argument("--sweep-rounds", type=int, default=3,
                        help="alternating rounds of the sweep variants, the fastest of each taken (default 3)")
    parser.add_argument("--json", metavar="PATH", type=Path,
                        help="also write the measured ratios, the machine load and the date to PATH (JSON; the docs' "
                             "performance page renders docs/_generated/bench.json)")
    parser.add_argument("--paper", action="store_true",
                        help="also time a full `recoil paper` before issue #11 and now (about a minute)")
    args = parser.parse_args(argv)

    def say(message: str) -> None:
        print(f"[bench] {message}", file=sys.stderr, flush=True)

    warnings.simplefilter("ignore")
    from mbs_models.cli import _resolve_scene
    from mbs_models import simulate
    from mbs_models.engine.accuracy import ACCURACY_PRESETS
    from validation.studies.precision import (PRESET_METRICS, RunValues, _engine_values, compute_truth, relative_errors,
                                      solve_plain)

    scene = _resolve_scene(args.scene)
    end_time = args.end_time
    standard = ACCURACY_PRESETS["standard"]
    print(f"bench: {scene.name}, {end_time:g} s, standard = {standard.label()} (atol {standard.absolute_tolerance:g}, "
          f"max step {standard.max_step:g} s); medians of {args.repeats} interleaved rounds, all in this process")

    say("truth (event-driven reference, rtol 1e-12)")
    truth = compute_truth(scene, end_time, check_rtol=None)
    metrics = [m for m in PRESET_METRICS if scene.has_absorber or m == "max_barrel_displacement"]

    def worst(errors):
        return max(errors[m] for m in metrics)

    # ---------------------------------------------------------------- accuracy of each contender
    say("standard preset")
    simulate(scene, end_time, "standard")  # warm-up
    result = simulate(scene, end_time, "standard")
    standard_errors = relative_errors(_engine_values(result, truth), truth)
    target = worst(standard_errors)

    say("scipy LSODA: loosest tolerance at least as accurate as the standard preset")
    lsoda_rtol = lsoda_errors = None
    for rtol in [10.0 ** (-k / 2) for k in range(6, 27)]:  # 1e-3 ... 1e-13 in half decades
        solution = solve_plain(scene, end_time, "LSODA", rtol)
        values = RunValues(solution.max_barrel_displacement, solution.peak_contact_force,
                           solution.max_absorber_velocity, solution.impacts,
                           np.asarray(solution.sol(truth.grid)[0]))
        errors = relative_errors(values, truth)
        if worst(errors) <= target:
            lsoda_rtol, lsoda_errors = rtol, errors
            break

    say("compiled DOPRI5 yardstick")
    compiled_run = compiled_note = compiled = None
    directory = tempfile.TemporaryDirectory(prefix="recoil-bench-")
    try:
        yardstick = CompiledDopri5(Path(directory.name))
    except (RuntimeError, subprocess.CalledProcessError, OSError) as exc:
        compiled_note = f"skipped: {getattr(exc, 'stderr', None) or exc}"
    else:
        compiled_run = yardstick.prepare(scene, end_time, standard.relative_tolerance, standard.absolute_tolerance,
                                         standard.max_step)
        count = compiled_run()
        from mbs_models.engine.mechanism import Mechanism
        from mbs_models.results.peaks import HermiteTrajectory
        from mbs_models.results.postprocess import analyse

        samples = yardstick.samples(count, scene)
        mechanism = Mechanism(scene)
        m = analyse(mechanism, samples, 1000.0)
        contact = m.contacts.get("contact")
        v_max = m.max_velocity.get("absorber", (None, None))[0]
        values = RunValues(m.max_barrel_displacement, None if contact is None else contact.peak_force, v_max,
                           [] if contact is None else [(i.start, i.end, i.peak_force) for i in contact.impacts],
                           HermiteTrajectory(samples.time, samples.positions["barrel"],
                                             samples.velocities["barrel"])(truth.grid))
        compiled = (count - 1, relative_errors(values, truth), yardstick.compiler, int(yardstick.stats[1]))

    # ---------------------------------------------------------------- timing, interleaved rounds
    say(f"timing: {args.repeats} interleaved rounds (standard, LSODA, compiled, stage by stage)")
    timings: dict[str, list[float]] = {}
    stages: dict[str, list[float]] = {}

    def add(name, seconds):
        timings.setdefault(name, []).append(seconds)

    def clock(name, function, *arguments):
        """Call; record wall time as ``name`` and CPU time of this process as ``name cpu``."""
        wall, cpu = time.perf_counter(), time.process_time()
        value = function(*arguments)
        add(name, time.perf_counter() - wall)
        add(f"{name} cpu", time.process_time() - cpu)
        return value

    layer_steps: dict[str, tuple[int, int]] = {}
    for _ in range(args.repeats):
        run = clock("standard", simulate, scene, end_time, "standard")
        add("standard solve", run.timings["solve"])
        if lsoda_rtol is not None:
            solution = clock("lsoda", solve_plain, scene, end_time, "LSODA", lsoda_rtol)
            add("lsoda solve", solution.solve_time)
        if compiled_run is not None:
            for _ in range(5):
                clock("compiled", compiled_run)
            clock("compiled post", analyse, mechanism, samples, 1000.0)
        breakdown_round(scene, end_time, stages)
        floor_seconds, floor_steps = exudyn_floor_round(scene, end_time)
        add("exudyn floor per step", floor_seconds / floor_steps)
        floor_seconds, floor_steps = exudyn_floor_round(scene, end_time, fold=True)
        add("exudyn folded floor per step", floor_seconds / floor_steps)
        for name, (seconds, accepted, rejected) in step_layers_round(scene, end_time).items():
            add(f"layer {name}", seconds)
            layer_steps[name] = (accepted, rejected)
    directory.cleanup()
    t = {name: statistics.median(values) for name, values in timings.items()}
    stages = {name: statistics.median(values) for name, values in stages.items()}
    t_standard, t_standard_solve = t["standard"], t["standard solve"]
    lsoda = None if lsoda_rtol is None else (lsoda_rtol, lsoda_errors, t["lsoda"], t["lsoda solve"])
    if compiled is not None:
        steps, c_errors, compiler, rejected = compiled
        compiled = (t["compiled"], steps, c_errors, t["compiled post"], compiler, rejected)

    say("import cost (fresh interpreters)")
    imports = import_cost()

    # ---------------------------------------------------------------- elements
    absorber_costs = law_costs = None
    if not args.skip_elements and scene.absorber is not None:
        say("elements: 1, 2, 4, 8 absorbers; onset capture")
        absorber_costs, law_costs = element_costs(scene, end_time, max(3, args.repeats // 3))

    # ---------------------------------------------------------------- memory
    memory = None
    if not args.skip_memory and args.memory_runs > 0:
        say(f"memory: {args.memory_runs} consecutive runs of {args.memory_end_time:g} s")
        start = time.perf_counter()
        memory = memory_test(scene, args.memory_runs, args.memory_end_time, say)
        memory_wall = time.perf_counter() - start

    # ---------------------------------------------------------------- sweeps and the paper job
    import bench_throughput as throughput

    sweeps, paper, reuse = {}, {}, None
    if not args.skip_sweeps or args.paper:
        with throughput.baseline_checkout() as baseline:
            if baseline is None:
                say(f"no git history: the code before issue #11 ({throughput.BASELINE_REV}) is not measured")
            if not args.skip_sweeps:
                full_gaps = max(2, args.gap_count // 4)
                variants = [("before", baseline, 1, "local", False), ("now", ROOT, 1, "local", False),
                            ("now 2 workers", ROOT, 2, "local", False)]
                if throughput.dask_available():
                    variants.append(("dask LocalCluster 2 workers", ROOT, 2, "local-cluster", False))
                variants += [(f"full runs, before", baseline, 1, "local", True),
                             (f"full runs, now", ROOT, 1, "local", True)]
                runs: dict[str, list[dict]] = {}
                for round_ in range(args.sweep_rounds):  # alternating: a shared machine's load drifts into all alike
                    for name, tree, workers, kind, full in variants:
                        if tree is not None:
                            say(f"sweep: Figs 4/5 grid, {name} (round {round_ + 1} of {args.sweep_rounds})")
                            runs.setdefault(name, []).append(throughput.sweep_once(
                                tree, workers, kind, full_gaps if full else args.gap_count, full))
                sweeps = {name: min(outs, key=lambda out: out["wall"]) for name, outs in runs.items()}
                if args.gap_count == throughput.GAP_COUNT:
                    import bench_reuse
                    say("sweep: fresh simulate against one reused Simulator, in this process")
                    reuse = bench_reuse.sweep_throughput(1, progress=say)
            if args.paper:
                for name, tree in (("before", baseline), ("now", ROOT)):
                    if tree is not None:
                        say(f"recoil paper, {name}")
                        paper[name] = throughput.paper_once(tree)
    reuse_memory = None
    if not args.skip_memory and args.memory_runs > 0:
        import bench_reuse
        say(f"memory: {args.memory_runs} points through one reused Simulator")
        reuse_memory = bench_reuse.memory_reuse(args.memory_runs, progress=say)

    # ---------------------------------------------------------------- report
    def err_text(errors):
        return ", ".join(f"{m.replace('max_', '').replace('_', ' ')} {errors[m]:.1e}" for m in metrics)

    load = t["standard"] / t["standard cpu"]
    record = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "scene": scene.name, "end_time_s": end_time,
              "repeats": args.repeats, "machine_load": load, "load_average_1min": os.getloadavg()[0], "cpus": os.cpu_count(),
              "command": "python scripts/bench.py " + " ".join(argv if argv is not None else sys.argv[1:]),
              "standard": {"steps": result.steps, "errors": dict(standard_errors),
                           "solve_fraction": t_standard_solve / t_standard}, "ratios": {}}
    ratios = record["ratios"]
    print()
    print(f"standard preset: errors {err_text(standard_errors)}; {result.steps} steps; the solve is "
          f"{100 * t_standard_solve / t_standard:.0f} % of a complete run [context: {ms(t_standard)}]")
    print(f"machine load: wall / CPU time of the standard run {load:.2f} "
          f"({'idle enough' if load < 1.15 else 'shared machine: trust the CPU-time ratios'})")
    floor_step, solve_step = t["exudyn floor per step"], t_standard_solve / result.steps
    print(f"per step ({result.steps} steps, max step {standard.max_step * 1e3:g} ms): the standard solve "
          f"{1e6 * solve_step:.2f} us, the complete run {1e6 * t_standard / result.steps:.2f} us; Exudyn's floor "
          f"{1e6 * floor_step:.2f} us: solve / floor {solve_step / floor_step:.2f}x (issue #24's target <= 1.3), "
          f"complete run / floor {t_standard / result.steps / floor_step:.2f}x (the floor with one item per connector; "
          f"with the connectors on the same ends folded, as the engine assembles them, {1e6 * t['exudyn folded floor per step']:.2f} us: "
          f"solve / folded floor {solve_step / t['exudyn folded floor per step']:.2f}x)")
    floor_name = next(iter(STEP_LAYERS))
    floor_accepted, floor_rejected = layer_steps[floor_name]
    floor_per_step = t[f"layer {floor_name}"] / floor_accepted
    floor_per_attempt = t[f"layer {floor_name}"] / (floor_accepted + floor_rejected)
    record["step_layers"] = []
    print("what a step of the standard solve adds to Exudyn's floor, one layer at a time (the items folded as the "
          "engine assembles them; per accepted step, and per attempt: accepted + rejected):")
    for name, (accepted, rejected) in layer_steps.items():
        seconds = t[f"layer {name}"]
        row = {"name": name, "solve_s": seconds, "steps": accepted, "rejected": rejected,
               "per_step_s": seconds / accepted, "per_attempt_s": seconds / (accepted + rejected),
               "per_step_over_floor": seconds / accepted / floor_per_step,
               "per_attempt_over_floor": seconds / (accepted + rejected) / floor_per_attempt}
        record["step_layers"].append(row)
        print(f"   {name:64s} {accepted:5d} steps, {rejected:4d} rejected: {1e6 * row['per_step_s']:5.2f} us per step "
              f"({row['per_step_over_floor']:4.2f}x the floor), {1e6 * row['per_attempt_s']:5.2f} us per attempt "
              f"({row['per_attempt_over_floor']:4.2f}x)")
    print("\n1. standard vs scipy LSODA at equal accuracy (same equations, no events, dense output; the worst of the "
          "three metrics: section 9 matches each separately)")
    if lsoda is None:
        print("   LSODA reached the standard preset's accuracy at no tolerance down to 1e-13: no ratio")
    else:
        rtol, lsoda_errors, t_lsoda, t_lsoda_solve = lsoda
        ratios["LSODA / standard, complete run (equal accuracy)"] = t_lsoda / t_standard
        ratios["LSODA / standard, integration alone"] = t_lsoda_solve / t_standard_solve
        print(f"   LSODA rtol {rtol:.3g} (atol rtol x 1e-2): errors {err_text(lsoda_errors)}")
        print(f"   LSODA / standard, complete run (solve + metrics):   {t_lsoda / t_standard:6.2f}x "
              f"(CPU time {t['lsoda cpu'] / t['standard cpu']:.2f}x) [{ms(t_lsoda)} vs {ms(t_standard)}]")
        print(f"   LSODA / standard, integration alone:              {t_lsoda_solve / t_standard_solve:6.2f}x "
              f"[{ms(t_lsoda_solve)} vs {ms(t_standard_solve)}]")
    print("\n2. standard vs a compiled fixed-structure DOPRI5 of the same equations (the physical limit)")
    if compiled is None:
        print(f"   {compiled_note}")
    else:
        t_c, steps, c_errors, t_c_post, compiler, rejected = compiled
        ratios["standard solve / compiled DOPRI5 integration"] = t_standard_solve / t_c
        ratios["standard complete run / compiled DOPRI5 integration"] = t_standard / t_c
        ratios["standard complete run / (compiled + the same post-processing)"] = t_standard / (t_c + t_c_post)
        ratios["Exudyn's floor / compiled DOPRI5 integration"] = t["exudyn floor per step"] * result.steps / t_c
        print(f"   compiled with {compiler} -O2: {steps} steps ({rejected} rejected; Exudyn: {result.steps}), "
              f"errors {err_text(c_errors)}")
        print(f"   standard solve / compiled integration:            {t_standard_solve / t_c:6.1f}x "
              f"[{ms(t_standard_solve)} vs {ms(t_c)}]")
        print(f"   standard complete run / compiled integration:     {t_standard / t_c:6.1f}x "
              f"(CPU time {t['standard cpu'] / t['compiled cpu']:.1f}x)")
        print(f"   standard complete run / (compiled + the same Python post-processing): "
              f"{t_standard / (t_c + t_c_post):6.2f}x")
        floor = t["exudyn floor per step"] * result.steps
        print(f"   Exudyn's floor / compiled integration:             {floor / t_c:6.1f}x [{ms(floor)}: this system "
              f"with built-in linear laws only, no sensors, no pre-step, {1e6 * t['exudyn floor per step']:.2f} us "
              f"per step, at the standard run's {result.steps} steps]")
    print("\n3. single-run cost breakdown (fractions of one complete standard run; import once per process)")
    run_total = sum(v for k, v in stages.items() if not k.startswith("  "))
    import_total = sum(imports.values())
    print(f"   import (fresh interpreter), relative to one run: {import_total / run_total:6.1f}x "
          f"[{ms(import_total)}: " + ", ".join(f"{k} {ms(v)}" for k, v in imports.items()) + "]")
    for name, value in stages.items():
        print(f"   {name:40s} {100 * value / run_total:5.1f} %  [{ms(value)}]")
    print(f"   (stage sum / simulate() wall time: {run_total / t_standard:.2f})")
    record["breakdown"] = {"import / one run": import_total / run_total,
                           **{name.strip(): value / run_total for name, value in stages.items()}}
    print(f"   post-processing (analyse) / solve: {stages['metrics (analyse)'] / stages['solve (Exudyn SolveDynamic)']:.3f}"
          " (issue #11's target: <= 0.15)")
    if memory is not None:
        print(f"\n4. memory over {args.memory_runs} consecutive runs ({args.memory_end_time:g} s each, "
              f"standard, symbolic user functions)")
        base = memory[1][1] if len(memory) > 1 else memory[0][1]
        for count, value in memory:
            print(f"   after {count:6d} runs: RSS {value / 2**20:8.1f} MiB")
        growth = memory[-1][1] - base
        per_run = growth / max(1, memory[-1][0] - memory[1][0]) if len(memory) > 2 else 0.0
        print(f"   growth from {memory[1][0]} to {memory[-1][0]} runs: {growth / 2**20:+.2f} MiB "
              f"({per_run:+.0f} bytes per run; {'OK, no growth' if abs(growth) < 4 * 2**20 else 'GROWS'})"
              f" [context: {args.memory_runs / memory_wall:.0f} runs/s]")
    if absorber_costs is not None:
        base_run, base_solve, base_steps = absorber_costs[1]
        print("\n5. elements: the same motion split over n absorbers (cost relative to 1 absorber), and the onset capture")
        for n, (run, solve, steps) in absorber_costs.items():
            print(f"   {n} absorber{'s' if n > 1 else ' '}: complete run {run / base_run:5.2f}x, solve {solve / base_solve:5.2f}x, "
                  f"solve per step {solve / steps / (base_solve / base_steps):5.2f}x  [{ms(run)}, {steps} steps]")
        (law_run, law_solve, law_steps), (hc_run, hc_solve, hc_steps) = law_costs.values()
        record["elements"] = {f"{n} absorbers": {"complete run": run / base_run, "solve": solve / base_solve,
                                                 "solve per step": solve / steps / (base_solve / base_steps)}
                              for n, (run, solve, steps) in absorber_costs.items()}
        record["elements"]["onset capture (exact-restitution / Hunt-Crossley)"] = {
            "complete run": law_run / hc_run, "solve per step": law_solve / law_steps / (hc_solve / hc_steps)}
        print(f"   onset capture (exact-restitution / Hunt-Crossley at the same first impact): solve per step "
              f"{law_solve / law_steps / (hc_solve / hc_steps):5.2f}x, complete run {law_run / hc_run:5.2f}x "
              f"[{law_steps} vs {hc_steps} steps]")
    if reuse_memory is not None:
        first = reuse_memory[1][1]
        print(f"\n4b. memory over {reuse_memory[-1][0]} points through one reused Simulator (model (ii), masses and gaps "
              f"cycling): RSS {first / 2**20:.1f} MiB after the first tenth, {reuse_memory[-1][1] / 2**20:.1f} MiB at the "
              f"end ({(reuse_memory[-1][1] - first) / 2**20:+.2f} MiB)")
    if sweeps:
        print(f"\n6. sweeps: the Figs 4/5 grid with the early stop, fresh interpreters (points per second; the "
              f"fastest of {args.sweep_rounds} alternating rounds)")
        for name, out in sweeps.items():
            print(f"   {name:30s} {out['points'] / out['wall']:7.1f} points/s  [{out['wall']:.1f} s wall, "
                  f"{out['cpu']:.1f} s CPU in the parent]")
        early = [out["values"] for name, out in sweeps.items() if not name.startswith("full")]
        full = [out["values"] for name, out in sweeps.items() if name.startswith("full")]
        print(f"   (\"full runs\": every 4th gap, complete 10 s runs with every metric, as `recoil sweep` runs by default)")
        print(f"   every variant gives the same displacements: "
              f"{all(v == early[0] for v in early) and all(v == full[0] for v in full)}")
        if reuse is not None:
            print(f"   in one process, serial: one reused Simulator / a fresh simulate per point: x{reuse['ratio']:.2f} "
                  f"[{reuse['points'] / reuse['fresh_s']:.1f} vs {reuse['points'] / reuse['reuse_s']:.1f} points/s]")
    if paper:
        print("\n7. the whole-paper job (full `recoil paper`, wall time)")
        for name, seconds in paper.items():
            print(f"   {name:8s} {seconds:6.1f} s")

    rows = []
    if stages:
        rows.append(("complete run / Exudyn solve", t_standard / t_standard_solve, "<= 1.3", t_standard / t_standard_solve <= 1.3))
    if compiled is not None:
        rows.append(("complete run / compiled DOPRI5", t_standard / compiled[0], "<= 12", t_standard / compiled[0] <= 12))
    if lsoda is not None:
        rows.append(("LSODA / complete run (equal accuracy)", lsoda[2] / t_standard, ">= 4", lsoda[2] / t_standard >= 4))
    if "before" in sweeps and "now" in sweeps:
        gain = sweeps["before"]["wall"] / sweeps["now"]["wall"]
        rows.append(("Figs 4/5 sweep (early stop), points/s now / before", gain, ">= 2", gain >= 2))
    if "full runs, before" in sweeps and "full runs, now" in sweeps:
        gain = sweeps["full runs, before"]["wall"] / sweeps["full runs, now"]["wall"]
        rows.append(("sweep of complete runs, points/s now / before", gain, ">= 2", gain >= 2))
    if "now 2 workers" in sweeps and "now" in sweeps:
        gain = sweeps["now"]["wall"] / sweeps["now 2 workers"]["wall"]
        rows.append(("sweep, 2 workers / 1 worker", gain, ">= 1.8", gain >= 1.8))
    if "now" in paper:
        rows.append(("full recoil paper, wall s" + (f" (before: {paper['before']:.1f} s)" if "before" in paper else ""),
                     paper["now"], "<= 8 s", paper["now"] <= 8))
    print("\nissue #11's targets (ratios of this run; the machine's load affects the wall-time ones)")
    for name, value, target, met in rows:
        print(f"   {name:55s} {value:7.2f}   target {target:8s} {'met' if met else 'NOT met'}")
    record["targets"] = [{"name": name, "value": value, "target": target, "met": bool(met)}
                         for name, value, target, met in rows]
    if not args.skip_carriage:
        import bench_carriage

        say("the carriage scenes against their 1-D twins")
        print("\n8. the planar model (issue #22): ", end="")
        costs = bench_carriage.carriage_costs(end_time=end_time, repeats=max(3, args.repeats // 3))
        bench_carriage.print_costs(costs, end_time)
        tree, mass = bench_carriage.bare_floor()
        print(f"   Exudyn's floor per fixed DOPRI5 step: a bare tree of the planar links {tree / mass:5.1f}x a bare "
              f"1-D mass [{tree:.1f} / {mass:.1f} us] (scripts/bench_carriage.py: the floor per simulated second)")
        record["carriage"] = {"rows": [{key: row[key] for key in ("scene", "preset", "run_ratio", "solve_ratio",
                                                                  "step_ratio")} for row in costs],
                              "bare_tree_us": tree, "bare_mass_us": mass}
    if not args.skip_issue24:
        import bench_scipy

        sys.stdout.flush()
        record["issue24"] = bench_scipy.run_section(quick=args.issue24_quick, progress=say)
    if args.json is not None:
        import json
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(record, indent=1, sort_keys=False) + "\n")
        say(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
