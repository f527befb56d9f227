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
    """Another gap: no law changes (the contact's offset is the item's, written anew); another absorber mass: none
    (the mass is the body's); another damping: the recoil damper's changes."""
    base = Mechanism(model_ii(100.0, 0.04)).connector
    gap = Mechanism(model_ii(100.0, 0.08)).connector
    mass = Mechanism(model_ii(500.0, 0.04)).connector
    damped = Mechanism(model_ii(100.0, 0.04).with_changes(**{"recoil_damper.recoil": 9000.0})).connector
    assert all(same_law(base[name], gap[name]) for name in base)
    assert base["contact"].offset != gap["contact"].offset
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


def test_a_sweep_records_each_law_once(monkeypatch, assert_results_identical):
    """Model (ii) over gaps, then over absorber masses, then with another recoil damping, through one system:
    two recordings for the first point (the recoil spring and damper share one item, the contact), none for a
    later gap (the contact's offset is the item's) or mass, one for the new damping; every result bit for bit a
    fresh run's."""
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
    assert counts == [2, 0, 0, 0, 0, 1]


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


CONTACT_SCENES = ["contact_hunt_crossley", "contact_hertz", "contact_kelvin_voigt", "contact_flores",
                  "contact_gonthier", "contact_lankarani_nikravesh", "contact_exact_restitution"]


@pytest.mark.parametrize("name", CONTACT_SCENES)
def test_every_contact_law_serves_another_gap_from_its_kept_item(name, monkeypatch, assert_results_identical):
    """Each contact law's scene, then the same with another gap, through one system: the second run is a fresh
    run's bit for bit, its contact law recorded again only where the law holds state (a restitution law's onset
    capture); the item's offset carries the gap."""
    from mbs_models.scenes import scene_path

    scene = load_scene(scene_path(name))
    other = scene.with_changes(**{"contact.gap": scene.contact.gap + 0.013})
    fresh = simulate(other, 1.0, "standard")
    calls = _count_recordings(monkeypatch)
    with Simulator() as simulator:
        simulator.simulate(scene, 1.0, "standard")
        before = len(calls)
        assert_results_identical(simulator.simulate(other, 1.0, "standard"), fresh)
        again = len(calls) - before
    stateful = Mechanism(scene).connector["contact"].capture is not None
    assert again == (1 if stateful else 0)


@pytest.mark.parametrize("field,value", [("stiffness", 2.2e8), ("exponent", 1.4), ("damping_factor", 0.7),
                                         ("law", "hertz")])
def test_every_number_of_the_contact_s_table_but_its_gap_changes_its_law_state(field, value):
    """The contact's ``spec`` (its table) is left out of the comparison (law_state_ignores): every field of it
    the law depends on is an attribute of the connector too, so a change of any of them is still seen."""
    from mbs_models import Contact

    base = model_ii(100.0, 0.04)
    assert isinstance(base.contact, Contact)
    fields = {field: value, **({"damping_factor": None} if value == "hertz" else {})}
    changed = base.with_changes(contact=replace(base.contact, **fields))
    assert not same_law(Mechanism(base).connector["contact"], Mechanism(changed).connector["contact"])


def test_every_field_of_the_contact_table_is_covered():
    """The fields of Contact: the gap (the item's offset) and the law's numbers, each of which the test above
    or the restitution laws' onset capture (never shared) covers: a new field fails here until it is."""
    import dataclasses

    from mbs_models import Contact

    covered = {"gap", "stiffness", "exponent", "damping_factor", "law",
               "restitution", "minimum_impact_velocity",  # restitution laws: an onset capture, never shared
               "damping"}  # kelvin-voigt's c: contact_damping
    assert {f.name for f in dataclasses.fields(Contact)} == covered
    kv = model_ii(100.0, 0.04).with_changes(contact=Contact(gap=0.04, stiffness=4e7, law="kelvin-voigt", damping=8e4))
    stiffer = kv.with_changes(contact=replace(kv.contact, damping=9e4))
    assert not same_law(Mechanism(kv).connector["contact"], Mechanism(stiffer).connector["contact"])
