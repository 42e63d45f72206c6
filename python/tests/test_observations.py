"""Observations agree with the plugin's canonical state record (psc_dump_state)."""

import numpy as np
from helpers import planes_from_record

import psc


def check_against_dumps(env, observations):
    info = env.info
    for i in range(env.num_envs):
        record = env.dump_state(i)
        expected = planes_from_record(record, env.object_names, info.max_height, info.max_width)
        np.testing.assert_array_equal(observations[i], expected, err_msg=f"environment {i}")


def test_sokoban_observations_match_the_state_records(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=3, levels=[0, 1, 2]) as env:
        observations, _ = env.reset(seed=0)
        check_against_dumps(env, observations)
        rng = np.random.default_rng(0)
        for _ in range(30):
            observations, *_ = env.step(rng.integers(0, 5, size=3))
            check_against_dumps(env, observations)


def test_random_game_observations_match_the_state_records(gems_plugin):
    with psc.VectorEnv(gems_plugin, num_envs=4) as env:
        observations, _ = env.reset(seed=1)
        check_against_dumps(env, observations)
        rng = np.random.default_rng(1)
        for _ in range(30):
            observations, *_ = env.step(rng.integers(0, 5, size=4))
            check_against_dumps(env, observations)
        np.testing.assert_array_equal(env.observe(), observations)
