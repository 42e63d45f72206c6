"""Text environments: a game's states as text for language-model agents.

TextVectorEnv steps a batch of episodes of one game (one psc batch, for
evaluating many episodes at once); TextEnv is one environment with
Gymnasium's single-environment API.  The text format is in text_state.py.
"""

import json
import os
from pathlib import Path
from typing import Dict, FrozenSet, List, Optional, Sequence, Union

from ..build import compile, emit_ir, ir_path_for, source_path_for
from ..vector_env import VectorEnv
from .game_text import ACTION_NAMES, GameText, make_game_text, parse_action
from .text_state import Symbols, cells_of_record, level_of_entry, parse_text, state_text

DEFAULT_UNDO_DEPTH = 256  # undo entries kept per environment (an episode of the paper's 100 steps fits)


def _is_plugin(path: str) -> bool:
    return os.path.splitext(path)[1] in (".so", ".dylib", ".dll")


def load_game(
    game: str, source: Optional[str], psc_binary: Optional[str], keep_going: bool
) -> tuple:
    """(plugin path, source text, IR) of a game file or of a plugin built by
    psc.compile / `python -m psc build` (which keep the IR and the source beside it)."""
    game = os.fspath(game)
    if _is_plugin(game):
        plugin = game
        ir_file = ir_path_for(plugin)
        source_file = os.fspath(source) if source is not None else source_path_for(plugin)
        for needed, what in ((ir_file, "IR"), (source_file, "source")):
            if not os.path.exists(needed):
                raise FileNotFoundError(
                    f"a text environment needs the game's {what}: {needed} is missing "
                    "(psc.compile and `python3 -m psc build` write it beside the plugin; or pass source=GAME.txt)"
                )
        with open(ir_file) as f:
            ir = json.load(f)
        return plugin, Path(source_file).read_text(encoding="utf-8"), ir
    plugin = compile(game, psc_binary=psc_binary, keep_going=keep_going)
    return plugin, Path(game).read_text(encoding="utf-8"), emit_ir(game, psc_binary, keep_going)


