#!/usr/bin/python3
"""psc solve over every playable level of the public corpus' games (the
scraped suite, one copy of each game text), at a fixed time per level: the
corpus-wide measure of docs/search.md.

  bench/corpus_solve.py extract --corpus ../shared/corpus --out DIR      the games as DIR/NNN.txt
  bench/corpus_solve.py run --games DIR --out R.jsonl [--time-limit 0.25] [--algorithm portfolio] [--jobs N] [--part K/M]
  bench/corpus_solve.py summary R.jsonl [...]

`run` searches each level with one CPU thread (--threads 1) and --keep-going
(the reference plays games with a few errors); a game whose plugin does not
build within --build-seconds counts its levels as not solved.  --part K/M
takes every M-th game from the K-th, and --skip R.jsonl leaves out the games
those results hold, to split a run across calls."""

import argparse
import concurrent.futures
import glob
import hashlib
import json
import os
import subprocess
import sys
import time


def extract(a):
    index = json.load(open(os.path.join(a.corpus, "INDEX.json")))
    seen = {}
    for entry in index:
        if entry["suite"] != "scraped" or entry["kind"] != "trace":
            continue
        game = json.load(open(os.path.join(a.corpus, entry["path"])))["game"]
        seen.setdefault(hashlib.sha1(game.encode()).hexdigest(), (entry["name"], game))
    os.makedirs(a.out, exist_ok=True)
    for n, (_, (name, game)) in enumerate(sorted(seen.items(), key=lambda kv: kv[1][0])):
        with open(os.path.join(a.out, f"{n:03d}.txt"), "w") as f:
            f.write(game)
    print(f"{len(seen)} games in {a.out}")


def solve_game(a, path):
    command = [a.psc, "solve", path, "--all-levels", "--keep-going", "--format", "json", "--quiet", "--threads", "1",
               "--time-limit", str(a.time_limit), "--algorithm", a.algorithm]
    start = time.time()
    try:
        done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              timeout=a.build_seconds + 200 * a.time_limit * 4)
    except subprocess.TimeoutExpired:
        return {"game": os.path.basename(path), "error": "timed out", "seconds": time.time() - start}
    records = [json.loads(line) for line in done.stdout.splitlines() if line.strip().startswith("{")]
    result = {"game": os.path.basename(path), "records": records, "seconds": round(time.time() - start, 2)}
    if done.returncode == 2 and not records:
        result["error"] = done.stderr.strip()[-300:]
    return result


def run(a):
    games = sorted(glob.glob(os.path.join(a.games, "*.txt")))
    k, m = (int(x) for x in a.part.split("/"))
    games = games[k::m]
    done = set()
    for path in a.skip:
        done |= {json.loads(line)["game"] for line in open(path)}
    games = [g for g in games if os.path.basename(g) not in done]
    # Results are written as games finish, so that a run cut short keeps them.
    with open(a.out, "w") as out, concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        futures = [pool.submit(solve_game, a, g) for g in games]
        for n, future in enumerate(concurrent.futures.as_completed(futures), 1):
            out.write(json.dumps(future.result()) + "\n")
            out.flush()
            if n % 50 == 0:
                print(f"{n}/{len(games)} games", flush=True)
    summary(argparse.Namespace(files=[a.out]))


def summary(a):
    games = levels = solved = exhausted = errors = 0
    for path in a.files:
        for line in open(path):
            result = json.loads(line)
            games += 1
            if "error" in result:
                errors += 1
            records = result.get("records", [])
            levels += len(records)
            solved += sum(r["status"] == "solved" for r in records)
            exhausted += sum(r["status"] == "exhausted" for r in records)
    print(f"{games} games ({errors} not searched), {levels} playable levels: {solved} solved "
          f"({100.0 * solved / max(levels, 1):.1f}%), {exhausted} exhausted")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    e = sub.add_parser("extract")
    e.add_argument("--corpus", default="../shared/corpus")
    e.add_argument("--out", required=True)
    r = sub.add_parser("run")
    r.add_argument("--psc", default="build/cli/psc")
    r.add_argument("--games", required=True)
    r.add_argument("--out", required=True)
    r.add_argument("--time-limit", type=float, default=0.25)
    r.add_argument("--algorithm", default="portfolio")
    r.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    r.add_argument("--build-seconds", type=float, default=180)
    r.add_argument("--part", default="0/1")
    r.add_argument("--skip", nargs="*", default=[])
    s = sub.add_parser("summary")
    s.add_argument("files", nargs="+")
    a = ap.parse_args()
    {"extract": extract, "run": run, "summary": summary}[a.command](a)


if __name__ == "__main__":
    main()
