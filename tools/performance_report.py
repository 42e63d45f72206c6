#!/usr/bin/python3
"""The summary table of docs/performance.md: each benchmark game's GPU steps/s
at default options (best batch, and batches 1, 1,024 and 16,384), its CPU
steps/s on one thread of the development machine, the ratio, PuzzleJAX's
figure and the ratio to it, and the cold build of its CUDA plugin; then the
geometric means against issue 18's bars.

  tools/performance_report.py --psc PSC --gpu-bench DIR [DIR ...] --cpu-bench MD [MD ...]
      [--cpu-before MD ... --cpu-after MD ...] --buildtime TXT

Each DIR holds `tools/gpu_check.sh bench`'s outputs (GAME.txt); a game's
figures come from the last DIR that has it.  Each MD is a `bench/cpu_bench.sh`
table (the best figure of a game over the files counts: the development
machine's speed varies by half between runs, and a slower run would flatter
the ratio).  Where the CPU code changed since those runs, --cpu-before and
--cpu-after name tables of the older and the newer psc run in turn on one
day: each game's figure is scaled by the median of the newer runs over the
median of the older ones, so that the day's speed cancels out.  TXT is
`tools/gpu_check.sh buildtime`'s output (its default,
parallel builds: each game's range over its repeats; the bars take each
game's median and the slowest single build).  A game's layout is the one
PSC generates for its level 0 (`--emit cuda`)."""
import argparse
import math
import os
import re
import subprocess
from statistics import median

# PuzzleJAX's best steps/s on the same GPU model (issue 4), millions.
PUZZLEJAX_M = {"sokoban": 4.75, "notsnake": 6.97, "blocks": 1.11, "traveling": 7.23, "match3": 2.55,
               "constellationz": 1.82, "zenpuzzle": 2.54, "dictionary": 1.68, "takeheart": 1.81, "limerick": 0.35,
               "slidings": 1.65, "kettle": 0.27, "atlas": 0.014}
SMALL_BATCHES = (1, 1024, 16384)


def gpu_bench(path):
    text = open(path).read()
    rows = {int(m.group(1)): float(m.group(2))
            for m in re.finditer(r"^\s+(\d+)\s+\d+\s+(\d+)\s+\d+\s+\d+(?:\s+[\d.]+)?$", text, re.M)}
    best = re.search(r"best batch (\d+)\nsteps/s: (\d+)", text)
    return {"best": float(best.group(2)), "best_batch": int(best.group(1)), "rows": rows}


def layout(psc, game):
    """The GPU state layout psc generates for the game's level 0, with its compile units."""
    source = subprocess.run([psc, game, "--emit", "cuda", "--levels", "0"], capture_output=True, text=True,
                            check=True, timeout=300).stdout
    define = lambda name: int(re.search(rf"^#define {name} (\d+)", source, re.M).group(1))
    units = define("PSC_COMPILE_UNITS")
    if define("PSC_STATE_IN_REGISTERS"):
        return "registers"
    return f"{'groups' if define('PSC_STATE_IN_GROUPS') else 'memory'}, {units} units"


def cpu_tables(paths):
    return [{m.group(1): float(m.group(2)) for m in re.finditer(r"^\| (\w+) \| ([\d.]+) \|", open(path).read(), re.M)}
            for path in paths]


def cpu_bench(paths):
    best = {}
    for table in cpu_tables(paths):
        for game, rate in table.items():
            best[game] = max(best.get(game, 0.0), rate)
    return best


def cpu_change(before_paths, after_paths):
    """Each game's CPU speed-up from the older psc to the newer, runs of one day."""
    before, after = cpu_tables(before_paths), cpu_tables(after_paths)
    return {g: median(t[g] for t in after) / median(t[g] for t in before) for g in before[0]}


def build_times(path):
    times = {}
    for m in re.finditer(r"^(\w+)\s+jobs all exit 0\s+total\s+([\d.]+) s", open(path).read(), re.M):
        times.setdefault(m.group(1), []).append(float(m.group(2)))
    return times


def seconds_range(values):
    return f"{min(values):.2f} s" if len(values) == 1 else f"{min(values):.2f}–{max(values):.2f} s"


