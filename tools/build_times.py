#!/usr/bin/python3
"""Cold build times (docs/robustness.md, docs/performance.md): the rule form
`auto` picks for each game, and the wall time and peak memory of
`psc GAME -o PLUGIN --target cpu|cuda` with an empty cache.

  tools/build_times.py run [--psc P] [--corpus C] [--largest N] [--code-games M] [--ids ID ...] [--targets cpu,cuda] [--jobs J] --json R.json
  tools/build_times.py run --all [--targets cpu] [--parallel P] [--shard K/N] --json R.json   every corpus game
  tools/build_times.py run --games G.txt ... [--repeats K] [--levels 0] [--against OLD_PSC] --json R.json
  tools/build_times.py render R.json            a Markdown table of R.json (a summary past 40 games)

Corpus games are taken once each (by text) from the corpus's traces, ranked
by the size of their source with the rules as straight-line code (`psc GAME
--emit cpp --rules code`, measured J at a time): the N largest, then the M
largest of those `auto` still writes as code, then the games of the cases
--ids names; or all of them, unranked.  --games builds the given files
instead, K times each; with --against, each of those builds follows one by
OLD_PSC, so that both see the machine alike, and the table sets them side by
side.  The builds run one at a time."""
import argparse
import concurrent.futures
import hashlib
import json
import os
import re
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from corpus_replay import provenance  # noqa: E402


def corpus_games(corpus):
    games = {}
    for entry in json.load(open(os.path.join(corpus, "INDEX.json"))):
        if entry["kind"] != "trace":
            continue
        text = json.load(open(os.path.join(corpus, entry["path"])))["game"]
        games.setdefault(hashlib.sha1(text.encode()).hexdigest(), (entry["id"], text))
    return sorted(games.values())


def code_bytes(psc, path):
    r = subprocess.run([psc, path, "--emit", "cpp", "--rules", "code", "--keep-going"], capture_output=True, timeout=600)
    return len(r.stdout) if r.returncode == 0 else 0


def auto_writes_table(psc, path):
    r = subprocess.run([psc, path, "--emit", "cpp", "--keep-going"], capture_output=True, text=True, timeout=600)
    return "PSC_TABLE int kRuleData[]" in r.stdout


def build(psc, path, target, tmp, extra=()):
    cache = tempfile.mkdtemp(dir=tmp)
    command = [psc, path, "-o", os.path.join(cache, "plugin.so"), "--target", target, "--keep-going", "--verbose", *extra]
    log = os.path.join(cache, "log")
    start = time.time()
    with open(log, "w") as out:
        child = subprocess.Popen(command, stdout=out, stderr=subprocess.STDOUT, env=dict(os.environ, PSC_CACHE_DIR=cache))
        # The child's resource use, its compilers' included (psc waits for them).
        _, status, usage = os.wait4(child.pid, 0)
    seconds = time.time() - start
    child.returncode = os.waitstatus_to_exitcode(status)
    text = open(log).read()
    subprocess.run(["rm", "-rf", cache])
    form = re.search(r"psc: (rules as (?:code|a table)[^\n]*)", text)
    ok = child.returncode == 0
    return {"ok": ok, "seconds": round(seconds, 2), "form": form.group(1) if form else "",
            "psc_maxrss_mb": round(usage.ru_maxrss / 1024),
            # psc's and its compilers' processor time (user + system): what the
            # build costs a machine of any core count.
            "cpu_seconds": round(usage.ru_utime + usage.ru_stime, 2),
            "error": "" if ok else text.strip()[-400:]}


def run_games(a):
    """The given game files, each built a.repeats times per target."""
    extra = ["--levels", *a.levels] if a.levels else []
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for path in a.games:
            row = {"game": os.path.splitext(os.path.basename(path))[0]}
            for target in a.targets.split(","):
                runs, before = [], []
                for _ in range(a.repeats):
                    if a.against:
                        before.append(build(a.against, path, target, tmp, extra))
                    runs.append(build(a.psc, path, target, tmp, extra))
                for key, builds in ((target, runs), (target + "_against", before)):
                    if builds:
                        row[key] = dict(builds[0], seconds=min(r["seconds"] for r in builds),
                                        ok=all(r["ok"] for r in builds), repeats=[r["seconds"] for r in builds])
            rows.append(row)
            print(json.dumps(row), flush=True)
    return rows


