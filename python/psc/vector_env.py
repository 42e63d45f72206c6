"""VectorEnv: a batch of one game's environments with Gymnasium's vector API."""

import json
import os
from dataclasses import dataclass
from typing import Optional, Sequence, Union

import numpy as np

from . import _abi
from .batch import Batch
from .build import compile, emit_ir, ir_path_for
from .dlpack import BufferView, array_address
from .plugin import Plugin
from .render import render_planes
from .shaped_reward import WinDistance
from .spaces import Box, Discrete, MultiDiscrete

# The values of gymnasium.vector.AutoresetMode (compare with `.value` there).
AUTORESET_NEXT_STEP = "NextStep"
AUTORESET_DISABLED = "Disabled"

BACKENDS = {"cpu": _abi.BACKEND_CPU, "cuda": _abi.BACKEND_CUDA}
REWARDS = ("win", "shaped")


@dataclass(frozen=True)
class EnvState:
    """One environment saved by VectorEnv.clone_state: the plugin's bytes
    (level, undo history, random state, episode step count) plus what the
    VectorEnv tracks itself."""

    data: bytes
    level: int
    episode_return: float
    needs_reset: bool


@dataclass(frozen=True)
class Buffers:
    """The batch's own buffers as zero-copy views (dlpack.BufferView)."""

    device: int  # -1: host memory, else the CUDA device ordinal
    actions: BufferView  # int32 (num_envs,)
    observations: BufferView  # uint8 (num_envs, channels, max_height, max_width)
    rewards: BufferView  # float32 (num_envs,)
    terminated: BufferView  # uint8 (num_envs,)
    truncated: BufferView  # uint8 (num_envs,)
    won: BufferView  # uint8 (num_envs,)
    episode_steps: BufferView  # int32 (num_envs,)


def cuda_ordinal(device) -> int:
    """The CUDA ordinal of 3, "cuda:3", "cuda" (0) or torch.device("cuda", 3)."""
    if isinstance(device, (int, np.integer)) and not isinstance(device, bool):
        ordinal = int(device)
    elif isinstance(device, str) and (device == "cuda" or device.startswith("cuda:")):
        ordinal = int(device[5:]) if device[5:].isdigit() else (0 if device == "cuda" else -1)
    elif getattr(device, "type", None) == "cuda":  # torch.device
        ordinal = 0 if device.index is None else int(device.index)
    else:
        raise ValueError(f'device must be a CUDA ordinal, "cuda:N" or a torch.device, not {device!r}')
    if ordinal < 0:
        raise ValueError(f"device must be a CUDA ordinal (0, 1, ...), not {device!r}")
    return ordinal


def _is_plugin(path: str) -> bool:
    return os.path.splitext(path)[1] in (".so", ".dylib", ".dll")