def si(v):
    for scale, suffix in ((1e9, " G"), (1e6, " M"), (1e3, " k")):
        if v >= scale:
            return f"{v / scale:.3g}{suffix}"
    return f"{v:.0f}"


def geomean(values):
    return math.exp(sum(math.log(v) for v in values) / len(values))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--psc", required=True)
    ap.add_argument("--games", default="bench/games", help="the benchmark games' folder")
    ap.add_argument("--gpu-bench", nargs="+", required=True, help="psc bench outputs (GAME.txt) or folders of them; a later one of a game wins")
    ap.add_argument("--cpu-bench", nargs="+", required=True)
    ap.add_argument("--cpu-before", nargs="+", action="append", default=[],
                    help="cpu_bench tables of an older psc; with --cpu-after, each game's CPU figure is scaled by "
                         "the change between them; given again, by each pair's in turn (a game missing from a pair: 1)")
    ap.add_argument("--cpu-after", nargs="+", action="append", default=[])
    ap.add_argument("--buildtime", required=True)
    a = ap.parse_args()
    if len(a.cpu_before) != len(a.cpu_after):
        ap.error("--cpu-before and --cpu-after go together, once each per pair")
    cpu = cpu_bench(a.cpu_bench)
    for before, after in zip(a.cpu_before, a.cpu_after):
        change = cpu_change(before, after)
        cpu = {g: rate * change.get(g, 1.0) for g, rate in cpu.items()}
    builds = build_times(a.buildtime)
    bench = {}
    for path in a.gpu_bench:
        files = [os.path.join(path, f) for f in os.listdir(path)] if os.path.isdir(path) else [path]
        for f in files:
            if f.endswith(".txt"):
                bench[os.path.splitext(os.path.basename(f))[0]] = gpu_bench(f)
    games = sorted(bench, key=lambda g: -bench[g]["best"])
    print("| game | layout | GPU steps/s, best batch | " + " | ".join(f"batch {b:,}" for b in SMALL_BATCHES) +
          " | CPU steps/s, 1 thread | GPU / CPU | PuzzleJAX | GPU / PuzzleJAX | cold CUDA build |")
    print("|---|---|---:|" + "---:|" * len(SMALL_BATCHES) + "---:|---:|---:|---:|---:|")
    to_cpu, to_jax = [], []
    for g in games:
        r = bench[g]
        r["layout"] = layout(a.psc, os.path.join(a.games, g + ".txt"))
        small = " | ".join(si(r["rows"][b]) if b in r["rows"] else "" for b in SMALL_BATCHES)
        ratio_cpu = r["best"] / cpu[g]
        ratio_jax = r["best"] / (PUZZLEJAX_M[g] * 1e6)
        to_cpu.append(ratio_cpu)
        to_jax.append(ratio_jax)
        print(f"| {g} | {r['layout']} | {si(r['best'])} ({r['best_batch']:,}) | {small} | {si(cpu[g])} | {ratio_cpu:,.0f}× | "
              f"{PUZZLEJAX_M[g]:g} M | {ratio_jax:,.0f}× | {seconds_range(builds[g])} |")
    repeats = max(len(builds[g]) for g in games)
    print()
    print(f"GPU / CPU: geometric mean {geomean(to_cpu):,.0f}× (bar 600×), lowest {min(to_cpu):,.0f}× (bar 400×); "
          f"{sum(v >= 400 for v in to_cpu)} of {len(games)} games at 400× or more.")
    print(f"GPU / PuzzleJAX: geometric mean {geomean(to_jax):,.0f}× (bar 1,000×), lowest {min(to_jax):,.0f}× (bar 300×).")
    print(f"Cold CUDA build ({repeats} a game): median over the games of each one's median "
          f"{median([median(builds[g]) for g in games]):.2f} s (bar 1.5 s); slowest game's median "
          f"{max(median(builds[g]) for g in games):.2f} s, slowest single build {max(max(builds[g]) for g in games):.2f} s "
          f"(bar 3 s).")


if __name__ == "__main__":
    main()
