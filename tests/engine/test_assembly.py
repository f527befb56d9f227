"""The assembled Exudyn system contains exactly the effects the scene calls for."""

from __future__ import annotations

import pytest

from mbs_models import RecoilDamper, load_scene, model_i, model_ii, simplified_model
from mbs_models.engine.assembly import assemble
from mbs_models.engine.mechanism import Mechanism
from mbs_models.scenes import list_scenes, scene_path


def _inventory(assembly):
    mbs = assembly.mbs
    objects = [mbs.GetObject(i) for i in range(mbs.systemData.NumberOfObjects())]
    types = [o["objectType"] for o in objects]
    user_functions = [o for o in objects if o.get("springForceUserFunction", 0) != 0]
    return types, user_functions, mbs.systemData.NumberOfNodes()


def test_simplified_model_has_no_absorber_and_no_contact():
    with assemble(simplified_model()) as assembly:
        types, user_functions, nodes = _inventory(assembly)
        assert nodes == 2  # ground + barrel
        assert types.count("Mass1D") == 1
        assert set(assembly.connectors) == {"recoil_spring", "recoil_damper"}
        assert "contact_force" not in assembly.sensors and "absorber_position" not in assembly.sensors
        # the asymmetric damper is the only user function
        assert assembly.user_function_connectors == ["recoil_damper"]
        assert len(user_functions) == 1


def test_symmetric_damper_uses_builtin_linear_damper_without_user_function():
    """Folded with the recoil spring (the same ends, engine/folding.py) into one built-in item: k and c together;
    unfolded, the damper's own item holds c alone."""
    scene = simplified_model().with_changes(recoil_damper=RecoilDamper(recoil=8000.0, counter_recoil=8000.0))
    with assemble(scene) as assembly:
        _, user_functions, _ = _inventory(assembly)
        assert user_functions == []
        damper = assembly.mbs.GetObject(assembly.connectors["recoil_damper"])
        assert damper["damping"] == 8000.0 and damper["stiffness"] == 27500.0
        assert assembly.connectors["recoil_spring"] == assembly.connectors["recoil_damper"]
    with assemble(scene, fold=False) as assembly:
        damper = assembly.mbs.GetObject(assembly.connectors["recoil_damper"])
        assert damper["damping"] == 8000.0 and damper["stiffness"] == 0.0


def test_zero_damping_adds_no_damper_at_all():
    scene = simplified_model().with_changes(recoil_damper=RecoilDamper(recoil=0.0, counter_recoil=0.0))
    with assemble(scene) as assembly:
        assert set(assembly.connectors) == {"recoil_spring"}


@pytest.mark.parametrize("factory, mount_is_barrel", [(model_i, True), (model_ii, False)])
@pytest.mark.parametrize("backend", ["symbolic", "python"])
def test_models_with_absorber(factory, mount_is_barrel, backend):
    with assemble(factory(500.0, 0.02), backend) as assembly:
        types, user_functions, nodes = _inventory(assembly)
        assert nodes == 3
        assert types.count("Mass1D") == 2
        assert set(assembly.connectors) == {"recoil_spring", "recoil_damper", "absorber_damper", "contact"}
        assert sorted(assembly.user_function_connectors) == ["contact", "recoil_damper"]
        assert len(user_functions) == 2
        mbs = assembly.mbs
        absorber_link = mbs.GetObject(assembly.connectors["absorber_damper"])
        mount_marker = mbs.GetMarker(absorber_link["markerNumbers"][0])
        mount_node = int(mount_marker["nodeNumber"])
        assert (mount_node == int(assembly.nodes["barrel"])) == mount_is_barrel
        assert absorber_link["stiffness"] == 13500.0 and absorber_link["damping"] == 3675.0
        contact = mbs.GetObject(assembly.connectors["contact"])
        # markers [absorber, barrel]: the connector's displacement is x_M - x_m
        nodes_of = [int(mbs.GetMarker(m)["nodeNumber"]) for m in contact["markerNumbers"]]
        assert nodes_of == [int(assembly.nodes["absorber"]), int(assembly.nodes["barrel"])]


def test_close_releases_the_model():
    assembly = assemble(model_ii())
    assembly.close()
    assert assembly.mbs is None and assembly.system_container is None
    assembly.close()  # idempotent


@pytest.mark.parametrize("name", list_scenes())
def test_the_mechanism_counts_the_sensors_the_assembly_stores(name):
    """The sample cap (engine/guard.py) is worked out before assembly from Mechanism.sensor_count."""
    scene = load_scene(scene_path(name))
    with assemble(scene) as assembly:
        assert Mechanism(scene).sensor_count == len(assembly.sensors)
