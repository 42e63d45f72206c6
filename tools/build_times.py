#!/usr/bin/python3
"""Cold build times of the corpus games with the most rule code
(docs/robustness.md): the rule form `auto` picks for each, and the wall time
and peak memory of `psc GAME -o PLUGIN --target cpu|cuda` with an empty cache.

  tools/build_times.py run [--psc P] [--corpus C] [--largest N] [--code-games M] [--ids ID ...] [--targets cpu,cuda] [--jobs J] --json R.json
  tools/build_times.py render R.json            a Markdown table of R.json

Games are taken once each (by text) from the corpus's traces, ranked by the
size of their source with the rules as straight-line code (`psc GAME --emit
cpp --rules code`, measured J at a time): the N largest, then the M largest
of those `auto` still writes as code, then the games of the cases --ids
names.  The builds run one at a time."""
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


def build(psc, path, target, tmp):
    cache = tempfile.mkdtemp(dir=tmp)
    command = ["/usr/bin/time", "-f", "maxrss_kb=%M", psc, path, "-o", os.path.join(cache, "plugin.so"),
               "--target", target, "--keep-going", "--verbose"]
    start = time.time()
    r = subprocess.run(command, capture_output=True, text=True, env=dict(os.environ, PSC_CACHE_DIR=cache))
    seconds = time.time() - start
    subprocess.run(["rm", "-rf", cache])
    form = re.search(r"psc: (rules as (?:code|a table)[^\n]*)", r.stderr)
    rss = re.search(r"maxrss_kb=(\d+)", r.stderr)
    return {"ok": r.returncode == 0, "seconds": round(seconds, 2), "form": form.group(1) if form else "",
            "psc_maxrss_mb": round(int(rss.group(1)) / 1024) if rss else None,
            "error": "" if r.returncode == 0 else r.stderr.strip()[-400:]}


def run(a):
    games = corpus_games(a.corpus)
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for game_id, text in games:
            path = os.path.join(tmp, game_id + ".txt")
            with open(path, "w") as f:
                f.write(text)
            paths.append((game_id, path))
        with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
            sizes = list(pool.map(lambda p: code_bytes(a.psc, p[1]), paths))
        ranked = sorted(zip(sizes, paths), key=lambda s: -s[0])
        chosen = ranked[: a.largest]
        code_games = [r for r in ranked[a.largest:] if not auto_writes_table(a.psc, r[1][1])][: a.code_games] if a.code_games else []
        named = [r for r in ranked if r[1][0] in (a.ids or [])]
        rows = []
        for size, (game_id, path) in chosen + code_games + named:
            row = {"game": game_id, "code_mb": round(size / 1e6, 2)}
            for target in a.targets.split(","):
                row[target] = build(a.psc, path, target, tmp)
            rows.append(row)
            print(json.dumps(row), flush=True)
    meta = provenance("tools/build_times.py " + " ".join(sys.argv[1:]), a.psc, "cpu")
    json.dump(dict(meta, games=rows), open(a.json, "w"), indent=1)


def render(a):
    report = json.load(open(a.report))
    targets = [t for t in ("cpu", "cuda") if any(t in g for g in report["games"])]
    print(f"`{report['command']}` (psc {report['commit']}, {report['machine']}, {report['date']}):\n")
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
    r.add_argument("--targets", default="cpu,cuda")
    r.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    r.add_argument("--json", required=True)
    d = sub.add_parser("render")
    d.add_argument("report")
    a = ap.parse_args()
    run(a) if a.command == "run" else render(a)


if __name__ == "__main__":
    main()
