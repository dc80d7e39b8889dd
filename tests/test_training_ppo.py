"""A short Brax PPO run on ecn_2r's reach task (issue 41): the environment is trainable.

Budget: 400,000 environment steps (128 worlds, 100-step episodes), on the CPU; docs/training.md
gives the time and the figures. The trained policy's mean episode reward must beat a uniform
random policy's by at least `MARGIN` (measured: see docs/training.md).
"""

from __future__ import annotations

import pytest
from tests.test_training import _require, load_file

from simkit.kitio import layout

pytestmark = pytest.mark.slow
STEPS = 400_000
EPISODE = 100  # control steps (2 s)
#: the trained policy's mean episode reward over the random policy's, at least
MARGIN = 50.0


def random_reward(env, episodes: int = 64, seed: int = 1) -> float:
    """Mean episode reward of uniform random actions in [-1, 1]."""
    import jax
    import jax.numpy as jp

    @jax.jit
    def run(rng):
        state = jax.vmap(env.reset)(jax.random.split(rng, episodes))

        def one(carry, key):
            state, total = carry
            action = jax.random.uniform(key, (episodes, env.action_size), minval=-1, maxval=1)
            state = jax.vmap(env.step)(state, action)
            return (state, total + state.reward), None

        (_, total), _ = jax.lax.scan(
            one, (state, jp.zeros(episodes)), jax.random.split(rng, EPISODE)
        )
        return total.mean()

    return float(run(jax.random.PRNGKey(seed)))


def replicate(tree, devices):
    """`jax.device_put_replicated` (removed in JAX 0.10), which brax 0.14.2, the newest, still
    calls once to copy the training state to each device."""
    import jax
    import jax.numpy as jp

    return jax.pmap(lambda _: tree, devices=devices)(jp.arange(len(devices)))


def train(env):
    """(mean episode reward at each evaluation: the untrained policy first, the trained one
    last; the last metrics)."""
    import jax
    from brax.training.agents.ppo import train as ppo
    from mujoco_playground import wrapper

    if "device_put_replicated" not in vars(jax):
        jax.device_put_replicated = replicate  # brax 0.14.2 on JAX 0.10

    evals: list[float] = []
    _, _, metrics = ppo.train(
        environment=env,
        num_timesteps=STEPS,
        num_evals=3,
        episode_length=EPISODE,
        num_envs=128,
        batch_size=128,
        num_minibatches=8,
        unroll_length=10,
        num_updates_per_batch=4,
        learning_rate=1e-3,
        entropy_cost=1e-3,
        discounting=0.97,
        normalize_observations=True,
        seed=0,
        wrap_env_fn=wrapper.wrap_for_brax_training,
        progress_fn=lambda _, m: evals.append(float(m["eval/episode_reward"])),
    )
    return evals, metrics


def test_ppo_beats_random_on_reach(kit_factory):
    _require("mujoco_playground")
    _require("brax")
    kit = kit_factory("ecn_2r").kit_dir
    module = load_file(kit, layout.PLAYGROUND_ENV)
    env = module.load(config_overrides={"episode_length": EPISODE})
    baseline = random_reward(env)
    evals, _ = train(env)
    untrained, trained = evals[0], evals[-1]
    assert trained > baseline + MARGIN, (trained, baseline)
    assert trained > untrained + MARGIN / 2, (trained, untrained)
