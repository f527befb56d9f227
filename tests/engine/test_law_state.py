"""Whether a kept item's user function serves the next point (mbs_models/engine/law_state.py, engine/folding.py):
only connectors of the same class whose attributes are equal by value and immutable all the way down share one
recording; anything else is recorded anew, and the results stay those of a fresh assembly."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, replace

import numpy as np
import pytest

from mbs_models import Simulator, load_scene, model_i, model_ii, simulate
from mbs_models.engine.law_state import same_law, same_laws, same_value
from mbs_models.engine.mechanism import Mechanism
from mbs_models.scenes import scene_path


@dataclass(frozen=True)
class Frozen:
    k: float
    table: tuple = ()


@dataclass
class Loose:
    k: float


class Colour(enum.Enum):
    RED = 1
    BLUE = 2


@pytest.mark.parametrize("a,b,equal", [
    (1.0, 1.0, True), (0.0, -0.0, False), (math.nan, math.nan, True), (1.0, 1.0 + 2 ** -52, False),
    (1, 1.0, False), (True, 1, False), ("hunt-crossley", "hunt-crossley", True), (None, None, True),
    ((0.0, (1.0, 2.0)), (0.0, (1.0, 2.0)), True), ((0.0, 1.0), (0.0, 1.0, 2.0), False),
    (Frozen(1.0, (2.0,)), Frozen(1.0, (2.0,)), True), (Frozen(1.0, (2.0,)), Frozen(1.0, (-2.0,)), False),
    (Colour.RED, Colour.RED, True), (Colour.RED, Colour.BLUE, False),
], ids=repr)
def test_values_compare_exactly(a, b, equal):
    assert same_value(a, b) is equal


def test_mutable_values_are_never_the_same_not_even_the_same_object():
    """A list, an array, a mutable dataclass: the held connector's may have changed since its law was recorded."""
    array, items, loose = np.ones(3), [1.0], Loose(1.0)
    for value in (array, items, loose, Frozen(1.0, (np.ones(2),))):
        assert not same_value(value, value)


def test_the_paper_connectors_share_what_a_sweep_keeps():
    """Another gap: the contact's law changes (its offset), the recoil spring's and dampers' do not; another
    absorber mass: no law changes (the mass is the body's); another damping: the recoil damper's changes."""
    base = Mechanism(model_ii(100.0, 0.04)).connector
    gap = Mechanism(model_ii(100.0, 0.08)).connector
    mass = Mechanism(model_ii(500.0, 0.04)).connector
    damped = Mechanism(model_ii(100.0, 0.04).with_changes(**{"recoil_damper.recoil": 9000.0})).connector
    assert {name: same_law(base[name], gap[name]) for name in base} == {
        "recoil_spring": True, "recoil_damper": True, "absorber_damper": True, "contact": False}
    assert all(same_law(base[name], mass[name]) for name in base)
    assert not same_law(base["recoil_damper"], damped["recoil_damper"])
    assert same_laws((base["recoil_spring"], base["recoil_damper"]), (gap["recoil_spring"], gap["recoil_damper"]))
    assert not same_laws((base["recoil_spring"],), (gap["recoil_spring"], gap["recoil_damper"]))
    assert not same_law(base["recoil_damper"], base["contact"])  # another class


def test_connectors_with_state_or_a_scene_never_share():
    """A restitution law's onset capture (its state) and the brake's scene: always recorded anew."""
    restitution = load_scene(scene_path("contact_exact_restitution"))
    assert not same_law(Mechanism(restitution).capturing_contacts[0], Mechanism(restitution).capturing_contacts[0])
    brake = load_scene(scene_path("recoil_brake"))
    assert not same_law(Mechanism(brake).connector["recoil_brake"], Mechanism(brake).connector["recoil_brake"])


def _count_recordings(monkeypatch) -> list:
    import exudyn.advancedUtilities as utilities

    calls = []
    original = utilities.CreateSymbolicUserFunction

    def counting(mbs, function, name, index=None, *args, **kwargs):
        calls.append(index)
        return original(mbs, function, name, index, *args, **kwargs)

    monkeypatch.setattr(utilities, "CreateSymbolicUserFunction", counting)
    return calls


def test_a_gap_sweep_records_the_recoil_law_once_and_the_contact_at_every_point(monkeypatch,
                                                                                 assert_results_identical):
    """Model (ii) over gaps, then over absorber masses, then with another recoil damping, through one system:
    two recordings for the first point, one per later gap (the contact), none per later mass, one for the new
    damping (the recoil spring and damper share one item); every result bit for bit a fresh run's."""
    scenes = ([model_ii(100.0, gap) for gap in (0.0, 0.04, 0.08)] + [model_ii(mass, 0.08) for mass in (300.0, 900.0)]
              + [model_ii(900.0, 0.08).with_changes(**{"recoil_damper.recoil": 9000.0})])
    fresh = [simulate(scene, 10.0, "standard", stop_when_final=("max_barrel_displacement",)) for scene in scenes]
    calls = _count_recordings(monkeypatch)
    counts = []
    with Simulator() as simulator:
        for scene, expected in zip(scenes, fresh):
            before = len(calls)
            assert_results_identical(
                simulator.simulate(scene, 10.0, "standard", stop_when_final=("max_barrel_displacement",)), expected)
            counts.append(len(calls) - before)
        assert simulator.assemblies == 1
    assert counts == [2, 1, 1, 0, 0, 1]


def test_python_user_functions_are_always_recorded_anew(assert_results_identical):
    """The python backend's functions are the connectors' own closures: never passed on (results as fresh)."""
    with Simulator() as simulator:
        for mass in (300.0, 900.0):
            scene = model_i(mass, 0.02)
            assert_results_identical(simulator.simulate(scene, 2.0, "draft", user_functions="python"),
                                     simulate(scene, 2.0, "draft", user_functions="python"))


def test_connectors_without_an_attribute_dictionary_are_not_compared():
    """A connector class keeping its numbers in slots: never the same law (recorded anew), never an error."""

    class Slotted:
        __slots__ = ("k",)

        def __init__(self, k):
            self.k = k

    assert not same_law(Slotted(1.0), Slotted(1.0))
