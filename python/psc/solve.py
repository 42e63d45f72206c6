"""Solving levels with `psc solve` (search/Solver.h): psc.solve(game, level)
returns the command's JSON record of that level."""

import json
import subprocess
from typing import Optional

from .build import find_psc_binary

ALGORITHMS = ("bfs", "astar", "wastar", "greedy", "beam", "portfolio")


class SolveError(RuntimeError):
    """psc solve could not run the search (a bad game, level or argument)."""


def solve(
    game: str,
    level: int = 0,
    *,
    algorithm: str = "bfs",
    backend: str = "cpu",
    time_limit: float = 60.0,
    max_states: int = 0,
    max_memory_mb: float = 0,
    threads: int = 1,
    seed: int = 0,
    from_inputs: str = "",
    weight: float = 2.0,
    beam_width: int = 0,
    psc_binary: Optional[str] = None,
) -> dict:
    """Searches playable level `level` of the game file `game` and returns its
    record: level, entry, status ("solved", "exhausted" or "limit"), solution
    (letters u d l r x, or None), length, expanded, generated, unique_states,
    seconds, memory_bytes, algorithm, backend, and limit when one stopped it;
    start_won (solved by the empty solution: the level's start wins it) and
    start_cut_off (exhausted: its start never settles) when true.
    `from_inputs` are played from the level's start first; the solution then
    continues from there."""
    if algorithm not in ALGORITHMS:
        raise ValueError(f"algorithm must be one of {', '.join(ALGORITHMS)}, not {algorithm!r}")
    command = [
        find_psc_binary(psc_binary), "solve", str(game), "--level", str(int(level)), "--algorithm", algorithm,
        "--backend", backend, "--time-limit", repr(float(time_limit)), "--max-states", str(int(max_states)),
        "--max-memory", repr(float(max_memory_mb)), "--threads", str(int(threads)), "--seed", str(int(seed)),
        "--weight", repr(float(weight)), "--beam-width", str(int(beam_width)), "--format", "json", "--quiet",
    ]
    if from_inputs:
        command += ["--from-inputs", from_inputs]
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode not in (0, 1) or not done.stdout.strip():
        raise SolveError(f"psc solve failed (exit {done.returncode}): {done.stderr.strip()}")
    return json.loads(done.stdout.strip().splitlines()[-1])
