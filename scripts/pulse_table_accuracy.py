#!/usr/bin/env python
"""The engine's error against the independent reference for breech-force pulses of many table points (issue #19).

    python scripts/pulse_table_accuracy.py              # the 401-point table and the small ones, three presets
    python scripts/pulse_table_accuracy.py --points 401 --scenes simplified
    python scripts/pulse_table_accuracy.py --shipped    # the shipped scenes with a pulse instead

Each table samples one smooth breech-force curve (:func:`breech_force_curve`, a 12 ms rise and decay) at
``n`` points, scaled to the paper's momentum (6.86 kg x 564 m/s): ``uniform-n`` at even spacing, ``uneven-n``
at spacing that grows along the pulse (no point a multiple of the engine's step).  Per scene, table and
preset it prints the engine's run time (the best of ``--repeat`` runs: the machine may be shared), its
steps, the errors of :func:`validation.studies.guarantee.errors_against_reference` (the reference at the
preset's tight tolerances) and the preset's violations.  Not a test: the
tests check the tolerances (``tests/elements/test_firing.py``); this measures the margin and the cost.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mbs_models import Firing, Pulse, load_scene, model_ii, simplified_model, simulate  # noqa: E402
from mbs_models.scenes import scene_path  # noqa: E402
from validation.studies.guarantee import TOLERANCES, errors_against_reference, reference_for, violations  # noqa: E402

#: Length of the pulse (s) and the time of its peak (s).
DURATION, PEAK_TIME = 0.012, 0.002
#: Spacing exponent of the uneven tables: t_i = DURATION (i / (n - 1))^UNEVEN_EXPONENT (denser near the start).
UNEVEN_EXPONENT = 1.37
KEYS = ("energy", "x", "v", "dissipated", "F", "S", "peaks", "time")


def breech_force_curve(t: float) -> float:
    """A breech force shape (N, before scaling): ``(t / t_p)^2 exp(2 (1 - t / t_p))`` for t_p = 2 ms, a smooth
    rise to 1 at the peak and an exponential decay; cut to 0 at the pulse's end (12 ms)."""
    s = t / PEAK_TIME
    return s * s * math.exp(2.0 * (1.0 - s))


def table(points: int, uneven: bool) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(times s, forces N) of the curve at ``points`` points over [0, DURATION]; uneven: denser early."""
    exponent = UNEVEN_EXPONENT if uneven else 1.0
    times = tuple(DURATION * (i / (points - 1)) ** exponent for i in range(points))
    return times, tuple(breech_force_curve(t) for t in times)


def pulse_scene(base, points: int, uneven: bool):
    times, forces = table(points, uneven)
    firing = Firing(projectile_mass=6.86, muzzle_velocity=564.0,
                    pulse=Pulse(times=times, forces=forces, scale_to_momentum=True))
    kind = "uneven" if uneven else "uniform"
    return base.with_changes(firing=firing, name=f"{base.name}, {kind} {points}-point pulse")


SCENES = {"simplified": (simplified_model, 2.0), "model_ii": (lambda: model_ii(1000.0, 0.0), 2.0)}
#: The shipped scenes with a pulse and the simulated time (s) they are measured over.
SHIPPED = {"breech_pulse": 2.0, "realistic": 6.0}


def measure(label: str, scene, end_time: float, accuracy: str, repeat: int) -> None:
    """Print one line: the best run time of ``repeat`` runs, the steps, the errors and the violations."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = simulate(scene, end_time, accuracy)
        times.append(time.perf_counter() - start)
    ref = reference_for(scene, end_time, (), accuracy)
    errors = errors_against_reference(result, ref, TOLERANCES[accuracy]["time"])
    problems = violations(errors, accuracy)
    worst = " ".join(f"{k}={errors[k]:.1e}" for k in KEYS)
    print(f"{label} {accuracy:9s} {min(times) * 1e3:8.1f} ms {result.steps:6d} steps  {worst}"
          f"  {'OK' if not problems else 'VIOLATES ' + '; '.join(problems)}", flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, nargs="*", default=[4, 11, 41, 401])
    parser.add_argument("--scenes", nargs="*", default=list(SCENES), choices=list(SCENES))
    parser.add_argument("--presets", nargs="*", default=list(TOLERANCES), choices=list(TOLERANCES))
    parser.add_argument("--repeat", type=int, default=3, help="engine runs per point (the best time is printed)")
    parser.add_argument("--shipped", action="store_true", help="measure the shipped scenes with a pulse instead")
    args = parser.parse_args(argv)
    if args.shipped:
        for name, end_time in SHIPPED.items():
            for accuracy in args.presets:
                measure(f"{name:24s}", load_scene(scene_path(name)), end_time, accuracy, args.repeat)
        return 0
    for scene_name in args.scenes:
        factory, end_time = SCENES[scene_name]
        for points in args.points:
            for uneven in (False, True):
                label = f"{scene_name:10s} {'uneven' if uneven else 'uniform':7s} {points:5d}"
                scene = pulse_scene(factory(), points, uneven)
                for accuracy in args.presets:
                    measure(label, scene, end_time, accuracy, args.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
