"""Gymnasium vector API conformance: spaces, shapes, dtypes, signatures."""

import numpy as np
import pytest
from helpers import GAMES, TEST_GAMES

import psc

NUM_ENVS = 3


@pytest.fixture
def env(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=NUM_ENVS, levels=[0, 1, 2], seed=3) as env:
        yield env


def test_spaces_describe_the_batch(env):
    # games/sokoban.txt: objects background, target, player, wall, crate; largest level 9x7.
    assert env.object_names == ("background", "target", "player", "wall", "crate")
    assert env.single_observation_space.shape == (5, 7, 9)
    assert env.single_observation_space.dtype == np.uint8
    assert env.observation_space.shape == (NUM_ENVS, 5, 7, 9)
    assert env.single_action_space.n == 5  # up, left, down, right, action
    assert env.action_space.shape == (NUM_ENVS,)
    assert list(env.action_space.nvec) == [5] * NUM_ENVS
    assert env.metadata["autoreset_mode"] == "NextStep"
    assert env.num_envs == NUM_ENVS
    assert env.unwrapped is env


def test_reset_returns_observations_and_info(env):
    result = env.reset(seed=0)
    assert isinstance(result, tuple) and len(result) == 2
    observations, info = result
    assert isinstance(info, dict)
    assert observations.shape == (NUM_ENVS, 5, 7, 9)
    assert observations.dtype == np.uint8
    assert env.observation_space.contains(observations)
    assert env.single_observation_space.contains(observations[0])


def test_step_returns_five_arrays(env):
    env.reset(seed=0)
    actions = env.action_space.sample()
    assert env.action_space.contains(actions)
    observations, rewards, terminated, truncated, info = env.step(actions)
    assert observations.shape == (NUM_ENVS, 5, 7, 9) and observations.dtype == np.uint8
    assert rewards.shape == (NUM_ENVS,) and rewards.dtype == np.float32
    assert terminated.shape == (NUM_ENVS,) and terminated.dtype == bool
    assert truncated.shape == (NUM_ENVS,) and truncated.dtype == bool
    assert isinstance(info, dict)


def test_observations_are_copies(env):
    first, _ = env.reset(seed=0)
    kept = first.copy()
    env.step([3, 3, 3])
    np.testing.assert_array_equal(first, kept)


def test_every_level_is_padded_at_the_top_left(env):
    observations, _ = env.reset(seed=0)
    # The levels are 7x5, 8x5 and 9x7: every cell holds background, and nothing lies outside the level.
    for i, (width, height) in enumerate([(7, 5), (8, 5), (9, 7)]):
        assert env.level_size(i) == (width, height)
        background = observations[i, 0]
        assert background[:height, :width].all()
        assert not observations[i, :, height:, :].any()
        assert not observations[i, :, :, width:].any()


def test_reset_options_choose_levels(env):
    observations, _ = env.reset(seed=0, options={"levels": 2})
    assert list(env.levels) == [2, 2, 2]
    assert all(observations[i, 0].all() for i in range(NUM_ENVS))  # the 9x7 level fills the planes
    env.reset(seed=0, options={"levels": [1, 0, 2]})
    assert list(env.levels) == [1, 0, 2]


def test_full_action_space_and_noaction_games(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=1, full_action_space=True) as env:
        assert env.single_action_space.n == 8
    # A game with noaction plays with the four directions.
    with psc.VectorEnv(TEST_GAMES / "noaction.txt", num_envs=1) as env:
        assert env.info.noaction
        assert env.single_action_space.n == 4


def test_game_source_is_compiled_on_the_fly():
    with psc.VectorEnv(GAMES / "ice.txt", num_envs=2, levels=[0, 1]) as env:
        observations, _ = env.reset(seed=0)
        assert observations.shape[0] == 2
        assert env.info.title


def test_device_names_a_cuda_ordinal(sokoban_plugin):
    from types import SimpleNamespace

    from psc.vector_env import cuda_ordinal

    assert cuda_ordinal(2) == 2
    assert cuda_ordinal(np.int64(1)) == 1
    assert cuda_ordinal("cuda") == 0
    assert cuda_ordinal("cuda:3") == 3
    assert cuda_ordinal(SimpleNamespace(type="cuda", index=1)) == 1  # as torch.device("cuda", 1)
    assert cuda_ordinal(SimpleNamespace(type="cuda", index=None)) == 0
    for bad in (-1, "cpu", "cuda:x", True, 1.5, SimpleNamespace(type="cpu", index=None)):
        with pytest.raises(ValueError, match="device must be"):
            cuda_ordinal(bad)
    with pytest.raises(ValueError, match="device must be"):
        psc.VectorEnv(sokoban_plugin, num_envs=1, device="cpu")
