#!/usr/bin/python3
"""Replays corpus trace cases with `psc replay` and reports pass counts.

    tools/corpus_replay.py [--psc build/cli/psc] [--corpus ../shared/corpus]
                           [--suite testsuite|scraped] [--jobs N] [--sample N]
                           [--json report.json] [--min PERCENT] [IDS...]

Each case is replayed in its own process (a crash or hang in one case cannot
hide the others).  Prints one line per failing case and a summary; exits 1 if
the pass rate is below --min.
"""
import argparse
import concurrent.futures
import hashlib
import json
import os
import subprocess
import sys
import time

TIMEOUT_S = 300


def load_index(corpus):
    with open(os.path.join(corpus, "INDEX.json")) as f:
        return json.load(f)


def sample_cases(cases, n):
    """Every game once first (sorted by a hash of the id), then more cases of the same games."""
    ranked = sorted(cases, key=lambda e: hashlib.sha1(e["id"].encode()).hexdigest())
    seen, first, rest = set(), [], []
    for e in ranked:
        game = e["id"].rsplit("-L", 1)[0]
        (rest if game in seen else first).append(e)
        seen.add(game)
    return (first + rest)[:n]


def replay(psc, corpus, entry, extra):
    path = os.path.join(corpus, entry["path"])
    start = time.time()
    try:
        r = subprocess.run([psc, "replay", path] + extra, capture_output=True, text=True, timeout=TIMEOUT_S)
        code, out = r.returncode, (r.stdout + r.stderr)
    except subprocess.TimeoutExpired:
        code, out = 3, f"timed out after {TIMEOUT_S} s"
    return entry, code, out, time.time() - start


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--psc", default="build/cli/psc")
    ap.add_argument("--corpus", default="../shared/corpus")
    ap.add_argument("--suite", default="testsuite")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--sample", type=int, default=0, help="replay this many cases, spread over games")
    ap.add_argument("--json", default="")
    ap.add_argument("--min", type=float, default=0.0)
    ap.add_argument("--backend", default="cpu")
    ap.add_argument("ids", nargs="*")
    a = ap.parse_args()

    cases = [e for e in load_index(a.corpus) if e["kind"] == "trace" and e["suite"] == a.suite]
    if a.ids:
        cases = [e for e in cases if e["id"] in a.ids]
    if a.sample:
        cases = sample_cases(cases, a.sample)
    extra = ["--backend", a.backend]
    results = []
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        for entry, code, out, seconds in pool.map(lambda e: replay(a.psc, a.corpus, e, extra), cases):
            results.append({"id": entry["id"], "status": {0: "pass", 1: "mismatch", 2: "error", 3: "timeout"}.get(code, f"crash({code})"),
                            "output": out.strip()[-2000:], "seconds": round(seconds, 2)})
            if code != 0:
                first = out.strip().splitlines()[:3]
                print(f"FAIL {entry['id']}: " + " | ".join(first)[:300], flush=True)
    passed = sum(r["status"] == "pass" for r in results)
    pct = 100.0 * passed / len(results) if results else 100.0
    print(f"{a.suite}: {passed}/{len(results)} passed ({pct:.2f}%)")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"suite": a.suite, "passed": passed, "total": len(results), "cases": results}, f, indent=1)
    sys.exit(0 if pct >= a.min else 1)


main()
