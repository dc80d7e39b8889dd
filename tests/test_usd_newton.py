"""Issue 33: Newton (newton-physics) loads each physics variant of a kit's composed USD stage
with its own USD importer, on Warp's CPU device: the same bodies and masses, joints, limits
and drive gains as the MJCF in MuJoCo, and it steps without NaN. In the "mujoco" variant Newton's
MjcPhysics resolver also reads the MuJoCo joint armature, friction loss and servos. The "none"
variant gives Newton no body. A fixed arm (ecn_2r) and a floating robot with prismatic,
continuous and fixed joints (tests/specs/usd_mix.yaml).

Slow: the first run compiles Newton's Warp kernels for the CPU (about 40 s on two cores; about
7 s a robot once Warp's kernel cache holds them)."""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

import numpy as np
import pytest

from simkit.pipeline import build

SPECS = Path(__file__).resolve().parent / "specs"
STEPS = 200  # 0.2 s at 1 ms
MISSING = any(importlib.util.find_spec(m) is None for m in ("newton", "newton_usd_schemas"))
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        MISSING and not os.environ.get("SIMKIT_REQUIRE_NEWTON"),
        reason="newton and newton-usd-schemas not installed (test extra)",
    ),
]


@pytest.fixture(scope="module", params=["ecn_2r", "usd_mix"])
def kit(request, tmp_path_factory) -> tuple[Path, str]:
    """(kit folder, robot name), built without the other checks (only the USD is loaded)."""
    target = request.param if request.param == "ecn_2r" else str(SPECS / "usd_mix.yaml")
    result = build(target, tmp_path_factory.mktemp(request.param), check=False)
    return result.kit_dir, request.param


def _load(kit: Path, name: str, variant: str):
    """Newton's ModelBuilder holding the entry point's stage in `variant`; the "mujoco"
    variant is read with Newton's MjcPhysics resolver and its MuJoCo actuator attributes."""
    import newton
    import newton.usd
    import warp as wp
    from pxr import Usd

    wp.config.quiet = True
    stage = Usd.Stage.Open(str(kit / "usd" / f"{name}.usda"))
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        stage.GetDefaultPrim().GetVariantSet("Physics").SetVariantSelection(variant)
    builder = newton.ModelBuilder()
    if variant != "mujoco":
        builder.add_usd(stage)
        return builder
    newton.solvers.SolverMuJoCo.register_custom_attributes(builder)
    resolvers = [newton.usd.SchemaResolverMjc(), newton.usd.SchemaResolverNewton()]
    builder.add_usd(stage, schema_resolvers=resolvers)
    return builder


def _leaf(label: str) -> str:
    return label.rsplit("/", 1)[-1]


@pytest.mark.parametrize("variant", ["physics", "physx", "mujoco"])
def test_newton_loads_the_variant_as_the_mjcf(kit, variant):
    import mujoco
    import newton

    folder, name = kit
    mj = mujoco.MjModel.from_xml_path(str(folder / "mjcf" / f"{name}.xml"))
    b = _load(folder, name, variant)
    bodies = {mj.body(i).name: i for i in range(1, mj.nbody)}
    assert sorted(_leaf(x) for x in b.body_label) == sorted(bodies)
    for i, label in enumerate(b.body_label):
        body = bodies[_leaf(label)]
        assert b.body_mass[i] == pytest.approx(mj.body_mass[body], rel=1e-6)
        np.testing.assert_allclose(np.array(b.body_com[i]), mj.body_ipos[body], atol=1e-6)
    assert b.joint_dof_count == mj.nv
    moved = {_leaf(x): j for j, x in enumerate(b.joint_label) if b.joint_dof_dim[j][0] == 1}
    moved.update({_leaf(x): j for j, x in enumerate(b.joint_label) if b.joint_dof_dim[j][1] == 1})
    hinges = [j for j in range(mj.njnt) if mj.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE]
    assert sorted(moved) == sorted(mj.joint(j).name for j in hinges)
    servo = {int(mj.actuator_trnid[a, 0]): a for a in range(mj.nu)}
    for jid in hinges:
        dof = b.joint_qd_start[moved[mj.joint(jid).name]]
        if mj.jnt_limited[jid]:  # Newton reads USD degrees back into radians
            got = [b.joint_limit_lower[dof], b.joint_limit_upper[dof]]
            np.testing.assert_allclose(got, mj.jnt_range[jid], rtol=1e-6, atol=1e-7)
        if jid in servo:
            a = servo[jid]
            want = [mj.actuator_gainprm[a, 0], -mj.actuator_biasprm[a, 2]]
            got = [b.joint_target_ke[dof], b.joint_target_kd[dof]]
            np.testing.assert_allclose(got, want, rtol=1e-5)
            assert b.joint_effort_limit[dof] == pytest.approx(mj.actuator_forcerange[a, 1])
    if variant == "mujoco":
        _mujoco_values(b, mj, moved, hinges)
    model = b.finalize(device="cpu")
    solver = newton.solvers.SolverMuJoCo(model, use_mujoco_cpu=True)
    state, after, control = model.state(), model.state(), model.control()
    for _ in range(STEPS):
        state.clear_forces()
        solver.step(state, after, control, None, 1e-3)
        state, after = after, state
    assert np.isfinite(state.joint_q.numpy()).all() and np.isfinite(state.body_q.numpy()).all()


def _mujoco_values(b, mj, moved: dict, hinges: list[int]) -> None:
    """Newton read the MjcPhysics layer: joint armature and friction loss per DOF, and one
    MuJoCo actuator per servo with the servo's gains, bias and force range."""
    for jid in hinges:
        dof = b.joint_qd_start[moved[mj.joint(jid).name]]
        got = [b.joint_armature[dof], b.joint_friction[dof]]
        want = [mj.dof_armature[mj.jnt_dofadr[jid]], mj.dof_frictionloss[mj.jnt_dofadr[jid]]]
        np.testing.assert_allclose(got, want, rtol=1e-6)
    attrs = b.custom_attributes
    targets = [_leaf(x) for x in attrs["mujoco:actuator_target_label"].values]
    assert sorted(targets) == sorted(mj.joint(int(j)).name for j in mj.actuator_trnid[:, 0])
    for row, joint in enumerate(targets):
        a = next(a for a in range(mj.nu) if mj.joint(int(mj.actuator_trnid[a, 0])).name == joint)
        got = [
            *attrs["mujoco:actuator_gainprm"].values[row],
            *attrs["mujoco:actuator_biasprm"].values[row],
        ]
        want = [*mj.actuator_gainprm[a], *mj.actuator_biasprm[a]]
        np.testing.assert_allclose(got, want, rtol=1e-6)
        forces = attrs["mujoco:actuator_forcerange"].values[row]
        np.testing.assert_allclose(list(forces), mj.actuator_forcerange[a], rtol=1e-6)


def test_newton_finds_no_body_in_the_geometry_only_variant(kit):
    folder, name = kit
    b = _load(folder, name, "none")
    assert (b.body_count, b.joint_count) == (0, 0)