class VectorEnv:
    """num_envs environments of one PuzzleScript game, stepped together.

    game: a game source (.txt, compiled with psc.compile) or a plugin built
    before (.so; built with --target all for backend="cuda").
    levels: one playable level (numbered from 0, messages not counted) for
    every environment, or one per environment; None: the first level built.
    autoreset: True: the plugin's next-step auto-reset (metadata
    ["autoreset_mode"] == "NextStep"): the step that wins or truncates returns
    the final observation; the next step restarts that environment's level
    (ignoring its action) and returns the start with reward 0.  False: play on
    as the reference engine does (next level, messages), terminated when the
    game is completed.
    max_episode_steps: steps after which an episode is truncated (autoreset only).
    reward: "win" (1 per level won) or "shaped" (shaped_reward.py).
    full_action_space: the action space holds all 8 plugin actions (undo,
    restart, tick too) instead of the directions and action.  step() accepts
    all 8 either way; undo needs undo_depth > 0.
    device: the CUDA device of a backend="cuda" batch: an ordinal, "cuda:N"
    or a torch.device (under torchrun: the rank's LOCAL_RANK).  Every call
    gives the caller's current CUDA context back, so one process may drive
    batches on several devices next to PyTorch's own.
    """

    def __init__(
        self,
        game: str,
        num_envs: int = 1,
        backend: str = "cpu",
        levels: Union[None, int, Sequence[int]] = None,
        seed: Optional[int] = None,
        max_episode_steps: Optional[int] = None,
        threads: int = 0,
        undo_depth: int = 0,
        reward: str = "win",
        autoreset: bool = True,
        full_action_space: bool = False,
        device: Union[int, str, object] = 0,
        psc_binary: Optional[str] = None,
    ):
        if backend not in BACKENDS:
            raise ValueError(f"backend must be one of {tuple(BACKENDS)}, not {backend!r}")
        if reward not in REWARDS:
            raise ValueError(f"reward must be one of {REWARDS}, not {reward!r}")
        if max_episode_steps and not autoreset:
            raise ValueError("max_episode_steps needs autoreset=True (the plugin truncates only auto-reset episodes)")
        game = os.fspath(game)
        if _is_plugin(game):
            self.plugin_path = game
        else:
            self.plugin_path = compile(game, target="cpu" if backend == "cpu" else "all", psc_binary=psc_binary)
        self.plugin = Plugin(self.plugin_path)
        self.info = self.plugin.info
        if not self.info.has_backend(BACKENDS[backend]):
            raise ValueError(f"{self.plugin_path} has no {backend} backend (build it with psc --target all)")
        self.num_envs = int(num_envs)
        self.backend = backend
        self.metadata = {
            "autoreset_mode": AUTORESET_NEXT_STEP if autoreset else AUTORESET_DISABLED,
            "render_modes": ["rgb_array"],
        }
        self.render_mode = "rgb_array"
        self.spec = None
        self.closed = False
        self._batch = Batch(
            self.plugin,
            self.num_envs,
            BACKENDS[backend],
            threads,
            undo_depth,
            _abi.AUTO_RESET_NEXT_STEP if autoreset else _abi.AUTO_RESET_OFF,
            max_episode_steps or 0,
            cuda_ordinal(device),
        )
        self.buffers = self._make_buffers()
        self._win_distance = self._make_win_distance(game, psc_binary) if reward == "shaped" else None

        channels, height, width = len(self.info.object_names), self.info.max_height, self.info.max_width
        if full_action_space:
            actions = _abi.ACTION_COUNT
        else:
            actions = _abi.ACTION_ACTION if self.info.noaction else _abi.ACTION_ACTION + 1
        self.single_observation_space = Box(0, 1, (channels, height, width), np.uint8, seed=seed)
        self.single_action_space = Discrete(actions, seed=seed)
        self.observation_space = Box(0, 1, (self.num_envs, channels, height, width), np.uint8, seed=seed)
        self.action_space = MultiDiscrete([actions] * self.num_envs, seed=seed)

        self.np_random = np.random.default_rng(seed)
        self._levels = self._level_list(self.plugin.playable_levels()[0] if levels is None else levels)
        self._episode_returns = np.zeros(self.num_envs, dtype=np.float64)
        self._needs_reset = np.zeros(self.num_envs, dtype=bool)
        self._distance = np.zeros(self.num_envs, dtype=np.float32)
        self._ready = False  # reset() has run since the last step_device()
        self._device_actions = None  # the last step_device() actions, alive while the plugin reads them

    # --- construction helpers

    def _make_buffers(self) -> Buffers:
        raw = self._batch.buffers()
        n = self.num_envs

        def view(address, shape, dtype):
            return BufferView(self._batch, address, shape, dtype, raw.device)

        return Buffers(
            device=raw.device,
            actions=view(raw.actions, (n,), np.int32),
            observations=view(raw.observations, self._batch.observation_shape, np.uint8),
            rewards=view(raw.rewards, (n,), np.float32),
            terminated=view(raw.terminated, (n,), np.uint8),
            truncated=view(raw.truncated, (n,), np.uint8),
            won=view(raw.won, (n,), np.uint8),
            episode_steps=view(raw.episode_steps, (n,), np.int32),
        )

    def _make_win_distance(self, game: str, psc_binary: Optional[str]) -> WinDistance:
        if _is_plugin(game):
            ir_path = ir_path_for(game)
            if not os.path.exists(ir_path):
                raise FileNotFoundError(
                    f'reward="shaped" needs the game\'s win conditions: {ir_path} is missing '
                    "(psc.compile and `python3 -m psc build` write it beside the plugin)"
                )
            with open(ir_path) as f:
                ir = json.load(f)
        else:
            ir = emit_ir(game, psc_binary)
        return WinDistance(ir["win_conditions"], self.info.object_names, self.info.max_width, self.info.max_height)

    def _level_list(self, levels) -> np.ndarray:
        array = np.array(levels, dtype=np.int64)
        if array.ndim == 0:
            array = np.full(self.num_envs, int(array))
        if array.shape != (self.num_envs,):
            raise ValueError(f"levels must be one level or {self.num_envs} levels, not shape {array.shape}")
        return array.astype(np.int32)

    # --- Gymnasium's vector API

    @property
    def unwrapped(self) -> "VectorEnv":
        return self

    @property
    def object_names(self):
        """Observation channel names, in channel order."""
        return self.info.object_names

    @property
    def levels(self) -> np.ndarray:
        """Each environment's level (a copy)."""
        return self._levels.copy()

    def level_size(self, i: int) -> tuple:
        """(width, height) of environment i's level: the top-left part of its planes that the level fills."""
        return self.info.level_sizes[int(self._levels[i])]

    def reset(self, seed: Union[None, int, Sequence[int]] = None, options: Optional[dict] = None):
        """Restarts every environment.  seed: an int (environment i gets
        seed + i, and the action spaces and later seeds follow it), one seed
        per environment, or None (drawn from np_random).  options={"levels":
        one level or one per environment} changes levels from now on.
        Returns (observations, info)."""
        self._check_open()
        options = options or {}
        unknown = set(options) - {"levels"}
        if unknown:
            raise ValueError(f"unknown reset options {sorted(unknown)} (known: levels)")
        if "levels" in options:
            levels = self._level_list(options["levels"])
        else:
            levels = self._levels
        if seed is None:
            seeds = self.np_random.integers(0, 2**63, size=self.num_envs, dtype=np.uint64)
        elif np.ndim(seed) == 0:
            self.np_random = np.random.default_rng(int(seed))
            self.single_action_space.seed(int(seed))
            self.action_space.seed(int(seed))
            seeds = np.arange(self.num_envs, dtype=np.uint64) + np.uint64(int(seed))
        else:
            seeds = np.asarray(seed, dtype=np.uint64)
        self._batch.reset(levels, seeds)
        self._levels = levels
        observations = self._observe_host()
        self._episode_returns[:] = 0
        self._needs_reset[:] = False
        if self._win_distance is not None:
            self._distance = self._win_distance(observations)
        self._ready = True
        return observations, {}

    def step(self, actions):
        """One action per environment (host array-like of ints).  Returns
        (observations, rewards, terminated, truncated, info) as numpy arrays;
        info["episode"] = {"r", "l", "_r", "_l"} and info["_episode"] mark
        the environments whose episode ended in this step (returns and lengths
        of the finished episodes), as Gymnasium's RecordEpisodeStatistics."""
        self._check_open()
        if not self._ready:
            raise RuntimeError("call reset() before step() (and after step_device())")
        actions = np.asarray(actions)
        if actions.shape != (self.num_envs,):
            raise ValueError(f"actions must have shape ({self.num_envs},), not {actions.shape}")
        if not np.issubdtype(actions.dtype, np.integer):
            raise ValueError(f"actions must be integers, not {actions.dtype}")
        observations, rewards, terminated, truncated, episode_steps = self._step_host(actions.astype(np.int32))
        restarted = self._needs_reset  # these environments were restarted by this step
        if self._win_distance is not None:
            distance = self._win_distance(observations)
            rewards = np.where(restarted, 0.0, self._distance - distance + rewards).astype(np.float32)
            self._distance = distance
        self._episode_returns[restarted] = 0
        self._episode_returns += rewards
        done = terminated | truncated
        info = {}
        if done.any():
            info["episode"] = {
                "r": np.where(done, self._episode_returns, 0.0),
                "l": np.where(done, episode_steps, 0),
                "_r": done.copy(),
                "_l": done.copy(),
            }
            info["_episode"] = done.copy()
        self._needs_reset = done if self.metadata["autoreset_mode"] == AUTORESET_NEXT_STEP else np.zeros_like(done)
        return observations, rewards, terminated, truncated, info

    def _step_host(self, actions: np.ndarray):
        if self.buffers.device < 0:
            # CPU: step in the batch's own buffers, so env.buffers stays current.
            self.buffers.actions.numpy()[:] = actions
            self._batch.step_buffers()
            b = self.buffers
            return (
                b.observations.numpy().copy(),
                b.rewards.numpy().copy(),
                b.terminated.numpy().astype(bool),
                b.truncated.numpy().astype(bool),
                b.episode_steps.numpy().copy(),
            )
        results = self._batch.step(actions)
        return (
            self._observe_host(),
            results["reward"].astype(np.float32),
            results["terminated"].astype(bool),
            results["truncated"].astype(bool),
            results["episode_steps"].astype(np.int32),
        )

    def observe(self) -> np.ndarray:
        """The current observations (host copy), e.g. after restore_state."""
        self._check_open()
        return self._observe_host()

    def _observe_host(self) -> np.ndarray:
        if self.buffers.device < 0:
            # Refresh the batch's buffer too (psc_reset and psc_load_state do not write it).
            self._batch.observe_into(self.buffers.observations.address, self.buffers.observations.nbytes)
            return self.buffers.observations.numpy().copy()
        return self._batch.observe()

    # --- zero-copy stepping

    def step_device(self, actions=None):
        """One step without host copies.  actions: an int32 array of shape
        (num_envs,) on the batch's device (CUDA tensors of torch, JAX or CuPy,
        through DLPack or __cuda_array_interface__; numpy or CPU tensors for
        CPU batches), read by the plugin in place; None: step with what was
        written into buffers.actions.  CUDA work is queued on the batch's
        stream (set_stream).  Returns the views (observations, rewards,
        terminated, truncated) of env.buffers.  Rewards are the plugin's win
        rewards and no episode statistics are kept: call reset() before going
        back to step()."""
        self._check_open()
        if self._win_distance is not None:
            raise ValueError('step_device gives the plugin\'s win rewards only; reward="shaped" needs step()')
        b = self.buffers
        if actions is None:
            self._batch.step_buffers()
            self._device_actions = None
        else:
            address = array_address(actions, (self.num_envs,), np.int32, b.device, self._batch.stream)
            self._batch.step_many(
                1, address, b.rewards.address, b.terminated.address, b.truncated.address, b.won.address
            )
            self._device_actions = actions
        self._ready = False
        return b.observations, b.rewards, b.terminated, b.truncated

    def set_stream(self, stream: int) -> None:
        """CUDA batches: queue their work on this cudaStream_t (an int handle,
        e.g. torch.cuda.current_stream().cuda_stream; 0: the default stream)."""
        self._check_open()
        self._batch.set_stream(int(stream))

    def synchronize(self) -> None:
        """Waits for queued CUDA work; raises if device actions were invalid."""
        self._check_open()
        self._batch.synchronize()

    def random_rollout(self, steps: int, seed: int) -> dict:
        """The plugin's fused random play (psc_rollout): `steps` steps of every
        environment with uniformly random actions (directions, plus action
        unless noaction), auto-resetting, without observations: the fastest
        way through the game, for throughput.  Returns the counts "steps",
        "wins" and "episodes".  Call reset() before going back to step()."""
        self._check_open()
        stats = self._batch.rollout(steps, seed)
        self._ready = False
        return {"steps": stats.steps, "wins": stats.wins, "episodes": stats.episodes}

    # --- search and inspection

    def clone_state(self, i: int) -> EnvState:
        """Environment i's complete state, for restore_state (into any
        environment of a batch of this plugin with the same undo_depth)."""
        self._check_open()
        i = self._env_index(i)
        return EnvState(
            data=self._batch.save_state(i),
            level=int(self._levels[i]),
            episode_return=float(self._episode_returns[i]),
            needs_reset=bool(self._needs_reset[i]),
        )

    def restore_state(self, i: int, state: EnvState) -> None:
        """Puts environment i back into a state from clone_state."""
        self._check_open()
        i = self._env_index(i)
        if not isinstance(state, EnvState):
            raise TypeError(f"restore_state takes an EnvState from clone_state, not {type(state).__name__}")
        self._batch.load_state(i, state.data)
        self._levels[i] = state.level
        self._episode_returns[i] = state.episode_return
        self._needs_reset[i] = state.needs_reset
        if self._win_distance is not None:
            self._distance[i] = self._win_distance(self._observe_host()[i : i + 1])[0]

    def dump_state(self, i: int) -> dict:
        """Environment i's canonical state record (the corpus' JSON form: level,
        screen, message, won, width, height, palette, rows)."""
        self._check_open()
        return self._batch.dump_state(self._env_index(i))

    def reset_to_entry(self, i: int, entry: int, seed: str) -> None:
        """Starts environment i at LEVELS entry `entry` (message entries
        counted) with every level load seeded by the string `seed`: the
        corpus harness's start, for exact replays (use autoreset=False)."""
        self._check_open()
        self._batch.reset_entry(self._env_index(i), entry, seed)
        self._ready = True

    def start_cut_off(self, i: int) -> bool:
        """Whether environment i's last reset started a level whose start
        turn runs an `again` chain that never settles (psc cuts it off after
        10,000 turns; the reference engine never finishes that start, so it
        never takes an input there)."""
        self._check_open()
        return self._batch.start_cut_off(self._env_index(i))

    def start_won(self, i: int) -> bool:
        """Whether environment i's last reset started a level that its start
        won before any input: a `run_rules_on_level_start` turn queued an
        `again` chain that satisfied the win conditions.  The reference
        engine shows the next entry before the first input; with autoreset
        the environment shows the won level, as after a winning step."""
        self._check_open()
        return self._batch.start_won(self._env_index(i))

    def render(self, i: int = 0, scale: int = 1) -> np.ndarray:
        """Environment i's level as RGB, uint8 (height*5*scale, width*5*scale, 3)."""
        self._check_open()
        i = self._env_index(i)
        state = self._batch.dump_state(i)  # the size of the level buffer actually shown
        planes = self._observe_host()[i]
        return render_planes(self.info, planes, state["width"], state["height"], scale)

    def close(self) -> None:
        """Releases the environments.  Views exported from env.buffers keep
        the plugin memory alive until they are gone."""
        if not self.closed:
            self.closed = True
            self._batch = None
            self._device_actions = None

    def __enter__(self) -> "VectorEnv":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _check_open(self) -> None:
        if self.closed:
            raise RuntimeError("the environment is closed")

    def _env_index(self, i: int) -> int:
        i = int(i)
        if not 0 <= i < self.num_envs:
            raise IndexError(f"environment {i} out of range [0, {self.num_envs})")
        return i

    def __repr__(self) -> str:
        return f"VectorEnv({self.info.title!r}, num_envs={self.num_envs}, backend={self.backend!r})"
