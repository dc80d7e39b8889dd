"""`training/` (issue 41): every seed kit's Playground environment resets and steps 8 worlds x
50 steps jitted without NaN, mjlab loads its entity and steps it, and the build's check holds
the Isaac Lab config to the USD stage (a tampered copy fails).

Playground and mjlab live in `simkit[train]`, which pins mujoco 3.11 (mjlab) and so goes in a
separate virtual environment (.ci/run); without them those tests skip, unless
SIMKIT_REQUIRE_TRAIN=1 (CI's training venv) makes the skip a failure.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import sys
from pathlib import Path

import pytest

from simkit.check.kit import Kit
from simkit.check.training import check_training
from simkit.kitio import layout

SEEDS = ("ecn_2r", "rosie_600", "rosie_1000", "rosie_1400", "asimov")
pytestmark = pytest.mark.slow


def _require(module: str):
    """The module, or a skip (a failure under SIMKIT_REQUIRE_TRAIN=1)."""
    if os.environ.get("SIMKIT_REQUIRE_TRAIN") == "1":
        return importlib.import_module(module)
    return pytest.importorskip(module, reason=f"{module}: pip install 'simkit[train]'")


def load_file(kit_dir: Path, relative: str):
    """Import one of a kit's training files as a module of its own (never cached across kits)."""
    path = kit_dir / relative
    name = f"_simkit_{kit_dir.name}_{path.stem}"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def _failed(kit_dir: Path) -> list[str]:
    return [f.check for f in check_training(Kit.open(kit_dir)) if not f.ok]


@pytest.mark.parametrize("name", SEEDS)
def test_training_files_pass_their_check(kit_factory, name):
    kit = kit_factory(name).kit_dir
    for relative in (layout.PLAYGROUND_ENV, layout.MJLAB_CFG, layout.ISAACLAB_CFG):
        assert (kit / relative).is_file(), relative
    found = check_training(Kit.open(kit))
    assert len(found) > 10 and all(f.ok for f in found), [f.line() for f in found if not f.ok]


def _tamper(tmp_path: Path, kit: Path, relative: str, old: str, new: str) -> Path:
    copy = tmp_path / kit.name
    shutil.copytree(kit, copy)
    text = (copy / relative).read_text(encoding="utf-8")
    assert old in text, old
    (copy / relative).write_text(text.replace(old, new, 1), encoding="utf-8")
    return copy


def test_isaaclab_tampered_stiffness_fails(kit_factory, tmp_path):
    kit = kit_factory("ecn_2r").kit_dir
    module = (kit / layout.ISAACLAB_CFG).read_text(encoding="utf-8")
    line = next(s for s in module.splitlines() if "stiffness=" in s)
    copy = _tamper(tmp_path, kit, layout.ISAACLAB_CFG, line, line.replace("=", "=1.01 * ", 1))
    assert "training.isaaclab.read" in _failed(copy)  # an expression is not a literal
    value = line.split("=", 1)[1].rstrip(",")
    copy2 = _tamper(tmp_path / "b", kit, layout.ISAACLAB_CFG, line, line.replace(value, "1234.5"))
    assert "training.isaaclab.actuators" in _failed(copy2)


@pytest.mark.parametrize(
    ("relative", "check"),
    [
        (layout.PLAYGROUND_ENV, "training.playground.servos"),
        (layout.MJLAB_CFG, "training.mjlab.servos"),
    ],
)
def test_tampered_gain_fails(kit_factory, tmp_path, relative, check):
    kit = kit_factory("ecn_2r").kit_dir
    text = (kit / relative).read_text(encoding="utf-8")
    kp = re.search(r'"kp": ([0-9.e+-]+)', text).group(0)
    copy = _tamper(tmp_path, kit, relative, kp, f'"kp": {float(kp.split(": ")[1]) * 1.01!r}')
    assert check in _failed(copy)


def test_isaaclab_tampered_home_and_velocity_fail(kit_factory, tmp_path):
    kit = kit_factory("asimov").kit_dir
    copy = _tamper(
        tmp_path, kit, layout.ISAACLAB_CFG, "velocity_limit_sim=", "velocity_limit_sim=2 * "
    )
    assert "training.isaaclab.read" in _failed(copy)  # not a literal
    text = (kit / layout.ISAACLAB_CFG).read_text(encoding="utf-8")
    pos = next(s for s in text.splitlines() if s.strip().startswith("pos="))
    copy2 = _tamper(tmp_path / "b", kit, layout.ISAACLAB_CFG, pos, "        pos=(0, 0, 0.5),")
    assert "training.isaaclab.base" in _failed(copy2)


@pytest.mark.parametrize("name", SEEDS)
def test_playground_env_steps_jitted(kit_factory, name):
    _require("mujoco_playground")
    import jax
    import jax.numpy as jp

    kit = kit_factory(name).kit_dir
    module = load_file(kit, layout.PLAYGROUND_ENV)
    from mujoco_playground import registry

    assert registry.get_default_config(name).ctrl_dt == module.default_config().ctrl_dt
    env = module.load()
    worlds, steps = 8, 50

    @jax.jit
    def rollout(rng):
        state = jax.vmap(env.reset)(jax.random.split(rng, worlds))

        def one(state, key):
            action = jax.random.uniform(key, (worlds, env.action_size), minval=-1, maxval=1)
            state = jax.vmap(env.step)(state, action)
            return state, state.reward

        return jax.lax.scan(one, state, jax.random.split(rng, steps))

    state, rewards = rollout(jax.random.PRNGKey(0))
    assert rewards.shape == (steps, worlds)
    assert not bool(jp.isnan(state.data.qpos).any()) and not bool(jp.isnan(rewards).any())
    assert state.obs.shape[0] == worlds and not bool(jp.isnan(state.obs).any())


@pytest.mark.parametrize("name", SEEDS)
def test_mjlab_entity_loads_and_steps(kit_factory, name):
    _require("mjlab")
    import numpy as np
    from mjlab.scene import Scene, SceneCfg
    from mjlab.sim.sim import Simulation, SimulationCfg

    kit = kit_factory(name).kit_dir
    module = load_file(kit, layout.MJLAB_CFG)
    scene = Scene(SceneCfg(num_envs=2, entities={"robot": module.get_robot_cfg()}), device="cpu")
    model = scene.compile()
    assert model.nu == len(module.ACTUATORS)
    gains = {
        model.actuator(a).name.split("/")[-1]: model.actuator_gainprm[a, 0] for a in range(model.nu)
    }
    assert gains == pytest.approx({n: v["kp"] for n, v in module.ACTUATORS.items()})
    sim = Simulation(num_envs=2, cfg=SimulationCfg(), model=model, device="cpu")
    scene.initialize(sim.mj_model, sim.model, sim.data)
    sim.reset()
    for _ in range(10):
        sim.step()
    qpos = np.asarray(sim.data.qpos.cpu() if hasattr(sim.data.qpos, "cpu") else sim.data.qpos)
    assert qpos.shape[0] == 2 and not np.isnan(qpos).any()
