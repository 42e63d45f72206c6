#!/usr/bin/python3
"""The multi-GPU table of docs/performance.md from a `tools/gpu_check.sh multigpu`
archive's folder: per game, aggregate steps/s on one GPU and on all of them,
driven by one process (psc bench --devices) and by one process a GPU
(examples/torchrun_rollout.py under torchrun), and the speed-ups.

    bench/multigpu_table.py docs/results/multigpu-2026-11-25
"""
import glob
import json
import os
import re
import sys


def bench_rate(path):
    with open(path) as f:
        match = re.search(r"^steps/s: (\d+)", f.read(), re.M)
    return float(match.group(1)) if match else None


def main():
    folder = sys.argv[1]
    games = sorted({os.path.basename(p).split(".")[0][len("bench_"):] for p in glob.glob(f"{folder}/bench_*.0.txt")})
    print("| game | batch per GPU | GPUs | one process: steps/s | speed-up | one process a GPU (torchrun): steps/s | speed-up |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for game in games:
        single = bench_rate(f"{folder}/bench_{game}.0.txt")
        runs = {}
        for path in glob.glob(f"{folder}/torchrun_{game}.*.json"):
            with open(path) as f:
                result = json.load(f)
            runs[result["gpus"]] = result
        for several in sorted(glob.glob(f"{folder}/bench_{game}.0-*.txt")):
            gpus = len(several.split(".")[-2].split("-"))
            rate = bench_rate(several)
            one, many = runs.get(1), runs.get(gpus)
            batch = many["envs_per_gpu"] if many else ""
            if one is not None:
                print(f"| {game} | {batch:,} | 1 | {single:,.0f} | | {one['aggregate_steps_per_s']:,.0f} | |")
            torchrun = (
                f"{many['aggregate_steps_per_s']:,.0f} | {many['aggregate_steps_per_s'] / one['aggregate_steps_per_s']:.2f}×"
                if one and many
                else "| "
            )
            print(f"| {game} | {batch:,} | {gpus} | {rate:,.0f} | {rate / single:.2f}× | {torchrun} |")


if __name__ == "__main__":
    main()