def run(a):
    if a.games:
        rows = run_games(a)
        meta = provenance("tools/build_times.py " + " ".join(sys.argv[1:]), a.psc, "cpu")
        json.dump(dict(meta, games=rows), open(a.json, "w"), indent=1)
        return
    games = corpus_games(a.corpus)
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for game_id, text in games:
            path = os.path.join(tmp, game_id + ".txt")
            with open(path, "w") as f:
                f.write(text)
            paths.append((game_id, path))
        if a.all:
            chosen, code_games, named = [(None, p) for p in paths][a.shard[0]::a.shard[1]], [], []
        else:
            with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
                sizes = list(pool.map(lambda p: code_bytes(a.psc, p[1]), paths))
            ranked = sorted(zip(sizes, paths), key=lambda s: -s[0])
            chosen = ranked[: a.largest]
            code_games = [r for r in ranked[a.largest:] if not auto_writes_table(a.psc, r[1][1])][: a.code_games] if a.code_games else []
            named = [r for r in ranked if r[1][0] in (a.ids or [])]
        def measure(item):
            size, (game_id, path) = item
            row = {"game": game_id, "code_mb": round(size / 1e6, 2) if size is not None else None}
            for target in a.targets.split(","):
                row[target] = build(a.psc, path, target, tmp)
            print(json.dumps(row), flush=True)
            return row

        # --parallel > 1 builds several games at once: their wall times are
        # then under load, their processor times (cpu_seconds) hardly.
        with concurrent.futures.ThreadPoolExecutor(a.parallel) as pool:
            rows = list(pool.map(measure, chosen + code_games + named))
    meta = provenance("tools/build_times.py " + " ".join(sys.argv[1:]), a.psc, "cpu")
    json.dump(dict(meta, games=rows), open(a.json, "w"), indent=1)


