"""CUDA batches and zero-copy exchange with PyTorch, JAX and CuPy.

Skipped (reported as skipped) unless PyTorch sees a CUDA device.  The plugin
must have the CUDA backend: set PSC_CUDA_PLUGIN to a plugin built elsewhere
with `python3 -m psc build games/gems.txt -o gems.so --target all`, or have a
psc compiler with CUDA here (then games/gems.txt is built with --target all).
Every check compares the CUDA batch with a CPU batch of the same plugin.
"""

import contextlib
import os

import numpy as np
import pytest
from helpers import GAMES

import psc

torch = pytest.importorskip("torch")
if not torch.cuda.is_available():
    pytest.skip("PyTorch sees no CUDA device", allow_module_level=True)

NUM_ENVS = 64
STEPS = 40


@pytest.fixture(scope="module")
def plugin() -> str:
    path = os.environ.get("PSC_CUDA_PLUGIN") or psc.compile(GAMES / "gems.txt", target="all")
    if not psc.Plugin(path).info.has_backend(psc._abi.BACKEND_CUDA):
        pytest.skip(f"{path} was built without the CUDA backend")
    return path


@contextlib.contextmanager
def cuda_and_cpu(plugin, seed):
    """A CUDA batch and a CPU batch of the same plugin over its playable levels, reset alike."""
    playable = psc.Plugin(plugin).playable_levels()
    levels = [playable[i % len(playable)] for i in range(NUM_ENVS)]
    with psc.VectorEnv(plugin, NUM_ENVS, backend="cuda", levels=levels) as cuda, psc.VectorEnv(
        plugin, NUM_ENVS, backend="cpu", levels=levels
    ) as cpu:
        cuda.reset(seed=seed)
        cpu.reset(seed=seed)
        yield cuda, cpu


@pytest.fixture
def pair(plugin):
    with cuda_and_cpu(plugin, 11) as both:
        yield both


def random_actions(cpu_env, rng):
    return rng.integers(0, cpu_env.single_action_space.n, size=NUM_ENVS).astype(np.int32)


def test_buffers_live_on_the_device(pair):
    cuda, _ = pair
    assert cuda.buffers.device >= 0
    assert cuda.buffers.observations.__dlpack_device__() == (2, cuda.buffers.device)
    interface = cuda.buffers.observations.__cuda_array_interface__
    assert interface["version"] == 3 and interface["data"][0] == cuda.buffers.observations.address


def test_torch_views_the_plugin_memory(pair):
    cuda, _ = pair
    observations = torch.from_dlpack(cuda.buffers.observations)
    assert observations.is_cuda and observations.dtype == torch.uint8
    assert observations.data_ptr() == cuda.buffers.observations.address
    np.testing.assert_array_equal(observations.cpu().numpy(), cuda.observe())
    through_interface = torch.as_tensor(cuda.buffers.observations, device="cuda")
    assert through_interface.data_ptr() == cuda.buffers.observations.address


def test_host_steps_agree_with_the_cpu_backend(pair):
    cuda, cpu = pair
    rng = np.random.default_rng(0)
    for _ in range(STEPS):
        actions = random_actions(cpu, rng)
        for a, b in zip(cuda.step(actions)[:4], cpu.step(actions)[:4]):
            np.testing.assert_array_equal(a, b)


def test_device_steps_with_torch_actions(pair):
    cuda, cpu = pair
    cuda.set_stream(torch.cuda.current_stream().cuda_stream)
    observations = torch.from_dlpack(cuda.buffers.observations)  # viewed once, current after every step
    rewards = torch.from_dlpack(cuda.buffers.rewards)
    rng = np.random.default_rng(1)
    for _ in range(STEPS):
        actions = random_actions(cpu, rng)
        cuda.step_device(torch.from_numpy(actions).cuda())
        expected, expected_rewards, *_ = cpu.step(actions)
        np.testing.assert_array_equal(observations.cpu().numpy(), expected)
        np.testing.assert_array_equal(rewards.cpu().numpy(), expected_rewards)


