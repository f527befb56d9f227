"""The phase of each peak force (mbs_models.studies.recoil_peaks), issue #19: the text must say whether a
peak belongs to the recoil or to the counter-recoil into the buffer.

Two variants of the paper's simplified model (M = 5600 kg, k = 27500 N/m, v0 = 0.6909 m/s) with a
constant-orifice brake (A = 0.012 m^2, Cd = 0.7, rho = 870 kg/m^3: K = rho A^3 / (2 Cd^2 a^2)) and a
linear battery buffer (Kelvin-Voigt, stiffness K_b, no damping) at x = 0; the phases follow from energy:

* **slam**: recoil area 3e-4 m^2 (K = 1.7e4 N s^2/m^2: 8.1 kN at v0), an open counter-recoil orifice
  (1e-2 m^2: K = 15 N s^2/m^2, 4 N at 0.5 m/s, it dissipates ~0.1 % of the return's energy) and a stiff
  buffer (K_b = 5e7 N/m).  The spring returns the barrel from x_max to battery at v = x_max sqrt(k / M),
  and the buffer (an undamped spring) stops it with a peak force v sqrt(K_b M) (the spring's k x is ~0 at
  x ~ 0): ~10^5 N, an order above anything in the recoil (K v0^2 + k x_max, < 15 kN): the mount's peak
  is on counter-recoil into the buffer.
* **hard brake**: recoil area 1e-4 m^2 (K = 1.53e5: K v0^2 = 73 kN on the mount at t = 0, the spring
  k x = 0 there) and a soft buffer (K_b = 1e6 N/m, sqrt(K_b M) = 7.5e4 N s/m): whatever the return, the
  barrel meets the buffer slower than the free-recoil velocity v0 (the spring's energy at x_max is less
  than the shot's), so the buffer's peak is < v0 sqrt(K_b M) = 52 kN: the mount's peak is during recoil,
  at the shot.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mbs_models import simplified_model, simulate
from mbs_models.elements.end_stops import BatteryStop
from mbs_models.elements.firing import Burst
from mbs_models.elements.recoil_brake import RecoilBrake
from mbs_models.studies.recoil_peaks import COUNTER_RECOIL, RECOIL, peak_forces, phase_at

M, K_SPRING = 5600.0, 27500.0
V0 = 6.86 * 564.0 / M


def _scene(recoil_area: float, buffer_stiffness: float):
    brake = RecoilBrake(piston_area=0.012, orifice_area=recoil_area, discharge_coefficient=0.7, fluid_density=870.0,
                        counter_recoil_orifice_area=1e-2)
    stop = BatteryStop(position=0.0, law="kelvin-voigt", stiffness=buffer_stiffness, damping=0.0)
    return simplified_model().with_changes(recoil_damper=None, recoil_brake=brake, battery_stop=stop)


def _coefficient(area: float) -> float:
    return 870.0 * 0.012 ** 3 / (2 * 0.7 ** 2 * area ** 2)


def test_a_barrel_slamming_into_its_buffer_peaks_on_counter_recoil():
    result = simulate(_scene(3e-4, 5e7), 3.0)
    peaks = peak_forces(result)
    x_max = result.max_barrel_displacement
    slam = x_max * math.sqrt(K_SPRING / M) * math.sqrt(5e7 * M)
    assert peaks["battery_stop"].force == pytest.approx(slam, rel=0.02)
    assert slam > 5 * (_coefficient(3e-4) * V0 ** 2 + K_SPRING * x_max)  # the phases' margin
    for name in ("battery_stop", "mount"):
        assert peaks[name].phase == COUNTER_RECOIL and peaks[name].into_buffer, name
        assert peaks[name].text().split(" (t =")[0].endswith("on counter-recoil into the buffer")
    assert peaks["mount"].force == pytest.approx(slam, rel=0.02)
    brake = peaks["brake"]  # K v0^2 at the shot
    at_shot = _coefficient(3e-4) * V0 ** 2
    assert brake.phase == RECOIL and brake.time == 0.0 and brake.force == pytest.approx(at_shot, rel=1e-9)
    assert brake.text() == f"peak brake force {at_shot / 1e3:.2f} kN during recoil (t = 0.000 s)"


def test_a_hard_brake_peaks_at_the_shot_during_recoil():
    result = simulate(_scene(1e-4, 1e6), 3.0)
    peaks = peak_forces(result)
    at_shot = _coefficient(1e-4) * V0 ** 2
    assert V0 * math.sqrt(1e6 * M) < 0.75 * at_shot  # the phases' margin
    assert peaks["mount"].phase == RECOIL and not peaks["mount"].into_buffer
    assert peaks["mount"].force == pytest.approx(at_shot, rel=1e-6)
    assert peaks["mount"].time == pytest.approx(0.0, abs=1e-9)
    assert peaks["mount"].text().split(" (t =")[0] == f"peak force on the mount {at_shot / 1e3:.2f} kN during recoil"
    if "battery_stop" in peaks:  # touched on the return: by then it is the counter-recoil
        assert peaks["battery_stop"].phase == COUNTER_RECOIL and peaks["battery_stop"].force < V0 * math.sqrt(1e6 * M)


def test_the_phase_is_the_turning_point_s_not_the_velocity_s():
    """After the turning point the barrel returns (counter-recoil) and, bouncing off its undamped buffer,
    moves out again (v > 0): still counter-recoil.  Before it, recoil."""
    result = simulate(_scene(3e-4, 5e7), 3.0)
    t_max = result.time_of_max_barrel_displacement
    bounce = result.time[(result.time > t_max) & (result.barrel_velocity > 0.05)]
    assert bounce.size and phase_at(result, float(bounce[0])) == COUNTER_RECOIL
    assert phase_at(result, 0.5 * t_max) == RECOIL and phase_at(result, 0.0) == RECOIL
    assert phase_at(result, t_max) == RECOIL


def test_with_a_burst_each_shot_has_its_phases():
    """A second shot fired at 3 s: just after it the barrel recoils again; its slam is that shot's
    counter-recoil."""
    result = simulate(_scene(3e-4, 5e7).with_changes(burst=Burst(shots=2, interval=3.0)), 6.0)
    second = result.shots[1]
    assert phase_at(result, second["time"] + 0.05) == RECOIL
    t = result.time
    after = (t > second["time_of_max_barrel_displacement"]) & (t < 6.0)
    slam = t[after][np.argmax(np.abs(result.support_force[after]))]
    assert phase_at(result, float(slam)) == COUNTER_RECOIL
