"""Drake, a third dynamics engine beside MuJoCo and Pinocchio: every seed kit's URDF and SDF
load into a MultibodyPlant with SceneGraph geometry (the OBJ collision pieces as convex
hulls), and Drake's mass matrix and link poses agree with MuJoCo's on the MJCF at 20 seeded
configurations.

MuJoCo's matrix carries the joint armature on its diagonal (rotor inertia that URDF and
SDFormat 1.9 cannot say), taken out before comparing. A free joint's velocities differ by
convention: MuJoCo (linear velocity in the world, angular in the body frame) vs Drake
(angular, then linear, both in the world), mapped by `_free_map`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pydrake", reason="drake is not installed (pip install -e .[test])")
mujoco = pytest.importorskip("mujoco")

from pydrake.geometry import Role  # noqa: E402
from pydrake.multibody.parsing import Parser  # noqa: E402
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph  # noqa: E402
from pydrake.systems.framework import DiagramBuilder  # noqa: E402

from mjcompat import full_mass_matrix  # noqa: E402
from simkit.check.readers.tree import read_urdf  # noqa: E402

pytestmark = pytest.mark.slow

SEEDS = ("asimov", "ecn_2r", "rosie_1000", "rosie_1400", "rosie_600")
CONFIGS = 20
M_TOL = 1e-9  # ||dM|| / ||M||, Frobenius
FK_TOL = 1e-9  # m, and rotation-matrix entries


def _drake(kit: Path, fmt: str):
    """(plant, context, scene graph inspector) of the kit's URDF or SDF. A fixed-base URDF's
    root link is welded to the world (SDF welds it itself; a URDF root named `world` is
    Drake's world)."""
    doc = json.loads((kit / "robot.json").read_text())
    path = kit / fmt / f"{doc['name']}.{fmt}"
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    (instance,) = Parser(plant).AddModels(str(path))
    if fmt == "urdf" and not doc.get("floating_base"):
        root = read_urdf(path).root
        if root != "world":
            plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(root, instance))
    plant.Finalize()
    diagram = builder.Build()
    context = plant.GetMyContextFromRoot(diagram.CreateDefaultContext())
    return plant, instance, context, scene_graph.model_inspector(), path


def _random_qpos(model, rng: np.random.Generator) -> np.ndarray:
    """Joint positions within the MJCF ranges (unlimited hinges +-pi); a free joint at a
    random place and orientation."""
    qpos = model.qpos0.copy()
    for j in range(model.njnt):
        adr = model.jnt_qposadr[j]
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            quat = rng.normal(size=4)
            qpos[adr : adr + 7] = [*rng.uniform(-1, 1, 3), *(quat / np.linalg.norm(quat))]
        else:
            low, high = model.jnt_range[j] if model.jnt_limited[j] else (-np.pi, np.pi)
            qpos[adr] = rng.uniform(low, high)
    return qpos


def _free_map(rot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(T, perm): Drake's free-body velocities = T @ MuJoCo's (6 x 6, `rot` the body's
    orientation in the world)."""
    t = np.zeros((6, 6))
    t[0:3, 3:6] = rot  # angular: body frame -> world
    t[3:6, 0:3] = np.eye(3)  # linear: world in both
    return t, np.arange(6)


def _drake_state(plant, instance, context, model, data) -> np.ndarray:
    """Set Drake's positions from MuJoCo's qpos; return T with v_drake = T @ qvel_mujoco."""
    q = plant.GetPositions(context).copy()
    t = np.zeros((plant.num_velocities(), model.nv))
    for j in range(model.njnt):
        name = model.joint(j).name
        qa, va = model.jnt_qposadr[j], model.jnt_dofadr[j]
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            body = plant.GetBodyByName(model.body(model.jnt_bodyid[j]).name, instance)
            qs, vs = body.floating_positions_start(), body.floating_velocities_start_in_v()
            q[qs : qs + 4] = data.qpos[qa + 3 : qa + 7]  # w, x, y, z in both
            q[qs + 4 : qs + 7] = data.qpos[qa : qa + 3]
            rot = data.xmat[model.jnt_bodyid[j]].reshape(3, 3)
            t[vs : vs + 6, va : va + 6] = _free_map(rot)[0]
        else:
            joint = plant.GetJointByName(name, instance)
            q[joint.position_start()] = data.qpos[qa]
            t[joint.velocity_start(), va] = 1.0
    plant.SetPositions(context, q)
    return t


def _compare(kit: Path, fmt: str) -> None:
    plant, instance, context, inspector, path = _drake(kit, fmt)
    collisions = path.read_text().count("<collision ")
    assert inspector.NumGeometriesWithRole(Role.kProximity) == collisions > 0
    doc = json.loads((kit / "robot.json").read_text())
    model = mujoco.MjModel.from_xml_path(str(kit / doc["files"]["mjcf"]))
    data = mujoco.MjData(model)
    assert plant.num_velocities() == model.nv
    rng = np.random.default_rng(0)
    worst_m, worst_fk = 0.0, 0.0
    for _ in range(CONFIGS):
        data.qpos[:] = _random_qpos(model, rng)
        mujoco.mj_forward(model, data)
        full = full_mass_matrix(model, data) - np.diag(model.dof_armature)
        t = _drake_state(plant, instance, context, model, data)
        mapped = t.T @ plant.CalcMassMatrix(context) @ t
        worst_m = max(worst_m, np.linalg.norm(mapped - full) / np.linalg.norm(full))
        for b in range(1, model.nbody):
            pose = plant.EvalBodyPoseInWorld(
                context, plant.GetBodyByName(model.body(b).name, instance)
            )
            worst_fk = max(
                worst_fk,
                np.abs(pose.translation() - data.xpos[b]).max(),
                np.abs(pose.rotation().matrix() - data.xmat[b].reshape(3, 3)).max(),
            )
    assert worst_m <= M_TOL, f"{path.name}: ||dM||/||M|| = {worst_m:.3g}"
    assert worst_fk <= FK_TOL, f"{path.name}: link poses differ by {worst_fk:.3g}"


@pytest.mark.parametrize("fmt", ["urdf", "sdf"])
@pytest.mark.parametrize("name", SEEDS)
def test_drake_loads_with_geometry_and_agrees_with_mujoco(seed_kits, name, fmt):
    _compare(seed_kits[name].kit_dir, fmt)


def test_drake_refuses_stl_convex_hulls(seed_kits, tmp_path):
    """Why the collision pieces are OBJ: the same URDF pointing at STL pieces fails in
    SceneGraph (Drake takes convex hulls only from OBJ, VTK or glTF)."""
    import shutil

    import trimesh

    kit = tmp_path / "kit"
    shutil.copytree(seed_kits["ecn_2r"].kit_dir, kit)
    urdf = kit / "urdf" / "ecn_2r.urdf"
    for piece in (kit / "meshes" / "collision").glob("*.obj"):
        trimesh.load(piece).export(piece.with_suffix(".stl"))
    urdf.write_text(urdf.read_text().replace(".obj", ".stl"))
    with pytest.raises(Exception, match=r"(?i)\.obj"):
        _drake(kit, "urdf")
