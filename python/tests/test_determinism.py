"""Seeds fix trajectories of a game that uses randomness (games/gems.txt)."""

import numpy as np

import psc

NUM_ENVS = 4
STEPS = 40


def trajectory(plugin: str, seed, actions: np.ndarray) -> np.ndarray:
    with psc.VectorEnv(plugin, num_envs=NUM_ENVS) as env:
        observations, _ = env.reset(seed=seed)
        frames = [observations]
        for step_actions in actions:
            frames.append(env.step(step_actions)[0])
        return np.stack(frames)


def test_the_game_uses_randomness(gems_plugin):
    assert psc.Plugin(gems_plugin).info.uses_random


def test_same_seed_and_actions_give_the_same_trajectory(gems_plugin):
    actions = np.random.default_rng(0).integers(0, 5, size=(STEPS, NUM_ENVS))
    np.testing.assert_array_equal(trajectory(gems_plugin, 7, actions), trajectory(gems_plugin, 7, actions))
    per_env = [11, 12, 13, 14]
    np.testing.assert_array_equal(trajectory(gems_plugin, per_env, actions), trajectory(gems_plugin, per_env, actions))


def test_different_seeds_give_different_trajectories(gems_plugin):
    actions = np.random.default_rng(0).integers(0, 5, size=(STEPS, NUM_ENVS))
    assert not np.array_equal(trajectory(gems_plugin, 7, actions), trajectory(gems_plugin, 8, actions))


def test_an_int_seed_gives_environment_i_seed_plus_i(gems_plugin):
    actions = np.random.default_rng(1).integers(0, 5, size=(STEPS, NUM_ENVS))
    np.testing.assert_array_equal(
        trajectory(gems_plugin, 20, actions), trajectory(gems_plugin, [20, 21, 22, 23], actions)
    )


def test_the_constructor_seed_fixes_unseeded_resets(gems_plugin):
    def first_observations():
        with psc.VectorEnv(gems_plugin, num_envs=NUM_ENVS, seed=5) as env:
            return np.stack([env.reset()[0] for _ in range(3)])

    np.testing.assert_array_equal(first_observations(), first_observations())
