"""One psc_batch: the plugin's environments, with every ABI call checked.

Views of the batch's buffers (dlpack.BufferView) hold a reference to the
Batch, so the plugin memory they point to lives until the last view is gone,
even after VectorEnv.close().
"""

import ctypes
import json
from typing import Optional, Sequence

import numpy as np

from . import _abi
from .plugin import Plugin


def _int32s(values, count: int, what: str) -> np.ndarray:
    array = np.ascontiguousarray(values, dtype=np.int32)
    if array.shape != (count,):
        raise ValueError(f"{what} must have shape ({count},), not {array.shape}")
    return array


class Batch:
    def __init__(
        self,
        plugin: Plugin,
        num_envs: int,
        backend: int,
        threads: int,
        undo_depth: int,
        auto_reset: int,
        max_episode_steps: int,
        device: int = 0,
        again_mode: int = _abi.AGAIN_SETTLE,
    ):
        self.plugin = plugin
        self.lib = plugin.lib
        options = _abi.BatchOptions(
            struct_size=ctypes.sizeof(_abi.BatchOptions),
            backend=backend,
            num_envs=num_envs,
            threads=threads,
            undo_depth=undo_depth,
            auto_reset=auto_reset,
            max_episode_steps=max_episode_steps,
            device=device,
            again_mode=again_mode,
        )
        handle = ctypes.c_void_p()
        plugin.check(self.lib.psc_batch_create(ctypes.byref(options), ctypes.byref(handle)), "creating the batch")
        self.handle = handle
        self.num_envs = num_envs
        self.backend = backend
        self.stream = 0  # the cudaStream_t CUDA work is queued on (0: the default stream)
        info = plugin.info
        self.observation_shape = (num_envs, len(info.object_names), info.max_height, info.max_width)

    def __del__(self):
        # Plugin memory goes when the last user (env or exported view) does.
        if getattr(self, "handle", None):
            self.lib.psc_batch_destroy(self.handle)
            self.handle = None

    def check(self, status: int, doing: str) -> None:
        self.plugin.check(status, doing)

    def reset(self, levels: Sequence[int], seeds: Sequence[int], env_ids: Optional[Sequence[int]] = None) -> None:
        count = self.num_envs if env_ids is None else len(env_ids)
        ids = None if env_ids is None else _int32s(env_ids, count, "env_ids")
        level_array = _int32s(levels, count, "levels")
        seed_array = np.ascontiguousarray(seeds, dtype=np.uint64)
        if seed_array.shape != (count,):
            raise ValueError(f"seeds must have shape ({count},), not {seed_array.shape}")
        status = self.lib.psc_reset(
            self.handle,
            None if ids is None else ids.ctypes.data,
            count,
            level_array.ctypes.data,
            seed_array.ctypes.data,
        )
        self.check(status, "resetting")

    def reset_entry(self, env: int, entry: int, seed: str) -> None:
        self.check(self.lib.psc_reset_entry(self.handle, env, entry, seed.encode("utf-8")), "resetting to an entry")

    def start_cut_off(self, env: int = 0) -> bool:
        """Whether the last reset of environment `env` started a level whose
        start turn ran an `again` chain that never settles (psc cuts it off
        after 10,000 turns; the reference engine never finishes it)."""
        flag = ctypes.c_uint8(0)
        self.check(self.lib.psc_start_cut_off(self.handle, env, ctypes.byref(flag)), "reading the start")
        return bool(flag.value)

    def start_won(self, env: int = 0) -> bool:
        """Whether the last reset of environment `env` started a level that
        its start won before any input (a `run_rules_on_level_start` turn's
        `again` chain satisfied the win conditions)."""
        flag = ctypes.c_uint8(0)
        self.check(self.lib.psc_start_won(self.handle, env, ctypes.byref(flag)), "reading the start")
        return bool(flag.value)

    def step(self, actions) -> np.ndarray:
        """One step with host actions; returns the psc_step_result array (host)."""
        action_array = _int32s(actions, self.num_envs, "actions")
        results = (_abi.StepResult * self.num_envs)()
        self.check(self.lib.psc_step(self.handle, action_array.ctypes.data, results), "stepping")
        return np.ctypeslib.as_array(results)

    def step_many(self, steps: int, actions: int, rewards: int, terminated: int, truncated: int, won: int) -> None:
        """psc_step_many with raw addresses (host or device, as the backend wants)."""
        status = self.lib.psc_step_many(self.handle, steps, actions, rewards, terminated, truncated, won)
        self.check(status, "stepping")

    def step_buffers(self) -> None:
        self.check(self.lib.psc_step_buffers(self.handle), "stepping")

    def observe(self, out: Optional[np.ndarray] = None) -> np.ndarray:
        if out is None:
            out = np.empty(self.observation_shape, dtype=np.uint8)
        self.observe_into(out.ctypes.data, out.nbytes)
        return out

    def observe_into(self, address: int, size: int) -> None:
        self.check(self.lib.psc_observe(self.handle, address, size), "observing")

    def buffers(self) -> _abi.Buffers:
        buffers = _abi.Buffers()
        self.check(self.lib.psc_get_buffers(self.handle, ctypes.byref(buffers)), "getting the buffers")
        return buffers

    def set_stream(self, stream: int) -> None:
        self.check(self.lib.psc_set_stream(self.handle, stream or None), "setting the stream")
        self.stream = stream

    def synchronize(self) -> None:
        self.check(self.lib.psc_synchronize(self.handle), "synchronizing")

    def rollout(self, steps: int, seed: int) -> _abi.RolloutStats:
        stats = _abi.RolloutStats()
        self.check(self.lib.psc_rollout(self.handle, steps, seed, ctypes.byref(stats)), "running the rollout")
        return stats

    def save_state(self, env: int) -> bytes:
        size = self.lib.psc_state_size(self.handle)
        buffer = ctypes.create_string_buffer(size)
        self.check(self.lib.psc_save_state(self.handle, env, buffer, size), f"saving environment {env}")
        return buffer.raw

    def load_state(self, env: int, state: bytes) -> None:
        if not isinstance(state, (bytes, bytearray)):
            raise TypeError(f"a saved state is bytes (from clone_state), not {type(state).__name__}")
        buffer = ctypes.create_string_buffer(bytes(state), len(state))
        self.check(self.lib.psc_load_state(self.handle, env, buffer, len(state)), f"restoring environment {env}")

    def dump_state(self, env: int) -> dict:
        needed = ctypes.c_size_t(0)
        status = self.lib.psc_dump_state(self.handle, env, None, 0, ctypes.byref(needed))
        if status != _abi.ERROR_BUFFER_TOO_SMALL:  # the expected answer to the size query
            self.check(status, f"dumping environment {env}")
        buffer = ctypes.create_string_buffer(needed.value)
        self.check(
            self.lib.psc_dump_state(self.handle, env, buffer, needed.value, ctypes.byref(needed)),
            f"dumping environment {env}",
        )
        return json.loads(buffer.value.decode("utf-8"))

    # ---- state keys and batched expansion (psc_plugin.h; docs/search.md)

    def key_bytes(self) -> int:
        return self.plugin.info.state_key_bytes

    def encode_states(self, env_ids: Sequence[int]):
        """(keys uint8 [n, key_bytes], hashes uint64 [n]) of environments env_ids."""
        ids = _int32s(env_ids, len(env_ids), "env_ids")
        keys = np.zeros((len(ids), self.key_bytes()), dtype=np.uint8)
        hashes = np.zeros(len(ids), dtype=np.uint64)
        status = self.lib.psc_encode_states(self.handle, ids.ctypes.data, len(ids), keys.ctypes.data, hashes.ctypes.data)
        self.check(status, "encoding states")
        return keys, hashes

    def canonical_keys(self, keys: np.ndarray):
        """(keys [n, key_bytes] in search's form, the form of expand's children;
        their hashes uint64 [n]): objects nothing but their creation tells
        apart have their cells on one of them (psc_canonical_keys)."""
        keys = np.array(keys, dtype=np.uint8, order="C", copy=True)
        if keys.ndim != 2 or keys.shape[1] != self.key_bytes():
            raise ValueError(f"keys must have shape (n, {self.key_bytes()}), not {keys.shape}")
        hashes = np.zeros(len(keys), dtype=np.uint64)
        self.check(self.lib.psc_canonical_keys(self.handle, keys.ctypes.data, len(keys), hashes.ctypes.data), "folding keys")
        return keys, hashes

    def decode_state(self, env: int, key: np.ndarray) -> None:
        key = np.ascontiguousarray(key, dtype=np.uint8)
        if key.shape != (self.key_bytes(),):
            raise ValueError(f"a state key has shape ({self.key_bytes()},), not {key.shape}")
        self.check(self.lib.psc_decode_state(self.handle, env, key.ctypes.data), f"decoding a key into environment {env}")

    def expand(self, template_env: int, keys: np.ndarray, actions: Sequence[int]):
        """Children of host keys [n, key_bytes] under each action (CPU batches):
        (children [n * len(actions), key_bytes], flags, hashes, estimates)."""
        keys = np.ascontiguousarray(keys, dtype=np.uint8)
        if keys.ndim != 2 or keys.shape[1] != self.key_bytes():
            raise ValueError(f"keys must have shape (n, {self.key_bytes()}), not {keys.shape}")
        action_array = _int32s(actions, len(actions), "actions")
        n = keys.shape[0] * len(action_array)
        children = np.zeros((n, self.key_bytes()), dtype=np.uint8)
        flags = np.zeros(n, dtype=np.uint8)
        hashes = np.zeros(n, dtype=np.uint64)
        estimates = np.zeros(n, dtype=np.int32)
        status = self.lib.psc_expand(
            self.handle, template_env, keys.ctypes.data, keys.shape[0], action_array.ctypes.data, len(action_array),
            children.ctypes.data, flags.ctypes.data, hashes.ctypes.data, estimates.ctypes.data)
        self.check(status, "expanding states")
        return children, flags, hashes, estimates

    def set_deadline(self, seconds: float) -> None:
        """psc_expand on this batch stops `seconds` from now (0: never),
        flagging the children it did not finish PSC_EXPAND_TIMED_OUT (on a
        CUDA batch, the GPU's expansion too, which `expand` here does not run)."""
        self.check(self.lib.psc_set_deadline(self.handle, float(seconds)), "setting the expansion deadline")

    def estimate_distance(self, template_env: int, keys: np.ndarray) -> np.ndarray:
        keys = np.ascontiguousarray(keys, dtype=np.uint8)
        out = np.zeros(keys.shape[0], dtype=np.int32)
        self.check(self.lib.psc_estimate_distance(self.handle, template_env, keys.ctypes.data, keys.shape[0], out.ctypes.data),
                   "estimating distances")
        return out
