"""Connectors between the same two points share one Exudyn item (mbs_models/engine/folding.py): which ones, the
item's force, and the runs folded against one item per connector."""

from __future__ import annotations

import exudyn
import numpy as np
import pytest

from mbs_models import RecoilDamper, load_scene, model_ii, simplified_model
from mbs_models.engine.assembly import assemble
from mbs_models.engine.driver import FreshModels
from mbs_models.engine.folding import connector_items
from mbs_models.engine.mechanism import Mechanism
from mbs_models.engine.simulation import simulate_with
from mbs_models.scenes import list_scenes, scene_path
from validation.studies.guarantee import TOLERANCES


def _names(scene) -> list[tuple[str, ...]]:
    return [tuple(c.name for c in members) for members in connector_items(Mechanism(scene).connectors)]


def test_the_recoil_spring_and_damper_share_an_item_the_absorber_and_its_contact_do_not():
    """model (ii): the spring and the damper both act between the ground and the barrel; the absorber's damper
    acts between the ground and the absorber, its contact between the absorber and the barrel (and records its
    force)."""
    assert _names(model_ii(1000.0, 0.0)) == [("recoil_spring", "recoil_damper"), ("absorber_damper",), ("contact",)]


def test_a_contact_and_an_element_with_its_own_items_keep_their_own():
    """The end stops act between the ground and the barrel like the recoil spring, but record their force; the
    cradle's friction is Exudyn's own connector (its add_items is its own)."""
    stops = _names(load_scene(scene_path("end_stops")))
    assert ("recoil_stop",) in stops and ("battery_stop",) in stops
    assert ("recoil_spring", "recoil_damper") in stops
    cradle = _names(load_scene(scene_path("cradle")))
    assert ("cradle",) in cradle and ("recoil_spring", "recoil_damper") in cradle


def test_an_absent_element_adds_no_item_and_a_folded_one_none_either():
    """Without the recoil damper: the spring's item alone; with it (symmetric or not): still one item between the
    ground and the barrel, where one item per connector has two."""
    bare = simplified_model().with_changes(recoil_damper=RecoilDamper(0.0, 0.0))
    with assemble(bare) as assembly:
        objects = assembly.mbs.systemData.NumberOfObjects()
        assert set(assembly.connectors) == {"recoil_spring"}
    for damper in (RecoilDamper(8000.0, 8000.0), RecoilDamper(6239.0, 14050.0)):
        scene = simplified_model().with_changes(recoil_damper=damper)
        with assemble(scene) as assembly:
            assert assembly.mbs.systemData.NumberOfObjects() == objects
        with assemble(scene, fold=False) as assembly:
            assert assembly.mbs.systemData.NumberOfObjects() == objects + 1


def _forces(scene, backend: str, fold: bool, states) -> list[np.ndarray]:
    """The connector items' generalized forces (Exudyn's ODE2 LHS, summed over the items) at each ``(q, v)``."""
    out = []
    with assemble(scene, backend, fold=fold) as assembly:
        mbs, data = assembly.mbs, assembly.mbs.systemData
        items = sorted({int(index) for index in assembly.connectors.values()})
        for q, v in states:
            data.SetODE2Coordinates(list(q), configuration=exudyn.ConfigurationType.Current)
            data.SetODE2Coordinates_t(list(v), configuration=exudyn.ConfigurationType.Current)
            total = np.zeros(data.ODE2Size())
            for i in items:
                ltg = list(data.GetObjectLTGODE2(i))
                total[ltg] += np.asarray(mbs.ComputeItem(exudyn.ObjectIndex(i), exudyn.ComputeItemType.ODE2LHS))
            out.append(total)
    return out


@pytest.mark.parametrize("backend", ["symbolic", "python"])
def test_the_folded_item_exerts_the_members_summed_force(backend):
    """model (ii) at states in recoil (v > 0), in counter-recoil (v < 0) and in contact: the folded system's forces
    equal one item per connector's (the same additions in another order: to 1e-15 of the largest force), and the
    barrel's is the hand sum ``k x + c(v) v`` of Eqs. (1)-(3) while the contact is open (k = 27500 N/m, c = 6239 /
    14050 N s/m)."""
    scene = model_ii(1000.0, 0.02)
    states = [((0.01, 0.0), (2.0, 0.0)), ((0.1, 0.05), (-0.5, -1.0)), ((0.05, 0.0), (3.0, -1.0))]
    folded, separate = _forces(scene, backend, True, states), _forces(scene, backend, False, states)
    for a, b in zip(folded, separate):
        assert np.allclose(a, b, rtol=0.0, atol=1e-15 * np.max(np.abs(b)))
    # state 1: the absorber at rest at 0 and the barrel 10 mm back: the gap (20 mm) is open, no contact force
    barrel = 27500.0 * 0.01 + 6239.0 * 2.0
    assert folded[0][0] == pytest.approx(barrel, rel=1e-15)
    # state 2: counter-recoil (c = 14050), x_M - x_m = 0.05 m beyond the gap: the contact pushes both bodies (~3e6 N),
    # in opposite directions; the sum of both bodies' forces is the linear elements' alone (the contact's cancels
    # to its round-off, ~1e-9 N: rel 1e-9 of the ~7e3 N sum), with the absorber's k_r = 13500 N/m, c_r = 3675 N s/m
    barrel = 27500.0 * 0.1 + 14050.0 * -0.5
    assert abs(folded[1][0] - barrel) > 1e5
    assert folded[1][0] + folded[1][1] == pytest.approx(barrel + 13500.0 * 0.05 + 3675.0 * -1.0, rel=1e-9)


class _OneItemPerConnector(FreshModels):
    def acquire(self, scene, user_functions, mechanism):
        return assemble(scene, user_functions, mechanism, fold=False)


@pytest.mark.parametrize("name", list_scenes())
def test_a_run_is_the_same_folded_or_not(name):
    """Every shipped scene, 1 s at standard, folded and with one item per connector.  The 1-D scenes: the same steps
    and numbers (the folded item adds its members' forces, each body's residual then adds it: the same sums, in an
    order IEEE addition does not see; measured bit-identical, compared within 1e-12 in case another CPU contracts a
    product into a sum).  The carriage's tree adds the forces in another order: other round-off and other step sizes
    (measured: 1e-12 to 1e-8 apart on the metrics), within the standard preset's guarantee of each other."""
    scene = load_scene(scene_path(name))
    folded = simulate_with(FreshModels(), scene, 1.0, "standard")
    separate = simulate_with(_OneItemPerConnector(), scene, 1.0, "standard")
    pairs = [(folded.max_barrel_displacement, separate.max_barrel_displacement, "metric"),
             (folded.peak_support_force, separate.peak_support_force, "force")]
    if separate.peak_contact_force is not None:
        pairs.append((folded.peak_contact_force, separate.peak_contact_force, "force"))
    if scene.carriage is None:
        assert folded.steps == separate.steps
        scale = float(np.max(np.abs(separate.barrel_position)))
        assert np.allclose(folded.barrel_position, separate.barrel_position, rtol=0.0, atol=1e-12 * scale)
        for a, b, _ in pairs:
            assert abs(a - b) <= 1e-12 * abs(b), (a, b)
    else:
        for a, b, key in pairs:
            assert abs(a - b) <= TOLERANCES["standard"][key] * abs(b), (key, a, b)
