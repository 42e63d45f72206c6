#!/usr/bin/python3
"""docs/search.md's table of expansion rates: one row per game and level, from
`psc bench GAME --expand` outputs, the GPU's (a folder of GAME.LN.txt, as
tools/gpu_check.sh's expand stage writes them) beside the CPU's (a folder of
the same names).

  bench/expand_table.py --gpu DIR [--cpu DIR]

Rows go from the fastest GPU rate down; a level other than 0 is named."""

import argparse
import re
from pathlib import Path

SUMMARY = re.compile(r"^game \S+ level (\d+) backend \S+.*?; (\d+) inputs a state, (\d+)-byte keys; best batch (\d+)$", re.M)
RATE = re.compile(r"^children/s: (\d+)$", re.M)


def read(path):
    text = path.read_text()
    summary, rate = SUMMARY.search(text), RATE.search(text)
    if not summary or not rate:
        raise SystemExit(f"{path}: no expansion summary")
    level, inputs, key_bytes, batch = map(int, summary.groups())
    return {"level": level, "inputs": inputs, "key_bytes": key_bytes, "batch": batch, "rate": int(rate.group(1))}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gpu", required=True, type=Path)
    ap.add_argument("--cpu", type=Path)
    a = ap.parse_args()
    rows = []
    for path in sorted(a.gpu.glob("*.L*.txt")):
        gpu = read(path)
        cpu_path = a.cpu / path.name if a.cpu else None
        cpu = read(cpu_path) if cpu_path and cpu_path.exists() else None
        rows.append((path.name.split(".L")[0], gpu, cpu))
    rows.sort(key=lambda row: -row[1]["rate"])
    print("| game (level 0) | key bytes | inputs | children/s, GPU | best batch | children/s, CPU |")
    print("|---|---:|---:|---:|---:|---:|")
    for game, gpu, cpu in rows:
        name = game if gpu["level"] == 0 else f"{game} level {gpu['level']}"
        cpu_rate = f"{cpu['rate']:,}" if cpu else ""
        print(f"| {name} | {gpu['key_bytes']} | {gpu['inputs']} | {gpu['rate']:,} | {gpu['batch']:,} | {cpu_rate} |")


if __name__ == "__main__":
    main()
