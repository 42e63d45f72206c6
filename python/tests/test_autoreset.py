"""Next-step auto-reset, truncation and episode statistics."""

import numpy as np
import pytest
from helpers import SOKOBAN_LEVEL0_SOLUTION

import psc

UP, LEFT, DOWN, RIGHT = 0, 1, 2, 3


def test_the_winning_step_shows_the_final_state_and_the_next_step_restarts(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=2, levels=0) as env:
        start, _ = env.reset(seed=0)
        crate, target = env.object_names.index("crate"), env.object_names.index("target")
        # Environment 1 walks down into the wall and stays put meanwhile.
        for action in SOKOBAN_LEVEL0_SOLUTION[:-1]:
            _, rewards, terminated, truncated, info = env.step([action, DOWN])
            assert not terminated.any() and not truncated.any() and "episode" not in info
        final, rewards, terminated, truncated, info = env.step([SOKOBAN_LEVEL0_SOLUTION[-1], DOWN])
        assert list(terminated) == [True, False] and not truncated.any()
        assert list(rewards) == [1.0, 0.0]
        # The final observation: the crate stands on the target.
        assert (final[0, crate] & final[0, target]).any()
        assert not (start[0, crate] & start[0, target]).any()
        # The next step ignores the action, restarts the level and gives no reward.
        restarted, rewards, terminated, truncated, info = env.step([RIGHT, DOWN])
        np.testing.assert_array_equal(restarted[0], start[0])
        assert list(rewards) == [0.0, 0.0] and not terminated.any() and not truncated.any()
        # Play goes on normally after the restart.
        moved, *_ = env.step([LEFT, DOWN])
        assert not np.array_equal(moved[0], start[0])


def test_episode_statistics_report_finished_episodes(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=2, levels=0) as env:
        env.reset(seed=0)
        info = {}
        for action in SOKOBAN_LEVEL0_SOLUTION:
            *_, info = env.step([action, DOWN])
        assert list(info["_episode"]) == [True, False]
        episode = info["episode"]
        assert list(episode["_r"]) == [True, False]
        assert episode["r"][0] == 1.0
        assert episode["l"][0] == len(SOKOBAN_LEVEL0_SOLUTION)
        # The second episode of environment 0 counts from its restart step (not counted).
        env.step([RIGHT, DOWN])
        for action in SOKOBAN_LEVEL0_SOLUTION:
            *_, info = env.step([action, DOWN])
        assert info["episode"]["l"][0] == len(SOKOBAN_LEVEL0_SOLUTION)
        assert info["episode"]["r"][0] == 1.0


def test_max_episode_steps_truncates(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=1, levels=0, max_episode_steps=3) as env:
        start, _ = env.reset(seed=0)
        for step in range(1, 4):
            _, rewards, terminated, truncated, info = env.step([LEFT])
            assert truncated[0] == (step == 3)
            assert not terminated[0]
        assert info["episode"]["l"][0] == 3 and info["episode"]["r"][0] == 0.0
        restarted, *_ = env.step([LEFT])
        np.testing.assert_array_equal(restarted, start)


def test_without_autoreset_a_win_moves_on_to_the_next_level(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=1, levels=0, autoreset=False) as env:
        assert env.metadata["autoreset_mode"] == "Disabled"
        env.reset(seed=0)
        for action in SOKOBAN_LEVEL0_SOLUTION:
            _, rewards, terminated, truncated, _ = env.step([action])
        assert rewards[0] == 1.0
        assert not terminated[0]  # terminated means the whole game was completed
        # games/sokoban.txt entries: message, level 0, level 1, ... -> now on entry 2 (level 1, 8x5).
        state = env.dump_state(0)
        assert (state["level"], state["width"], state["height"]) == (2, 8, 5)


def test_the_fused_random_rollout_counts_steps_and_episodes(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=8, levels=0, max_episode_steps=30) as env:
        env.reset(seed=0)
        stats = env.random_rollout(300, seed=1)
        assert stats["steps"] == 8 * 300
        # Every episode ends within 30 steps (a win or truncated), then a step restarts it.
        assert 8 * (300 // 31) <= stats["episodes"] <= stats["steps"]
        assert 0 < stats["wins"] <= stats["episodes"]
        with pytest.raises(RuntimeError, match="reset"):
            env.step([0] * 8)
