"""Zero-copy buffers on the CPU backend: DLPack and __array_interface__
(the same code paths that serve CUDA batches, with host memory)."""

import gc

import numpy as np
import pytest

import psc
from psc import dlpack


@pytest.fixture
def env(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=3, levels=[0, 1, 2]) as env:
        env.reset(seed=0)
        yield env


def test_buffers_are_views_of_the_plugin_memory(env):
    b = env.buffers
    assert b.device == -1
    observations = np.from_dlpack(b.observations)
    assert observations.ctypes.data == b.observations.address
    assert observations.shape == (3, 5, 7, 9) and observations.dtype == np.uint8
    np.testing.assert_array_equal(observations, env.observe())
    assert b.observations.__dlpack_device__() == (dlpack.DEVICE_CPU, 0)
    assert not hasattr(b.observations, "__cuda_array_interface__")
    # Views see the next step without being exported again.
    stepped, rewards, *_ = env.step([3, 3, 3])
    np.testing.assert_array_equal(observations, stepped)
    np.testing.assert_array_equal(np.asarray(b.rewards), rewards)


def test_every_buffer_has_its_shape_and_type(env):
    b = env.buffers
    for view, dtype in [
        (b.actions, np.int32),
        (b.rewards, np.float32),
        (b.terminated, np.uint8),
        (b.truncated, np.uint8),
        (b.won, np.uint8),
        (b.episode_steps, np.int32),
    ]:
        array = np.from_dlpack(view)
        assert array.shape == (3,) and array.dtype == dtype


def test_exports_are_released(env):
    before = len(dlpack._exported)
    consumed = np.from_dlpack(env.buffers.rewards)  # numpy consumes the capsule, then calls the deleter when freed
    unconsumed = env.buffers.rewards.__dlpack__()  # a capsule nobody consumed frees its tensor itself
    assert len(dlpack._exported) == before + 2
    del consumed, unconsumed
    gc.collect()
    assert len(dlpack._exported) == before


def test_a_view_keeps_the_plugin_memory_after_close(sokoban_plugin):
    env = psc.VectorEnv(sokoban_plugin, num_envs=1, levels=0)
    start, _ = env.reset(seed=0)
    observations = np.from_dlpack(env.buffers.observations)
    env.close()
    del env
    gc.collect()
    np.testing.assert_array_equal(observations, start)


def test_step_device_matches_step(sokoban_plugin):
    actions = np.random.default_rng(0).integers(0, 5, size=(20, 2)).astype(np.int32)
    with psc.VectorEnv(sokoban_plugin, num_envs=2, levels=[0, 2]) as host, psc.VectorEnv(
        sokoban_plugin, num_envs=2, levels=[0, 2]
    ) as device:
        host.reset(seed=0)
        device.reset(seed=0)
        for step_actions in actions:
            observations, rewards, terminated, truncated, _ = host.step(step_actions)
            views = device.step_device(step_actions)
            np.testing.assert_array_equal(np.asarray(views[0]), observations)
            np.testing.assert_array_equal(np.asarray(views[1]), rewards)
            np.testing.assert_array_equal(np.asarray(views[2]).astype(bool), terminated)
            np.testing.assert_array_equal(np.asarray(views[3]).astype(bool), truncated)


def test_step_device_reads_actions_written_into_the_buffer(env):
    expected = env.observe()
    np.asarray(env.buffers.actions)[:] = [1, 1, 1]
    observations, *_ = env.step_device()
    assert not np.array_equal(np.asarray(observations), expected)
    np.testing.assert_array_equal(np.asarray(observations), env.observe())


def test_step_device_takes_any_array_protocol(env):
    class DLPackOnly:
        """An array that offers DLPack and nothing else (as a CPU torch tensor would)."""

        def __init__(self, array):
            self.array = array

        def __dlpack__(self, stream=None):
            return self.array.__dlpack__()

        def __dlpack_device__(self):
            return self.array.__dlpack_device__()

    class ArrayInterfaceOnly:
        def __init__(self, array):
            self.array = array
            self.__array_interface__ = array.__array_interface__

    for wrapper in (DLPackOnly, ArrayInterfaceOnly):
        before = env.observe()
        observations, *_ = env.step_device(wrapper(np.array([3, 1, 3], dtype=np.int32)))
        after = np.asarray(observations)
        assert not np.array_equal(after, before)
        np.testing.assert_array_equal(after, env.observe())


def test_step_device_checks_its_actions(env):
    with pytest.raises(ValueError, match="shape"):
        env.step_device(np.zeros(4, dtype=np.int32))
    with pytest.raises(ValueError, match="dtype"):
        env.step_device(np.zeros(3, dtype=np.int64))
    with pytest.raises(ValueError, match="contiguous"):
        env.step_device(np.zeros(6, dtype=np.int32)[::2])
    with pytest.raises(TypeError, match="__dlpack__"):
        env.step_device([0, 0, 0])
    with pytest.raises(psc.PscError, match="out of range"):
        env.step_device(np.array([0, 8, 0], dtype=np.int32))


def test_step_after_step_device_needs_a_reset(env):
    env.step_device(np.zeros(3, dtype=np.int32))
    with pytest.raises(RuntimeError, match="reset"):
        env.step([0, 0, 0])
    env.reset(seed=0)
    env.step([0, 0, 0])


def test_shaped_rewards_are_not_offered_on_the_device_path(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=1, reward="shaped") as env:
        env.reset(seed=0)
        with pytest.raises(ValueError, match="shaped"):
            env.step_device(np.zeros(1, dtype=np.int32))


def test_torch_cpu_tensors_view_and_drive_the_batch(env):
    torch = pytest.importorskip("torch")
    observations = torch.from_dlpack(env.buffers.observations)
    assert observations.data_ptr() == env.buffers.observations.address
    before = observations.clone()
    env.step_device(torch.tensor([3, 1, 3], dtype=torch.int32))
    assert not torch.equal(observations, before)
    np.testing.assert_array_equal(observations.numpy(), env.observe())
