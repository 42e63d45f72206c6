"""clone_state / restore_state round trips (for search)."""

import dataclasses

import numpy as np
import pytest

import psc


def play(env, actions):
    return [env.step(a) for a in actions]


def test_restore_brings_back_the_observation_and_the_future(gems_plugin):
    rng = np.random.default_rng(3)
    with psc.VectorEnv(gems_plugin, num_envs=2) as env:
        env.reset(seed=3)
        play(env, rng.integers(0, 5, size=(5, 2)))
        saved = env.clone_state(0)
        saved_observation = env.observe()[0]
        future = rng.integers(0, 5, size=(15, 2))
        first = play(env, future)
        env.restore_state(0, saved)
        np.testing.assert_array_equal(env.observe()[0], saved_observation)
        second = play(env, future)
        # Environment 0 replays exactly, random draws included.
        for a, b in zip(first, second):
            np.testing.assert_array_equal(a[0][0], b[0][0])
            assert a[1][0] == b[1][0]


def test_a_state_restores_into_another_environment(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=2, levels=[0, 2]) as env:
        env.reset(seed=0)
        env.step([1, 1])
        env.restore_state(0, env.clone_state(1))
        observations = env.observe()
        np.testing.assert_array_equal(observations[0], observations[1])
        assert list(env.levels) == [2, 2]
        assert env.dump_state(0) == env.dump_state(1)


def test_restore_keeps_the_episode_return(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=1, levels=0, reward="shaped") as env:
        env.reset(seed=0)
        saved = env.clone_state(0)
        returns = []
        for _ in range(2):
            env.restore_state(0, saved)
            info = {}
            for action in [1, 1, 0, 3]:
                *_, info = env.step([action])
            returns.append(info["episode"]["r"][0])
        assert returns[0] == returns[1]


def test_undo_history_is_part_of_the_state(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=1, levels=0, undo_depth=8, full_action_space=True) as env:
        start, _ = env.reset(seed=0)
        env.step([1])
        saved = env.clone_state(0)
        env.reset(seed=0)  # clears the undo history
        env.restore_state(0, saved)
        undone, *_ = env.step([5])  # undo
        np.testing.assert_array_equal(undone, start)


def test_foreign_or_damaged_states_are_refused(sokoban_plugin, gems_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=1) as sokoban, psc.VectorEnv(gems_plugin, num_envs=1) as gems:
        sokoban.reset(seed=0)
        gems.reset(seed=0)
        with pytest.raises(psc.PscError):
            gems.restore_state(0, sokoban.clone_state(0))
        saved = sokoban.clone_state(0)
        damaged = dataclasses.replace(saved, data=b"garbage!" + saved.data[8:])
        with pytest.raises(psc.PscError, match="not a saved state of this game"):
            sokoban.restore_state(0, damaged)
