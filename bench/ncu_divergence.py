#!/usr/bin/python3
"""Where a stepping kernel's warps run with few threads, from `tools/gpu_check.sh
divergence`'s CSVs: Nsight Compute's source counters of one launch of
psc_run_kernel, SASS instruction by instruction (GAME_sass.csv).

For each game: its warp instructions, the threads a warp instruction has
active on average, the share of warp instructions issued with fewer than
LOW threads of 32, and the largest runs of consecutive SASS instructions
that each ran with fewer than LOW threads (a divergent branch's body): their
SASS index range, share of the kernel's warp instructions and average
threads.  Functions the kernel calls (stepEvent, nextLevel, ...) follow the
kernel in the listing; a run in them is marked "called".

    bench/ncu_divergence.py FOLDER [--low 10] [--runs 3]
"""
import argparse
import csv
import glob
import os


def read_sass(path):
    """(instruction text, warp instructions, thread instructions) per SASS instruction."""
    with open(path, errors="replace") as f:
        rows = list(csv.reader(line for line in f if line.startswith('"')))
    header = next(r for r in rows if "Instructions Executed" in r)
    executed = header.index("Instructions Executed")
    threads = header.index("Thread Instructions Executed")
    source = header.index("Source")
    out = []
    for row in rows[rows.index(header) + 1:]:
        if len(row) != len(header):
            continue
        try:
            out.append((row[source].strip(), float(row[executed]), float(row[threads])))
        except ValueError:
            pass
    return out


def kernel_end(sass):
    """Index of the kernel's last instruction: its last EXIT before the first
    function's RET (the called functions come after the kernel)."""
    first_ret = next((i for i, (text, _, _) in enumerate(sass) if text.startswith("RET")), len(sass))
    exits = [i for i, (text, _, _) in enumerate(sass[:first_ret]) if "EXIT" in text]
    return exits[-1] if exits and first_ret < len(sass) else len(sass) - 1


def low_runs(sass, low, end):
    """Runs of executed instructions that each had fewer than `low` threads;
    a run ends at the kernel's end and at a function's return."""
    runs, current = [], None
    for i, (text, n, t) in enumerate(sass):
        if current and (i == end + 1 or text.startswith("RET")):
            runs.append(current)
            current = None
        if n == 0:
            continue
        if t / n < low:
            if current is None:
                current = [i, i, 0.0, 0.0]
            current[1] = i
            current[2] += n
            current[3] += t
        elif current:
            runs.append(current)
            current = None
    if current:
        runs.append(current)
    return runs


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder")
    parser.add_argument("--low", type=float, default=10, help="threads of 32 below which a warp instruction counts as divergent")
    parser.add_argument("--runs", type=int, default=3, help="largest runs shown a game")
    args = parser.parse_args()
    paths = sorted(glob.glob(os.path.join(args.folder, "*_sass.csv")))
    if not paths:
        raise SystemExit(f"no *_sass.csv in {args.folder}")
    print(f"| game | SASS instructions | threads active a warp instruction | warp instructions with < {args.low:g} threads "
          f"| largest runs below {args.low:g} threads: SASS range (instructions), share of warp instructions, threads |")
    print("|---|---:|---:|---:|---|")
    for path in paths:
        game = os.path.basename(path)[: -len("_sass.csv")]
        sass = read_sass(path)
        total = sum(n for _, n, _ in sass)
        if total == 0:
            print(f"| {game} | {len(sass)} | | | no instruction executed |")
            continue
        threads = sum(t for _, _, t in sass) / total
        end = kernel_end(sass)
        runs = sorted(low_runs(sass, args.low, end), key=lambda r: -r[2])
        low_share = sum(r[2] for r in runs) / total
        shown = []
        for first, last, n, t in runs[: args.runs]:
            where = " called" if first > end else ""
            shown.append(f"{first}–{last} ({last - first + 1}){where}: {100 * n / total:.1f} %, {t / n:.1f}")
        print(f"| {game} | {len(sass):,} | {threads:.1f} | {100 * low_share:.0f} % | {'; '.join(shown)} |")


if __name__ == "__main__":
    main()
