"""One process, batches on two GPUs: each on its own device, stepping alike,
and the caller's CUDA context left as it was.

Skipped (reported as skipped) unless PyTorch sees two CUDA devices.  The
plugin: PSC_CUDA_PLUGIN (built with --target all), else games/gems.txt built
here.
"""

import ctypes
import os

import numpy as np
import pytest
from helpers import GAMES

import psc

torch = pytest.importorskip("torch")
if torch.cuda.device_count() < 2:
    pytest.skip("PyTorch sees fewer than two CUDA devices", allow_module_level=True)

NUM_ENVS = 256
STEPS = 30


@pytest.fixture(scope="module")
def plugin() -> str:
    return os.environ.get("PSC_CUDA_PLUGIN") or psc.compile(GAMES / "gems.txt", target="all")


def current_context() -> int:
    """The calling thread's current CUDA context (the driver's, which PyTorch's current device follows)."""
    libcuda = ctypes.CDLL("libcuda.so.1")
    context = ctypes.c_void_p()
    assert libcuda.cuCtxGetCurrent(ctypes.byref(context)) == 0
    return context.value or 0


def test_batches_on_two_devices_step_like_the_cpu(plugin):
    rng = np.random.default_rng(5)
    with psc.VectorEnv(plugin, NUM_ENVS, backend="cuda", device=0) as first, psc.VectorEnv(
        plugin, NUM_ENVS, backend="cuda", device="cuda:1"
    ) as second, psc.VectorEnv(plugin, NUM_ENVS, backend="cpu") as cpu:
        assert (first.buffers.device, second.buffers.device) == (0, 1)
        assert torch.from_dlpack(second.buffers.observations).device == torch.device("cuda", 1)
        for env in (first, second, cpu):
            env.reset(seed=7)
        for _ in range(STEPS):
            actions = rng.integers(0, cpu.single_action_space.n, size=NUM_ENVS).astype(np.int32)
            expected, expected_rewards, *_ = cpu.step(actions)
            for env in (first, second):
                observations, rewards, *_ = env.step(actions)
                assert np.array_equal(observations, expected)
                assert np.array_equal(rewards, expected_rewards)


def test_device_actions_on_the_second_gpu(plugin):
    device = torch.device("cuda", 1)
    with psc.VectorEnv(plugin, NUM_ENVS, backend="cuda", device=device) as gpu, psc.VectorEnv(
        plugin, NUM_ENVS, backend="cpu"
    ) as cpu:
        gpu.set_stream(torch.cuda.current_stream(device).cuda_stream)
        gpu.reset(seed=3)
        cpu.reset(seed=3)
        observations = torch.from_dlpack(gpu.buffers.observations)
        rng = np.random.default_rng(9)
        for _ in range(STEPS):
            actions = rng.integers(0, cpu.single_action_space.n, size=NUM_ENVS).astype(np.int32)
            gpu.step_device(torch.from_numpy(actions).to(device))
            expected, *_ = cpu.step(actions)
            assert np.array_equal(observations.cpu().numpy(), expected)
        gpu.synchronize()
        with pytest.raises(ValueError):  # actions on the other GPU are refused, not read across devices
            gpu.step_device(torch.zeros(NUM_ENVS, dtype=torch.int32, device="cuda:0"))


def test_the_callers_context_is_given_back(plugin):
    torch.cuda.set_device(0)
    torch.zeros(1, device="cuda:0")  # PyTorch's context for device 0 is current now
    before = current_context()
    assert before != 0
    with psc.VectorEnv(plugin, NUM_ENVS, backend="cuda", device=1) as env:
        assert current_context() == before
        env.reset(seed=1)
        env.step(np.zeros(NUM_ENVS, dtype=np.int32))
        env.random_rollout(10, seed=2)
        env.observe()
        assert current_context() == before
        assert torch.cuda.current_device() == 0
        assert torch.zeros(1, device="cuda").device == torch.device("cuda", 0)
    assert current_context() == before