def render_summary(report, targets):
    """Many games: the spread of their build times, and the slowest."""
    games = report["games"]
    print("| target | games | built | failed | wall: median | 99th percentile | slowest | over 60 s | over 120 s "
          "| processor time: median | slowest |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for t in targets:
        runs = [g[t] for g in games if t in g]
        seconds = sorted(r["seconds"] for r in runs)
        cpu = sorted(r.get("cpu_seconds") or 0 for r in runs)
        ok = sum(r["ok"] for r in runs)
        pick = lambda values, q: values[min(len(values) - 1, int(q * len(values)))]
        print(f"| {t.upper()} | {len(runs)} | {ok} | {len(runs) - ok} | {pick(seconds, 0.5):.1f} s | {pick(seconds, 0.99):.1f} s | "
              f"{seconds[-1]:.1f} s | {sum(s > 60 for s in seconds)} | {sum(s > 120 for s in seconds)} | "
              f"{pick(cpu, 0.5):.1f} s | {cpu[-1]:.1f} s |")
    for t in targets:
        slowest = sorted((g for g in games if t in g), key=lambda g: -g[t]["seconds"])[:10]
        print(f"\nThe ten slowest {t.upper()} builds: " + ", ".join(f"`{g['game']}` {g[t]['seconds']:.1f} s" for g in slowest) + ".")
        failed = [g for g in games if t in g and not g[t]["ok"]]
        for g in failed:
            print(f"\n{t.upper()} build of `{g['game']}` failed: {g[t]['error'][-200:]}")


def median(values):
    return sorted(values)[len(values) // 2]


def render_against(report, targets):
    """Games built several times by two psc, alternately: their medians side by side."""
    print("| game | " + " | ".join(f"{t.upper()} before: min / median | after | after / before" for t in targets) + " |")
    print("|---|" + "---:|---:|---:|" * len(targets))
    medians = {t: ([], []) for t in targets}
    for g in report["games"]:
        cells = []
        for t in targets:
            old, new = g[t + "_against"], g[t]
            if not (old["ok"] and new["ok"]):
                cells += ["failed" if not old["ok"] else "", "failed" if not new["ok"] else "", ""]
                continue
            m_old, m_new = median(old["repeats"]), median(new["repeats"])
            medians[t][0].append(m_old)
            medians[t][1].append(m_new)
            cells += [f"{min(old['repeats']):.2f} / {m_old:.2f} s", f"{min(new['repeats']):.2f} / {m_new:.2f} s",
                      f"{m_new / m_old:.2f}"]
        print(f"| {g['game']} | " + " | ".join(cells) + " |")
    for t in targets:
        old, new = medians[t]
        if old:
            print(f"\n{t.upper()}: median over the games {median(old):.2f} s before, {median(new):.2f} s after; "
                  f"maximum {max(old):.2f} s before, {max(new):.2f} s after")


def render_repeats(report, targets):
    """Given games built several times: min and median of each."""
    print("| game | " + " | ".join(f"{t.upper()} plugin, cold: min / median" for t in targets) + " |")
    print("|---|" + "---:|" * len(targets))
    medians = {t: [] for t in targets}
    for g in report["games"]:
        cells = []
        for t in targets:
            runs = g[t]["repeats"]
            medians[t].append(median(runs))
            cells.append(f"{min(runs):.2f} / {median(runs):.2f} s" if g[t]["ok"] else "failed")
        print(f"| {g['game']} | " + " | ".join(cells) + " |")
    for t in targets:
        print(f"\n{t.upper()}: median over the games {median(medians[t]):.2f} s, maximum {max(medians[t]):.2f} s")


def render(a):
    report = json.load(open(a.report))
    targets = [t for t in ("cpu", "cuda") if any(t in g for g in report["games"])]
    print(f"`{report['command']}` (psc {report['commit']}, {report['machine']}, {report['date']}):\n")
    if any(t + "_against" in g for g in report["games"] for t in targets):
        render_against(report, targets)
        return
    if any("repeats" in g.get(t, {}) for g in report["games"] for t in targets):
        render_repeats(report, targets)
        return
    if len(report["games"]) > 40:
        render_summary(report, targets)
        return
    print("| corpus case (game) | CPU source with rules as code | form `auto` chose | " +
          " | ".join(f"{t.upper()} plugin, cold | psc's peak RSS ({t.upper()})" for t in targets) + " |")
    print("|---|---:|---|" + "---:|---:|" * len(targets))
    for g in report["games"]:
        form = next((g[t]["form"] for t in targets if g.get(t, {}).get("form")), "")
        cells = []
        for t in targets:
            b = g[t]
            cells.append(f"{b['seconds']:.1f} s" if b["ok"] else f"failed after {b['seconds']:.0f} s")
            cells.append(f"{b['psc_maxrss_mb']} MB" if b["psc_maxrss_mb"] is not None else "")
        short = "table" if "table" in form else "code"
        print(f"| `{g['game']}` | {g['code_mb']:.2f} MB | {short} | " + " | ".join(cells) + " |")


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run")
    r.add_argument("--psc", default="build/cli/psc")
    r.add_argument("--corpus", default="../shared/corpus")
    r.add_argument("--largest", type=int, default=20)
    r.add_argument("--code-games", type=int, default=0)
    r.add_argument("--ids", nargs="*", help="also these cases' games (corpus case ids)")
    r.add_argument("--all", action="store_true", help="every corpus game, unranked")
    r.add_argument("--games", nargs="*", help="these game files instead of the corpus's")
    r.add_argument("--repeats", type=int, default=1, help="builds of each --games file")
    r.add_argument("--levels", nargs="*", help="psc --levels for --games builds")
    r.add_argument("--against", help="with --games: another psc, each of whose builds precedes one of --psc's")
    r.add_argument("--parallel", type=int, default=1, help="corpus games built at once (default one at a time)")
    r.add_argument("--shard", type=lambda v: tuple(int(x) for x in v.split("/")), default=(0, 1),
                   help="K/N: with --all, every N-th game from the K-th (0-based), for runs split across calls")
    r.add_argument("--targets", default="cpu,cuda")
    r.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    r.add_argument("--json", required=True)
    d = sub.add_parser("render")
    d.add_argument("report")
    a = ap.parse_args()
    run(a) if a.command == "run" else render(a)


if __name__ == "__main__":
    main()
