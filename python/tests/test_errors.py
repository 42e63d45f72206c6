"""Misuse raises Python exceptions carrying the plugin's own message."""

import numpy as np
import pytest
from helpers import GAMES

import psc


@pytest.fixture
def env(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=2) as env:
        env.reset(seed=0)
        yield env


def test_a_level_out_of_range(env):
    with pytest.raises(psc.PscError, match=r"level 7 out of range \[0, 3\)") as raised:
        env.reset(options={"levels": [0, 7]})
    assert raised.value.status_name == "PSC_ERROR_BAD_LEVEL"


def test_a_level_left_out_of_the_plugin():
    plugin = psc.compile(GAMES / "sokoban.txt", levels=[1])
    with psc.VectorEnv(plugin, num_envs=1) as env:
        assert list(env.levels) == [1]  # the default: the first level built
        env.reset(seed=0)
        with pytest.raises(psc.PscError, match="left out of this plugin"):
            env.reset(options={"levels": 0})


def test_an_action_out_of_range(env):
    with pytest.raises(psc.PscError, match=r"action 9 of environment 1 out of range \[0, 8\)") as raised:
        env.step([0, 9])
    assert raised.value.status_name == "PSC_ERROR_BAD_ACTION"
    with pytest.raises(psc.PscError, match="action -1 of environment 0"):
        env.step([-1, 0])


def test_actions_of_the_wrong_shape_or_type(env):
    with pytest.raises(ValueError, match=r"shape \(2,\)"):
        env.step([0, 1, 2])
    with pytest.raises(ValueError, match=r"shape \(2,\)"):
        env.step(np.zeros((2, 1), dtype=np.int64))
    with pytest.raises(ValueError, match="integers"):
        env.step([0.5, 1.0])


def test_levels_of_the_wrong_shape(env):
    with pytest.raises(ValueError, match="one level or 2 levels"):
        env.reset(options={"levels": [0, 1, 2]})


def test_unknown_options(sokoban_plugin, env):
    with pytest.raises(ValueError, match="unknown reset options"):
        env.reset(options={"level": 1})
    with pytest.raises(ValueError, match="backend"):
        psc.VectorEnv(sokoban_plugin, backend="tpu")
    with pytest.raises(ValueError, match="reward"):
        psc.VectorEnv(sokoban_plugin, reward="dense")


def test_bad_batch_options_come_from_the_plugin(sokoban_plugin):
    with pytest.raises(psc.PscError, match="num_envs must be positive"):
        psc.VectorEnv(sokoban_plugin, num_envs=0)
    with pytest.raises(psc.PscError, match="undo_depth must not be negative"):
        psc.VectorEnv(sokoban_plugin, undo_depth=-1)


def test_a_cuda_backend_missing_from_the_plugin(sokoban_plugin):
    with pytest.raises(ValueError, match="no cuda backend"):
        psc.VectorEnv(sokoban_plugin, backend="cuda")


def test_environment_indices(env):
    with pytest.raises(IndexError):
        env.dump_state(2)
    with pytest.raises(IndexError):
        env.clone_state(-1)
    with pytest.raises(TypeError, match="EnvState"):
        env.restore_state(0, b"bytes")


def test_step_before_reset(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=1) as env:
        with pytest.raises(RuntimeError, match="reset"):
            env.step([0])


def test_a_closed_environment(env):
    env.close()
    with pytest.raises(RuntimeError, match="closed"):
        env.step([0, 0])
    env.close()  # closing twice is harmless


def test_compile_errors_carry_the_compiler_diagnostics(tmp_path):
    broken = tmp_path / "broken.txt"
    broken.write_text("title Broken\n\n========\nOBJECTS\n========\n\nPlayer\nnotacolour\n")
    with pytest.raises(psc.CompileError, match="expected a colour for object PLAYER"):
        psc.compile(broken)


def test_a_missing_compiler(tmp_path, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.setenv("PSC_BINARY", str(tmp_path / "nothing"))
    monkeypatch.setattr(psc.build, "_REPO_ROOT", tmp_path)
    with pytest.raises(FileNotFoundError, match="cannot find the psc compiler"):
        psc.compile(tmp_path / "game.txt")
