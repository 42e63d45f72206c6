"""How close an episode got to a win: for each visited state, the solver's
shortest distance (psc solve, breadth-first) from it to a win of the level.

psc solve starts from the level's start and replays inputs (u d l r x) before
searching, so each state is reached by an undo-free input path: InputPath
keeps it through undo and restart.  A path is checked by replaying it and
comparing the state it reaches with the visited one, so a path the model gets
wrong (checkpoints, random games after an undo) gives "unknown", never a
wrong distance.  Distances are cached by state (by path in games that use
random, where the state alone does not fix the future).
"""

import json
import os
import threading
from typing import Callable, Dict, Optional

from ..solve import SolveError, solve
from ..vector_env import VectorEnv
from .game_text import ACTION_IDS, LETTER_OF_ACTION

UNKNOWN = "unknown"


class InputPath:
    """Inputs from the level's start to the current state, undo and restart
    folded in as the engine applies them (a backup before every input that
    changes the level and before every restart; undo drops backups equal to
    the current level and goes back to the newest other one).

    In games that use random every input counts (one that changes nothing may
    still draw random numbers), and after an undo or a restart no path is
    known (they do not rewind the random stream)."""

    def __init__(self, uses_random: bool = False):
        self.inputs: Optional[str] = ""  # None: no undo-free path is known
        self._uses_random = uses_random
        self._backups = []

    def played(self, action: str, changed: bool) -> None:
        if self.inputs is None:
            return
        if action in LETTER_OF_ACTION:
            if changed or self._uses_random:
                self._backups.append(self.inputs)
                self.inputs += LETTER_OF_ACTION[action]
        elif self._uses_random or (action == "tick" and changed):
            # ticks are no input psc solve replays; undo and restart keep the random stream going
            self.inputs = None
        elif action == "restart":
            self._backups.append(self.inputs)
            self.inputs = ""
        elif action == "undo":
            while self._backups and self._backups[-1] == self.inputs:
                self._backups.pop()
            if self._backups:
                self.inputs = self._backups.pop()


def state_key(record: dict) -> str:
    return json.dumps([record["palette"], record["rows"]], separators=(",", ":"))


class Distances:
    """Cached solver distances of one game's states, safe to use from threads.

    solve_level gives the record of `psc solve` from a level's start (the
    optimum); distance(...) the shortest distance from a visited state:
    {"distance": int or None, "status": "solved" | "exhausted" (no win is
    reachable) | "limit" (search stopped) | "unknown" (no checked path)}.
    """

    def __init__(
        self,
        game_path: str,
        plugin_path: str,
        uses_random: bool,
        time_limit: float = 10.0,
        psc_binary: Optional[str] = None,
        solver: Callable[..., dict] = solve,
    ):
        self.game_path = game_path
        self.uses_random = uses_random
        self.time_limit = time_limit
        self.psc_binary = psc_binary
        self._solver = solver
        self._cache: Dict[tuple, dict] = {}
        self._lock = threading.Lock()
        self._replay_lock = threading.Lock()
        # Searches use a core each: at most one per core at a time, whatever the harness's concurrency.
        self._searches = threading.Semaphore(os.cpu_count() or 1)
        self._replayer = VectorEnv(plugin_path, num_envs=1, autoreset=True, full_action_space=True)

    def solve_level(self, level: int, seed: int, inputs: str = "") -> dict:
        key = ("solve", level, seed if self.uses_random else None, inputs)
        with self._lock:
            cached = self._cache.get(key)
        if cached is None:
            try:
                with self._searches:
                    cached = self._solver(
                        self.game_path, level, from_inputs=inputs, seed=seed, time_limit=self.time_limit,
                        psc_binary=self.psc_binary,
                    )
            except SolveError as e:
                cached = {"status": "error", "solution": None, "length": None, "error": str(e)}
            with self._lock:
                self._cache[key] = cached
        return cached

    def distance(self, level: int, seed: int, inputs: Optional[str], record: dict, won: bool) -> dict:
        if won:
            return {"distance": 0, "status": "solved"}
        if inputs is None or record.get("screen") != "level":
            return {"distance": None, "status": UNKNOWN}
        key = ("state", level, seed, inputs) if self.uses_random else ("state", level, state_key(record))
        with self._lock:
            cached = self._cache.get(key)
        if cached is not None:
            return cached
        if not self._reaches(level, seed, inputs, record):
            result = {"distance": None, "status": UNKNOWN}
        else:
            solved = self.solve_level(level, seed, inputs)
            status = solved.get("status", "error")
            result = {"distance": solved.get("length") if status == "solved" else None, "status": status}
        with self._lock:
            self._cache[key] = result
        return result

    def _reaches(self, level: int, seed: int, inputs: str, record: dict) -> bool:
        """Whether playing `inputs` from the level's start reaches `record`'s objects without winning."""
        letters = {letter: name for name, letter in LETTER_OF_ACTION.items()}
        with self._replay_lock:
            env = self._replayer
            env.reset(seed=[seed], options={"levels": [level]})
            for letter in inputs:
                _, _, terminated, _, _ = env.step([ACTION_IDS[letters[letter]]])
                if terminated[0]:
                    return False
            return state_key(env.dump_state(0)) == state_key(record)

    def close(self) -> None:
        self._replayer.close()
