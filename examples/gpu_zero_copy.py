"""Checks that PyTorch, JAX and CuPy view a CUDA batch's buffers without copies.

    python3 examples/gpu_zero_copy.py --plugin gems.so     # built with --target all

For each framework present: its array's device pointer equals the plugin's
observation buffer, its values equal psc_observe's host copy, and stepping
with a device actions tensor (no host copy) gives the same states as a CPU
batch of the same plugin stepped with the same actions.  Prints one line per
check and exits 1 if any fails.
"""

import argparse
import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))  # run from a checkout without installing the package
os.environ.setdefault("XLA_PYTHON_CLIENT_PREALLOCATE", "false")  # JAX: leave GPU memory to the plugin and torch

import numpy as np  # noqa: E402

import psc  # noqa: E402

failures = []


def check(name: str, ok: bool, detail: str = "") -> None:
    print(f"{'PASS' if ok else 'FAIL'}  {name}{': ' + detail if detail else ''}")
    if not ok:
        failures.append(name)


def check_torch(env: psc.VectorEnv, cpu: psc.VectorEnv, steps: int) -> None:
    import torch

    address = env.buffers.observations.address
    observations = torch.from_dlpack(env.buffers.observations)
    check(
        "torch.from_dlpack: same device pointer",
        observations.data_ptr() == address,
        f"0x{observations.data_ptr():x} vs 0x{address:x}",
    )
    check("torch.from_dlpack: values equal psc_observe", np.array_equal(observations.cpu().numpy(), env.observe()))
    through_interface = torch.as_tensor(env.buffers.observations, device=observations.device)
    check("torch.as_tensor (__cuda_array_interface__): same device pointer", through_interface.data_ptr() == address)

    env.set_stream(torch.cuda.current_stream().cuda_stream)
    rewards = torch.from_dlpack(env.buffers.rewards)
    rng = np.random.default_rng(0)
    same = True
    for _ in range(steps):
        actions = rng.integers(0, env.single_action_space.n, size=env.num_envs).astype(np.int32)
        device_actions = torch.from_numpy(actions).to(observations.device)
        env.step_device(device_actions)  # the plugin reads device_actions in place
        expected, expected_rewards, *_ = cpu.step(actions)
        # The views taken before stepping show the new state: nothing was copied.
        same &= np.array_equal(observations.cpu().numpy(), expected)
        same &= np.array_equal(rewards.cpu().numpy(), expected_rewards)
    check(f"step_device with torch actions: {steps} steps equal the CPU batch", same)
    check("psc_synchronize reports no invalid action", _synchronizes(env))


def _synchronizes(env: psc.VectorEnv) -> bool:
    try:
        env.synchronize()
        return True
    except psc.PscError as error:
        print(f"      {error}")
        return False


def check_jax(env: psc.VectorEnv) -> None:
    import jax
    import jax.dlpack

    observations = jax.dlpack.from_dlpack(env.buffers.observations)
    pointer = observations.unsafe_buffer_pointer()
    address = env.buffers.observations.address
    check("jax.dlpack.from_dlpack: same device pointer", pointer == address, f"0x{pointer:x} vs 0x{address:x}")
    # JAX arrays are immutable by contract: compare before the plugin writes again.
    check("jax.dlpack.from_dlpack: values equal psc_observe", np.array_equal(np.asarray(observations), env.observe()))


def check_cupy(env: psc.VectorEnv) -> None:
    import cupy

    address = env.buffers.observations.address
    through_dlpack = cupy.from_dlpack(env.buffers.observations)
    through_interface = cupy.asarray(env.buffers.observations)
    check("cupy.from_dlpack: same device pointer", through_dlpack.data.ptr == address)
    check("cupy.asarray (__cuda_array_interface__): same device pointer", through_interface.data.ptr == address)
    check("cupy: values equal psc_observe", np.array_equal(cupy.asnumpy(through_dlpack), env.observe()))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plugin", help="a plugin built with --target all (default: build games/gems.txt)")
    parser.add_argument("--game", default=str(REPO / "games" / "gems.txt"))
    parser.add_argument("--num-envs", type=int, default=1024)
    parser.add_argument("--steps", type=int, default=50)
    args = parser.parse_args()
    plugin = args.plugin or psc.compile(args.game, target="all")

    env = psc.VectorEnv(plugin, args.num_envs, backend="cuda")
    cpu = psc.VectorEnv(plugin, args.num_envs, backend="cpu")
    env.reset(seed=123)
    cpu.reset(seed=123)
    print(f"{env.info.title}: {args.num_envs} environments on CUDA device {env.buffers.device}")
    print(f"observations: {env.buffers.observations}")
    check("buffers are device memory", env.buffers.device >= 0)

    for name, run in (
        ("cupy", lambda: check_cupy(env)),
        ("jax", lambda: check_jax(env)),
        ("torch", lambda: check_torch(env, cpu, args.steps)),
    ):
        try:
            __import__(name)
        except ImportError:
            print(f"SKIP  {name} is not installed")
            continue
        run()

    print(f"{len(failures)} check(s) failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
