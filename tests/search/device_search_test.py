#!/usr/bin/python3
"""Breadth-first and beam search with their states on the GPU
(search/DeviceStateSet.h) against the host's: on every level asked for, the
same status and solution (both stores hold the same states, a layer in the
same order, so the first win is the same), on exhausted levels (and beams
that emptied) the same number of distinct states, and the limits reported as
limits.  (A solved level's counts depend on the batch a backend expands at
once.)  Needs a GPU: run by tools/gpu_check.sh's search stage, not by CI.

Usage: device_search_test.py PSC_BINARY [SECONDS_PER_LEVEL]"""

import json
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PSC = sys.argv[1]
SECONDS = sys.argv[2] if len(sys.argv) > 2 else "20"

# Every level of the test games and the bundled games, and the benchmark
# games' levels that breadth-first finishes on one CPU thread in seconds.
GAMES = sorted((REPO / "tests/search/games").glob("*.txt")) + sorted((REPO / "games").glob("*.txt"))
BENCH_LEVELS = {
    "sokoban": "0,1", "match3": "0,1", "slidings": "0,1,2,3,4,5,6,7,8,9,10", "kettle": "0,1,2,3,4,5,6,7,8,9,10",
    "takeheart": "0,1,2,3,4,5,6,7,8,9,10", "traveling": "0,1,2,3,4,5,6,7,8,9,10", "limerick": "0,4,5,8",
    "constellationz": "0,1,2,3,4,6,7,9", "dictionary": "0", "atlas": "0,1,2,3,5", "blocks": "0",
}
# Levels beam search settles on one CPU thread in seconds, at widths 16 and 1,000.
BEAM_LEVELS = {
    "sokoban": "0,1", "slidings": "0,3,6,9", "kettle": "0,2,4", "takeheart": "0,3,6", "limerick": "0,4,5,8",
    "constellationz": "0,2,4", "atlas": "0,1,2,3,4,5,6,7", "traveling": "0,5", "zenpuzzle": "0,1",
}
failures = []
checks = 0


def check(condition, what):
    global checks
    checks += 1
    if not condition:
        failures.append(what)
        print("FAIL:", what, flush=True)


def solve(game, backend, *args, algorithm="bfs"):
    done = subprocess.run([PSC, "solve", str(game), "--format", "json", "--quiet", "--algorithm", algorithm,
                           "--backend", backend, *args], capture_output=True, text=True)
    return done.returncode, [json.loads(l) for l in done.stdout.splitlines() if l.strip()], done.stderr


def compare(game, levels, beam_width=None):
    args = ["--time-limit", SECONDS] + (["--level", levels] if levels else ["--all-levels"])
    algorithm = "bfs"
    if beam_width:
        args += ["--beam-width", str(beam_width)]
        algorithm = "beam"
    _, cpu, cpu_err = solve(game, "cpu", *args, algorithm=algorithm)
    code, cuda, cuda_err = solve(game, "cuda", *args, algorithm=algorithm)
    check(code in (0, 1) and len(cuda) == len(cpu) and cpu, f"{game.name}: both backends answer ({cpu_err}{cuda_err})")
    for c, g in zip(cpu, cuda):
        where = f"{game.name} level {c['level']}" + (f" beam {beam_width}" if beam_width else "")
        # A beam that emptied settles a level as exhaustion does; the other limits leave it open.
        if any(r["status"] == "limit" and r.get("limit") != "beam" for r in (c, g)):
            print(f"  {where}: a limit (cpu {c.get('limit')}, cuda {g.get('limit')}), not compared")
            continue
        fields = ("status", "solution", "length") if c["status"] == "solved" else ("status", "limit", "expanded", "unique_states")
        for field in fields:
            check(c.get(field) == g.get(field), f"{where}: {field} cpu {c.get(field)!r} cuda {g.get(field)!r}")
        print(f"  {where}: {g['status']} {g.get('length', '')} ({g['unique_states']} states; "
              f"cpu {c['seconds']:.2f} s, cuda {g['seconds']:.2f} s)", flush=True)


for game in GAMES:
    compare(game, None)
for name, levels in BENCH_LEVELS.items():
    compare(REPO / "bench/games" / f"{name}.txt", levels)
# Beams narrow enough to drop states on every level, wide enough to solve some.
for game in GAMES:
    if game.name != "deadline.txt":  # its one expansion outlasts the time limit on the GPU (below)
        compare(game, None, beam_width=4)
for name, levels in BEAM_LEVELS.items():
    for width in (16, 1000):
        compare(REPO / "bench/games" / f"{name}.txt", levels, beam_width=width)

# Limits stop the search and say which.
game = REPO / "bench/games/notsnake.txt"
code, records, err = solve(game, "cuda", "--level", "0", "--max-states", "100000")
check(code == 1 and records and records[0]["status"] == "limit" and records[0]["limit"] == "states",
      f"notsnake --max-states: a states limit ({records} {err})")
code, records, err = solve(game, "cuda", "--level", "0", "--max-memory", "8")
check(code == 1 and records and records[0]["status"] == "limit" and records[0]["limit"] == "memory",
      f"notsnake --max-memory 8 MB: a memory limit ({records} {err})")
# Atlas's large keys: far from its memory limit in 2 s.
code, records, err = solve(REPO / "bench/games/atlas.txt", "cuda", "--level", "9", "--time-limit", "2")
check(code == 1 and records and records[0]["status"] == "limit" and records[0]["limit"] == "time",
      f"atlas level 9 --time-limit 2: a time limit ({records} {err})")

# An expansion on the GPU stops at the search's deadline: deadline.txt's one
# chain of 10,000 again turns takes one GPU thread about 40 s on an H100
# (0.2 s on a CPU core), so a search limited to 2 s must stop inside it, soon
# after 2 s.  (A GPU fast enough to finish the chain would exhaust the level
# instead, and fail here: then the level needs to be larger.)
code, records, err = solve(REPO / "tests/search/games/deadline.txt", "cuda", "--time-limit", "2")
check(code == 1 and records and records[0].get("limit") == "time" and records[0]["seconds"] < 3,
      f"deadline.txt on the GPU at 2 s: stopped inside the chain ({records} {err})")
print(f"  deadline.txt at 2 s: stopped after {records[0]['seconds'] if records else '-'} s", flush=True)

print(f"{checks - len(failures)} of {checks} checks passed")
sys.exit(1 if failures else 0)