def test_device_steps_on_a_side_stream(pair):
    cuda, cpu = pair
    stream = torch.cuda.Stream()
    rng = np.random.default_rng(2)
    with torch.cuda.stream(stream):
        cuda.set_stream(stream.cuda_stream)
        for _ in range(STEPS):
            actions = random_actions(cpu, rng)
            cuda.step_device(torch.from_numpy(actions).cuda())
            cpu.step(actions)
        observations = torch.from_dlpack(cuda.buffers.observations).cpu().numpy()
    np.testing.assert_array_equal(observations, cpu.observe())


def test_actions_written_into_the_buffer(pair):
    cuda, cpu = pair
    actions = torch.from_dlpack(cuda.buffers.actions)
    actions.fill_(3)
    cuda.step_device()
    expected, *_ = cpu.step(np.full(NUM_ENVS, 3))
    np.testing.assert_array_equal(cuda.observe(), expected)


def test_invalid_device_actions_are_reported(pair):
    cuda, _ = pair
    cuda.step_device(torch.full((NUM_ENVS,), 9, dtype=torch.int32, device="cuda"))
    with pytest.raises(psc.PscError, match="outside"):
        cuda.synchronize()


def test_state_records_and_saved_states_agree(pair):
    cuda, cpu = pair
    rng = np.random.default_rng(3)
    for _ in range(10):
        actions = random_actions(cpu, rng)
        cuda.step(actions)
        cpu.step(actions)
    for i in (0, NUM_ENVS - 1):
        assert cuda.dump_state(i) == cpu.dump_state(i)
    saved = cuda.clone_state(0)
    cuda.step(random_actions(cpu, rng))
    cuda.restore_state(0, saved)
    assert cuda.dump_state(0) == cpu.dump_state(0)


@pytest.mark.parametrize("game", ["kick.txt", "ice.txt", "gems.txt"])
def test_fused_rollouts_agree_with_the_cpu_backend(game):
    """psc_rollout runs hundreds of steps a launch on the GPU, through `again`
    chains (kick rolls its ball a cell per again turn, ice slides by again),
    auto-resets and the GPU's own movement resolution; each environment must
    end where the CPU's rollout leaves it, launch after launch."""
    with cuda_and_cpu(psc.compile(GAMES / game, target="all"), 5) as (cuda, cpu):
        for seed, steps in ((1, 300), (2, 7)):
            assert cuda.random_rollout(steps, seed) == cpu.random_rollout(steps, seed)
            for i in range(NUM_ENVS):
                assert cuda.dump_state(i) == cpu.dump_state(i), f"environment {i} after rollout {seed}"


def test_a_torch_view_outlives_close(plugin):
    env = psc.VectorEnv(plugin, NUM_ENVS, backend="cuda")
    start, _ = env.reset(seed=0)
    observations = torch.from_dlpack(env.buffers.observations)
    env.close()
    del env
    np.testing.assert_array_equal(observations.cpu().numpy(), start)


def test_jax_views_the_plugin_memory(pair):
    os.environ.setdefault("XLA_PYTHON_CLIENT_PREALLOCATE", "false")  # leave GPU memory to the plugin and torch
    jax = pytest.importorskip("jax")
    cuda, _ = pair
    observations = jax.dlpack.from_dlpack(cuda.buffers.observations)
    assert observations.unsafe_buffer_pointer() == cuda.buffers.observations.address
    np.testing.assert_array_equal(np.asarray(observations), cuda.observe())


def test_cupy_views_the_plugin_memory(pair):
    cupy = pytest.importorskip("cupy")
    cuda, _ = pair
    through_dlpack = cupy.from_dlpack(cuda.buffers.observations)
    through_interface = cupy.asarray(cuda.buffers.observations)
    assert through_dlpack.data.ptr == through_interface.data.ptr == cuda.buffers.observations.address
    np.testing.assert_array_equal(cupy.asnumpy(through_dlpack), cuda.observe())
