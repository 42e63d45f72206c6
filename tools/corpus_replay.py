#!/usr/bin/python3
"""Replays corpus trace cases with `psc replay` and reports pass counts.

    tools/corpus_replay.py [--psc build/cli/psc] [--corpus ../shared/corpus]
                           [--suite testsuite|scraped|all] [--jobs N] [--sample N]
                           [--backend cpu|cuda] [--fast-compile LEVEL] [--gpu-state STATE] [--rules FORM]
                           [--dumps DIR] [--json report.json]
                           [--min PERCENT] [--ids-file FILE] [--timeout S] [--verbose] [--list] [IDS...]

Each case is replayed in its own process (a crash or hang in one case cannot
hide the others).  Prints one line per failing case and a summary; exits 1 if
the pass rate is below --min.  With --dumps, every case's states are written
to DIR/<id>.jsonl and the report gives each dump's sha1, so the states of two
backends can be compared case by case (tools/compare_dumps.py).  --list
prints the chosen cases' paths, largest game first, and replays nothing.
"""
import argparse
import concurrent.futures
import hashlib
import json
import os
import subprocess
import sys
import time

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


def game_size(corpus, entry):
    with open(os.path.join(corpus, entry["path"])) as f:
        return len(json.load(f).get("game", ""))


def file_sha1(path):
    try:
        with open(path, "rb") as f:
            return hashlib.sha1(f.read()).hexdigest()
    except OSError:
        return None


def replay(psc, corpus, entry, extra, dumps, timeout):
    path = os.path.join(corpus, entry["path"])
    dump = os.path.join(dumps, entry["id"] + ".jsonl") if dumps else None
    start = time.time()
    try:
        r = subprocess.run([psc, "replay", path] + extra + (["--dump", dump] if dump else []),
                           capture_output=True, text=True, timeout=timeout)
        code, out = r.returncode, (r.stdout + r.stderr)
    except subprocess.TimeoutExpired as e:
        partial = "".join(x.decode(errors="replace") if isinstance(x, bytes) else x for x in (e.stdout, e.stderr) if x)
        code, out = 3, partial + f"\ntimed out after {timeout} s"
    return entry, code, out, time.time() - start, file_sha1(dump) if dump else None


def provenance(command, psc, backend):
    """What produced a report: the command, psc's commit, the machine and the day."""
    # An installed psc of tools/device_bundle.sh names its commit beside it.
    stamp = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(psc))), "COMMIT")
    if os.path.exists(stamp):
        commit = open(stamp).read().strip()
    else:
        commit = subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True, text=True,
                                cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name")), "?")
    machine = f"{cpu}, {os.cpu_count()} cores"
    if backend == "cuda":
        gpu = subprocess.run(["nvidia-smi", "--query-gpu=name", "--format=csv,noheader"], capture_output=True, text=True).stdout
        machine = f"{gpu.splitlines()[0].strip() if gpu.strip() else 'unknown GPU'}; {machine}"
    return {"command": command, "commit": commit or "unknown", "machine": machine, "date": time.strftime("%Y-%m-%d")}


def write_report(a, results, meta):
    passed = sum(r["status"] == "pass" for r in results)
    with open(a.json, "w") as f:
        json.dump({"suite": a.suite, "backend": a.backend, "passed": passed, "total": len(results), **meta,
                   "cases": results}, f, indent=1)


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
    ap.add_argument("--fast-compile", default="", help="psc replay's --fast-compile (CUDA)")
    ap.add_argument("--gpu-state", default="", help="psc replay's --gpu-state (CUDA)")
    ap.add_argument("--rules", default="", help="psc replay's --rules: code, table or auto")
    ap.add_argument("--dumps", default="", help="write every case's states to this folder")
    ap.add_argument("--ids-file", default="", help="replay the case ids listed in this file (one a line)")
    ap.add_argument("--timeout", type=float, default=300, help="seconds a case may take, compile included")
    ap.add_argument("--verbose", action="store_true", help="psc replay's --verbose: compile options and where the time goes")
    ap.add_argument("--check-keys", action="store_true", help="psc replay's --check-keys: every level state's search key gives it back")
    ap.add_argument("--list", action="store_true", help="print the chosen cases' paths instead of replaying them")
    ap.add_argument("ids", nargs="*")
    a = ap.parse_args()

    cases = [e for e in load_index(a.corpus) if e["kind"] == "trace" and a.suite in ("all", e["suite"])]
    ids = set(a.ids)
    if a.ids_file:
        with open(a.ids_file) as f:
            ids |= {line.strip() for line in f if line.strip()}
    if ids:
        cases = [e for e in cases if e["id"] in ids]
    if a.sample:
        cases = sample_cases(cases, a.sample)
    # The largest games start first: compile time grows with the game, and the
    # slowest cases would otherwise start last and leave the other jobs idle.
    cases.sort(key=lambda e: -game_size(a.corpus, e))
    if a.list:
        print("\n".join(os.path.join(a.corpus, e["path"]) for e in cases))
        return
    extra = ["--backend", a.backend] + (["--fast-compile", a.fast_compile] if a.fast_compile else []) + \
        (["--gpu-state", a.gpu_state] if a.gpu_state else []) + (["--rules", a.rules] if a.rules else []) + \
        (["--verbose"] if a.verbose else []) + \
        (["--check-keys"] if a.check_keys else [])
    if a.dumps:
        os.makedirs(a.dumps, exist_ok=True)
    meta = provenance("tools/corpus_replay.py " + " ".join(sys.argv[1:]), a.psc, a.backend) if a.json else {}
    results = []
    retry = []
    reported = time.time()

    def record(entry, code, out, seconds, sha1):
        nonlocal reported
        results.append({"id": entry["id"], "status": {0: "pass", 1: "mismatch", 2: "error", 3: "timeout"}.get(code, f"crash({code})"),
                        "output": out.strip()[-2000:], "seconds": round(seconds, 2), "dump_sha1": sha1})
        if code != 0:
            first = [line for line in out.strip().splitlines() if "warning:" not in line and not line.startswith("psc: ")][:3]
            print(f"FAIL {entry['id']}: " + " | ".join(first)[:300], flush=True)
        if a.json and time.time() - reported > 5:
            write_report(a, results, meta)  # partial results survive a run cut short
            reported = time.time()

    with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        futures = [pool.submit(replay, a.psc, a.corpus, e, extra, a.dumps, a.timeout) for e in cases]
        for future in concurrent.futures.as_completed(futures):
            entry, code, out, seconds, sha1 = future.result()
            if a.backend == "cuda" and code == 2 and "out of memory" in out and a.jobs > 1:
                retry.append(entry)  # the GPU was shared by too many replays: again, alone, below
                continue
            record(entry, code, out, seconds, sha1)
    # A game with large boards reserves tens of GB of stack (CudaCompiler.h,
    # stackBound); such replays run one at a time.
    for entry in retry:
        record(*replay(a.psc, a.corpus, entry, extra, a.dumps, a.timeout))
    results.sort(key=lambda r: r["id"])
    passed = sum(r["status"] == "pass" for r in results)
    pct = 100.0 * passed / len(results) if results else 100.0
    print(f"{a.suite}: {passed}/{len(results)} passed ({pct:.2f}%)")
    if a.json:
        write_report(a, results, meta)
    sys.exit(0 if pct >= a.min else 1)


if __name__ == "__main__":
    main()
