#!/usr/bin/python3
"""Proves psc solve's solutions in the original PuzzleScript engine: each
solved record (bench/solve_report.py's JSON lines: game, entry, seed,
solution) is recorded with ../shared/tools/refgen from the level's entry with
the same seed, and must stay on that level until its last input, which wins it
(the engine moves on to another entry, a message or the title screen).  An
empty solution says the level's start wins it (`run_rules_on_level_start` with
an `again` chain): the engine must have left the level before any input.

  tools/verify_solutions.py --engine PUZZLESCRIPT_SRC R.jsonl [--game-dir bench/games] [--jobs 2]

The engine is a copy of increpare/PuzzleScript's src/ (refgen's README says
how to get one); it is never part of psc.  Prints one line per failure and a
closing `N passed, M failed`; exits 1 on any failure."""

import argparse
import concurrent.futures
import json
import os
import subprocess
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NAMES = {"u": "up", "l": "left", "d": "down", "r": "right", "x": "action"}


def verify(refgen, engine, game_path, record):
    inputs = ",".join(NAMES[c] for c in record["solution"])
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "case.json")
        done = subprocess.run(["node", os.path.join(refgen, "record.js"), "--engine", engine, "--game", game_path,
                               "--level", str(record["entry"]), "--seed", str(record.get("seed", 0)), "--inputs", inputs,
                               "--time-limit-ms", "120000", "--out", out], capture_output=True, text=True)
        if done.returncode != 0:
            return f"the engine failed: {done.stderr.strip()[-300:]}"
        case = json.load(open(out))
    start = record["entry"]
    def on_level(state):
        return state["level"] == start and state["screen"] == "level"
    if not record["solution"]:
        return "the engine's start does not win the level" if on_level(case["initial"]) else None
    if not on_level(case["initial"]):
        return "the engine did not start on the level"
    steps = case["steps"]
    for i, state in enumerate(steps[:-1]):
        if not on_level(state):
            return f"the level ended after input {i + 1} of {len(steps)}"
    if on_level(steps[-1]):
        return "the last input does not win the level"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--engine", required=True, help="the PuzzleScript engine's src/ folder")
    ap.add_argument("--refgen", default=os.path.join(REPO, "..", "shared", "tools", "refgen"))
    ap.add_argument("--game-dir", default=os.path.join(REPO, "bench", "games"))
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    ap.add_argument("results", nargs="+")
    a = ap.parse_args()
    records = []
    for path in a.results:
        with open(path) as f:
            records += [json.loads(line) for line in f if line.strip()]
    solved = [r for r in records if r["status"] == "solved"]
    failed = 0
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        futures = {pool.submit(verify, a.refgen, a.engine, os.path.join(a.game_dir, r["game"] + ".txt"), r): r for r in solved}
        for future in concurrent.futures.as_completed(futures):
            r = futures[future]
            problem = future.result()
            if problem:
                failed += 1
                print(f"FAIL {r['game']} level {r['level']} ({r['solution']}): {problem}", flush=True)
    print(f"{len(solved) - failed} passed, {failed} failed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