class TextVectorEnv:
    """num_envs episodes of one game, stepped together, observed as text.

    Episode mode (play_through=False, the default): an episode is one level;
    it ends when the level is won (terminated) or after max_steps steps
    (truncated); reset() starts the next episodes.  play_through=True plays as
    the reference engine does (a win goes on to the next entry, message
    screens included; terminated when the game is complete), which is how
    corpus traces are replayed (reset_to_entry).
    """

    def __init__(
        self,
        game: str,
        num_envs: int = 1,
        max_steps: Optional[int] = None,
        undo_depth: int = DEFAULT_UNDO_DEPTH,
        action_set: str = "full",
        play_through: bool = False,
        source: Optional[str] = None,
        psc_binary: Optional[str] = None,
        keep_going: bool = False,
    ):
        plugin, source_text, ir = load_game(game, source, psc_binary, keep_going)
        self.plugin_path = plugin
        self.env = VectorEnv(
            plugin, num_envs=num_envs, undo_depth=undo_depth, autoreset=not play_through, full_action_space=True
        )
        info = self.env.info
        self.info = info
        self.game: GameText = make_game_text(
            source_text, ir, info.flags, info.object_names, action_set, info.title, info.author, info.homepage
        )
        self.source_text = source_text
        self.num_envs = int(num_envs)
        self.max_steps = max_steps
        self.play_through = play_through
        self._base_symbols: Dict[Optional[int], Symbols] = {}  # by level: each episode starts from a copy
        self._symbols = [Symbols(self.game) for _ in range(self.num_envs)]
        self._steps = [0] * self.num_envs
        self._ended = [True] * self.num_envs
        self._texts = [""] * self.num_envs
        self._records: List[dict] = [{} for _ in range(self.num_envs)]

    # --- levels and entries

    @property
    def level_count(self) -> int:
        return self.info.level_count

    def level_of_entry(self, entry: int) -> Optional[int]:
        """The playable level shown at LEVELS entry `entry`, or for a message
        entry the level after it (None after the last level)."""
        return level_of_entry(self.info.level_entries, entry)

    # --- episodes

    def reset(self, seeds: Sequence[int], levels: Union[int, Sequence[int]] = 0):
        """Starts an episode in every environment: environment i plays level
        levels[i] (playable, from 0) with seed seeds[i].  Returns (texts, infos)."""
        if len(seeds) != self.num_envs:
            raise ValueError(f"{self.num_envs} seeds needed, not {len(seeds)}")
        self.env.reset(seed=[int(s) for s in seeds], options={"levels": levels})
        for i in range(self.num_envs):
            self._start_episode(i)
        return list(self._texts), [self._info(i, False) for i in range(self.num_envs)]

    def reset_to_entry(self, i: int, entry: int, seed: str) -> str:
        """Starts environment i at LEVELS entry `entry` (message entries
        counted) with every level load seeded by the string `seed`: the
        corpus harness's start.  Returns its text."""
        self.env.reset_to_entry(i, entry, seed)
        self._start_episode(i)
        return self._texts[i]

    def _start_episode(self, i: int) -> None:
        level = self.level_of_entry(int(self.env.dump_state(i)["level"]))
        if level not in self._base_symbols:
            self._base_symbols[level] = Symbols(self.game, level)
        self._symbols[i] = self._base_symbols[level].copy()
        self._steps[i] = 0
        self._ended[i] = False
        self._refresh(i, level_won=False)

    def step(self, actions: Sequence):
        """One action per environment: a name, letter or psc_action number
        (game_text.parse_action), or None: a turn without a move (an invalid
        reply: the state stays, the turn counts toward max_steps; for an
        environment whose episode has ended: left alone).  Returns (texts,
        rewards, terminated, truncated, infos); each info holds "level",
        "entry", "screen", "level_won", "steps" and "action" (the name
        played, or None)."""
        if len(actions) != self.num_envs:
            raise ValueError(f"{self.num_envs} actions needed, not {len(actions)}")
        numbers = []
        for i, action in enumerate(actions):
            if action is not None and self._ended[i]:
                raise RuntimeError(f"environment {i}: its episode has ended; call reset() first")
            # An environment without a move is stepped with tick and put back (psc steps whole batches).
            numbers.append(ACTION_NAMES.index("tick") if action is None else parse_action(action))
        held = {i: self.env.clone_state(i) for i, a in enumerate(actions) if a is None and not self._ended[i]}
        if any(a is not None for a in actions):
            _, rewards, terminated, _, _ = self.env.step(numbers)
        else:
            rewards, terminated = [0.0] * self.num_envs, [False] * self.num_envs
        for i, state in held.items():
            self.env.restore_state(i, state)
        out_rewards, out_terminated, out_truncated, infos = [], [], [], []
        for i, action in enumerate(actions):
            if self._ended[i]:
                out_rewards.append(0.0)
                out_terminated.append(False)
                out_truncated.append(False)
                infos.append(self._info(i, False))
                continue
            moved = action is not None
            self._steps[i] += 1
            level_won = moved and bool(rewards[i] > 0)
            done = moved and bool(terminated[i])
            cut = not done and self.max_steps is not None and self._steps[i] >= self.max_steps
            self._ended[i] = done or cut
            if moved:
                self._refresh(i, level_won=level_won and not self.play_through)
            out_rewards.append(float(rewards[i]) if moved else 0.0)
            out_terminated.append(done)
            out_truncated.append(cut)
            info = self._info(i, level_won)
            info["action"] = ACTION_NAMES[numbers[i]] if moved else None
            infos.append(info)
        return list(self._texts), out_rewards, out_terminated, out_truncated, infos

    def _refresh(self, i: int, level_won: bool) -> None:
        record = self.env.dump_state(i)
        self._records[i] = record
        self._texts[i] = state_text(record, self._symbols[i], self.game, self.info.level_entries, level_won)

    def _info(self, i: int, level_won: bool) -> dict:
        record = self._records[i]
        entry = int(record["level"])
        return {
            "level": self.level_of_entry(entry),
            "entry": entry,
            "screen": record["screen"],
            "level_won": level_won,
            "steps": self._steps[i],
        }

    # --- inspection

    def text(self, i: int) -> str:
        """Environment i's current text."""
        return self._texts[i]

    def start_won(self, i: int) -> bool:
        """Whether environment i's level was won by its start, before any
        input (a `run_rules_on_level_start` turn's `again` chain): the
        reference engine shows the next entry before the first input."""
        return self.env.start_won(i)

    def record(self, i: int) -> dict:
        """Environment i's current state record (psc_dump_state: the corpus' form)."""
        return self._records[i]

    def ended(self, i: int) -> bool:
        return self._ended[i]

    def close(self) -> None:
        self.env.close()

    def __enter__(self) -> "TextVectorEnv":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class TextEnv:
    """One environment of a game with Gymnasium's single-environment API and
    text observations.

        env = psc.TextEnv("games/sokoban.txt", level=0, seed=0, max_steps=100)
        text, info = env.reset()
        text, reward, terminated, truncated, info = env.step("left")

    game: a game source (.txt) or a plugin built by psc.compile or `python -m
    psc build` (its .ir.json and .source.txt beside it, or source=GAME.txt).
    An episode is one level (level: playable, from 0); it is terminated when
    the level is won and truncated after max_steps steps.  step() takes an
    action name or letter in any case (up, left, down, right, action, undo,
    restart, tick; u l d r x z) or a psc_action number; anything else raises
    ValueError.  Undo needs undo_depth > 0.
    """

    def __init__(
        self,
        game: str,
        level: int = 0,
        seed: Optional[int] = None,
        max_steps: Optional[int] = None,
        undo_depth: int = DEFAULT_UNDO_DEPTH,
        action_set: str = "full",
        play_through: bool = False,
        source: Optional[str] = None,
        psc_binary: Optional[str] = None,
        keep_going: bool = False,
    ):
        self._env = TextVectorEnv(
            game, 1, max_steps, undo_depth, action_set, play_through, source, psc_binary, keep_going
        )
        if not 0 <= int(level) < self._env.level_count:
            raise ValueError(f"level {level} out of range [0, {self._env.level_count})")
        self.level = int(level)
        self.seed = 0 if seed is None else int(seed)
        self.game = self._env.game
        self.info = self._env.info
        self.metadata = {"render_modes": ["ansi"]}
        self.render_mode = "ansi"

    parse = staticmethod(parse_text)
    parse.__doc__ = "Each cell's objects (rows of sets of lower-case names, top row first) from a state's text."

    @property
    def actions(self) -> tuple:
        """The actions offered to agents (names, in psc_action order)."""
        return self.game.actions

    def reset(self, seed: Optional[int] = None, options: Optional[dict] = None):
        """Starts an episode; seed: the level's random seed (default: the
        constructor's); options={"level": n} changes the level.  Returns (text, info)."""
        options = options or {}
        unknown = set(options) - {"level"}
        if unknown:
            raise ValueError(f"unknown reset options {sorted(unknown)} (known: level)")
        if "level" in options:
            level = int(options["level"])
            if not 0 <= level < self._env.level_count:
                raise ValueError(f"level {level} out of range [0, {self._env.level_count})")
            self.level = level
        if seed is not None:
            self.seed = int(seed)
        texts, infos = self._env.reset([self.seed], [self.level])
        return texts[0], infos[0]

    def reset_to_entry(self, entry: int, seed: str):
        """Starts at LEVELS entry `entry` (messages counted) with level loads
        seeded by the string `seed`, as the corpus harness does.  Returns (text, info)."""
        text = self._env.reset_to_entry(0, entry, seed)
        return text, self._env._info(0, False)

    def step(self, action):
        texts, rewards, terminated, truncated, infos = self._env.step([action])
        return texts[0], rewards[0], terminated[0], truncated[0], infos[0]

    def render(self) -> str:
        return self._env.text(0)

    def cells(self) -> List[List[FrozenSet[str]]]:
        """The current state's objects (from the plugin's state record), in parse()'s form."""
        return cells_of_record(self._env.record(0))

    def record(self) -> Dict:
        return self._env.record(0)

    def rules_text(self) -> str:
        """The game's title, author, legend, collision layers, rules and win
        conditions as written (comments stripped): the prompt's description."""
        from .prompt import describe_game

        return describe_game(self.game)

    def close(self) -> None:
        self._env.close()

    def __enter__(self) -> "TextEnv":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
