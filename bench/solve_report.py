#!/usr/bin/python3
"""psc solve over every level of the benchmark games (bench/games, made by
bench/extract_games.py), and the tables of docs/search.md.

  bench/solve_report.py run --backend cpu --threads 2 --time-limit 30 --out R.jsonl [--algorithm A] [--games a,b] [--jobs N] [--per-level]
  bench/solve_report.py table R.jsonl [R2.jsonl ...]     per-game table, one column group per file
  bench/solve_report.py levels R.jsonl [R2.jsonl ...]    per-level table
  bench/solve_report.py searches GAME.LN.json ...         one row per long search (psc solve --format json of
                                                          one level, named after its game and level)

`run` writes one JSON record per level (psc solve's, plus "game", "seed" and
"time_limit") and prints progress; the records are what tools/verify_solutions.py
checks in the original engine.  With --jobs N, N games are searched at once
(their seconds then include the sharing).  With --per-level, each level is
searched by its own psc solve --level N, whose plugin is built for that level
alone: a game's environments are as large as the largest level built, so a
small level of a game with a huge one expands faster on its own."""

import argparse
import concurrent.futures
import json
import os
import subprocess
import sys

GAMES = ["sokoban", "match3", "limerick", "blocks", "slidings", "notsnake", "traveling", "zenpuzzle", "dictionary",
         "takeheart", "kettle", "constellationz", "atlas"]
# The PuzzleJAX paper's breadth-first search: levels solved within 1 M steps or one minute (of its 72).
PAPER = {"sokoban": "2/2", "match3": "2/2", "limerick": "4/10", "blocks": "1/1", "slidings": "11/11", "notsnake": "0/1",
         "traveling": "11/11", "zenpuzzle": "0/5", "dictionary": "1/1", "takeheart": "11/12", "kettle": "11/11",
         "constellationz": "5/5", "atlas": "-"}


def search(a, path, levels, time_limit=None):
    command = [a.psc, "solve", path, *levels, "--format", "json", "--quiet", "--backend", a.backend,
               "--threads", str(a.threads), "--time-limit", str(time_limit or a.time_limit), "--algorithm", a.algorithm]
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode == 2:
        return None, done.stderr.strip()[-500:]
    return [json.loads(line) for line in done.stdout.splitlines() if line.strip()], ""


def solve_game(a, game):
    path = os.path.join(a.game_dir, game + ".txt")
    if not a.per_level:
        records, error = search(a, path, ["--all-levels"])
        return game, records, error
    # The levels counted by a search that stops at once.
    records, error = search(a, path, ["--all-levels", "--max-states", "1"], time_limit=0.001)
    if records is None:
        return game, None, error
    by_level = []
    for level in range(len(records)):
        mine, error = search(a, path, ["--level", str(level)])
        if mine is None:
            return game, None, error
        by_level += mine
    return game, by_level, ""


def run(a):
    games = a.games.split(",") if a.games else GAMES
    by_game = {}
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        futures = [pool.submit(solve_game, a, g) for g in games]
        for future in concurrent.futures.as_completed(futures):
            game, records, error = future.result()
            if records is None:
                print(f"{game}: error: {error}", file=sys.stderr)
                continue
            for r in records:
                r.update(game=game, seed=0, time_limit=a.time_limit)
            by_game[game] = records
            solved = sum(r["status"] == "solved" for r in records)
            print(f"{game}: {solved}/{len(records)} solved, {sum(r['seconds'] for r in records):.1f} s", flush=True)
            # Rewritten as each game ends: a run cut short keeps the games it finished.
            with open(a.out, "w") as out:
                for g in games:
                    for r in by_game.get(g, []):
                        out.write(json.dumps(r) + "\n")


def load(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def rate(records):
    seconds = sum(r["seconds"] for r in records)
    return sum(r["generated"] for r in records) / seconds if seconds else 0


def table(a):
    runs = [(p, load(p)) for p in a.files]
    head = "| game | levels |" + "".join(f" {os.path.basename(p)}: solved | ≤ 10 s | children/s |" for p, _ in runs) + \
        " PuzzleJAX BFS (paper) |"
    print(head)
    print("|---|---:|" + "---:|---:|---:|" * len(runs) + "---:|")
    totals = [[0, 0] for _ in runs]
    levels_total = 0
    for game in GAMES:
        row = f"| {game} |"
        count = None
        for k, (_, records) in enumerate(runs):
            mine = [r for r in records if r["game"] == game]
            if not mine:
                row += " - | - | - |"
                continue
            count = len(mine) if count is None else count
            solved = [r for r in mine if r["status"] == "solved"]
            fast = [r for r in solved if r["seconds"] <= 10]
            totals[k][0] += len(solved)
            totals[k][1] += len(fast)
            row += f" {len(solved)} | {len(fast)} | {rate(mine):,.0f} |"
        levels_total += count or 0
        print(row.replace(f"| {game} |", f"| {game} | {count} |", 1) + f" {PAPER[game]} |")
    print(f"| **all** | {levels_total} |" + "".join(f" **{s}** | **{f}** | {rate(r):,.0f} |" for (s, f), (_, r) in zip(totals, runs))
          + " 59/72 |")


def levels(a):
    runs = [(p, {(r["game"], r["level"]): r for r in load(p)}) for p in a.files]
    print("| game | level |" + "".join(f" {os.path.basename(p)}: status | length | expanded | seconds |" for p, _ in runs))
    print("|---|---:|" + "---|---:|---:|---:|" * len(runs))
    keys = sorted({k for _, rs in runs for k in rs}, key=lambda k: (GAMES.index(k[0]), k[1]))
    for key in keys:
        row = f"| {key[0]} | {key[1]} |"
        for _, rs in runs:
            r = rs.get(key)
            if not r:
                row += " - | | | |"
                continue
            status = r["status"] if r["status"] != "limit" else f"limit ({r.get('limit')})"
            row += f" {status} | {r['length'] if r['length'] is not None else ''} | {r['expanded']:,} | {r['seconds']:.2f} |"
        print(row)


def searches(a):
    print("| game | level | status | states stored | children generated | seconds | children/s | memory (GB) | length |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|")
    for path in a.files:
        with open(path) as f:
            r = json.loads(f.readline())
        game = os.path.basename(path).split(".")[0]
        status = r["status"] if r["status"] != "limit" else f"limit ({r.get('limit')})"
        print(f"| {game} | {r['level']} | {status} | {r['unique_states']:,} | {r['generated']:,} | {r['seconds']:.2f} | "
              f"{r['generated'] / r['seconds']:,.0f} | {r['memory_bytes'] / 1e9:.1f} | {r['length'] or ''} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run")
    r.add_argument("--psc", default="build/cli/psc")
    r.add_argument("--game-dir", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "games"))
    r.add_argument("--games", default="")
    r.add_argument("--backend", default="cpu")
    r.add_argument("--threads", type=int, default=1)
    r.add_argument("--time-limit", type=float, default=30)
    r.add_argument("--algorithm", default="bfs")
    r.add_argument("--jobs", type=int, default=1)
    r.add_argument("--per-level", action="store_true", help="a psc solve (and a plugin) per level")
    r.add_argument("--out", required=True)
    for name in ("table", "levels", "searches"):
        t = sub.add_parser(name)
        t.add_argument("files", nargs="+")
    a = ap.parse_args()
    {"run": run, "table": table, "levels": levels, "searches": searches}[a.command](a)


if __name__ == "__main__":
    main()
