#!/usr/bin/python3
"""The build-time table of docs/performance.md from `tools/gpu_check.sh buildtime`'s
output: per benchmark game, the cold end-to-end `psc GAME -o GAME.so --target
cuda --levels 0` with the host side in one compile process (PSC_COMPILE_JOBS=1)
and in parallel ones (the default), min and median of the repeats, and the
median and maximum over the games.

    bench/buildtime_table.py docs/results/build-profile-2026-11-25/buildtime.txt
"""
import re
import statistics
import sys

LINE = re.compile(r"^(\S+)\s+jobs (\S+)\s+exit (\d+)\s+total\s+([\d.]+) s\s+nvrtc\s+([\d.]+) s\s+host\s+([\d.]+) s")


def main():
    runs = {}
    for line in open(sys.argv[1]):
        m = LINE.match(line)
        if not m or m.group(3) != "0":
            continue
        game, jobs = m.group(1), m.group(2)
        runs.setdefault(game, {}).setdefault(jobs, []).append(tuple(float(m.group(i)) for i in (4, 5, 6)))
    # Only the modes the run measured (BUILD_JOBS="0" builds with parallel host processes alone).
    modes = [(jobs, label) for jobs, label in (("1", "one host process"), ("all", "parallel host processes"))
             if any(jobs in r for r in runs.values())]
    print("| game | " + " | ".join(f"{label}: total min / median | NVRTC | host" for _, label in modes) + " |")
    print("|---|" + "---:|---:|---:|" * len(modes))
    medians = {"1": [], "all": []}
    for game in sorted(runs):
        cells = []
        for jobs, _ in modes:
            r = runs[game].get(jobs, [])
            if not r:
                cells += ["", "", ""]
                continue
            totals = [t for t, _, _ in r]
            medians[jobs].append(statistics.median(totals))
            cells += [f"{min(totals):.2f} / {statistics.median(totals):.2f} s",
                      f"{statistics.median(n for _, n, _ in r):.2f} s", f"{statistics.median(h for _, _, h in r):.2f} s"]
        print(f"| {game} | " + " | ".join(cells) + " |")
    for jobs, label in (("1", "one host process"), ("all", "parallel host processes")):
        if medians[jobs]:
            print(f"\n{label}: median over the games {statistics.median(medians[jobs]):.2f} s, "
                  f"maximum {max(medians[jobs]):.2f} s", end="")
    print()


if __name__ == "__main__":
    main()
