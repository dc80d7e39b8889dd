"""Imported robots get `training/` too (issue 41), through the same pipeline: an arm, and a
floating biped whose URDF has no sensors. The biped's GPU scene gains the base sensors
Playground's locomotion examples read (gyro, local_linvel, upvector) at a site on its base
link; the main MJCF does not change. Both kits' training files pass their check.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest
from tests.test_mjx_import import _biped, _mesh_arm
from tests.test_training import _require, load_file

from simkit.check.kit import Kit
from simkit.check.training import check_training
from simkit.emit.training_sensors import SITE
from simkit.importer import import_robot
from simkit.kitio import layout
from simkit.pipeline import build

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def kits(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("training_import")
    out = {}
    for name, make, floating in (("mesh_arm", _mesh_arm, False), ("box_biped", _biped, True)):
        done = import_robot(make(folder), folder / f"{name}_spec", floating=floating)
        out[name] = build(str(done.spec_path), folder / "kits").kit_dir
    return out


@pytest.mark.parametrize("name", ["mesh_arm", "box_biped"])
def test_imported_kits_carry_checked_training_files(kits, name):
    kit = kits[name]
    for relative in (layout.PLAYGROUND_ENV, layout.MJLAB_CFG, layout.ISAACLAB_CFG):
        assert (kit / relative).is_file(), relative
    found = check_training(Kit.open(kit))
    assert all(f.ok for f in found), [f.line() for f in found if not f.ok]


def test_a_floating_base_without_sensors_gets_them_in_the_gpu_scene_only(kits):
    kit = kits["box_biped"]
    gpu = mujoco.MjModel.from_xml_path(str(kit / layout.mjcf_mjx("box_biped")))
    site = gpu.site(SITE)
    assert gpu.body(int(site.bodyid[0])).name == "body"  # the floating base link
    kinds = {gpu.sensor(i).name: gpu.sensor_type[i] for i in range(gpu.nsensor)}
    assert kinds == {
        "gyro": mujoco.mjtSensor.mjSENS_GYRO,
        "local_linvel": mujoco.mjtSensor.mjSENS_VELOCIMETER,
        "upvector": mujoco.mjtSensor.mjSENS_FRAMEZAXIS,
    }
    main = mujoco.MjModel.from_xml_path(str(kit / layout.mjcf("box_biped")))
    assert main.nsensor == 0
    arm = mujoco.MjModel.from_xml_path(str(kits["mesh_arm"] / layout.mjcf_mjx("mesh_arm")))
    assert arm.nsensor == 0  # an arm observes its encoders


def test_the_imported_biped_stands_in_playground(kits):
    _require("mujoco_playground")
    import jax
    import jax.numpy as jp

    env = load_file(kits["box_biped"], layout.PLAYGROUND_ENV).load()
    state = jax.jit(env.reset)(jax.random.PRNGKey(0))
    step = jax.jit(env.step)
    for _ in range(5):
        state = step(state, jp.zeros(env.action_size))
    assert not bool(jp.isnan(state.obs).any())
    assert float(state.data.qpos[2]) > 0.5 * float(env._home_qpos[2])  # still up
