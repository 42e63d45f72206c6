#!/usr/bin/python3
"""Where a stepping kernel's warps stall, line by line of its generated
source, from `tools/gpu_check.sh divergence`'s files for one game:
GAME_sass.csv (Nsight Compute's source counters, SASS instruction by
instruction) and GAME_lines.csv (the same instructions under each line of
source they came from; the kernels are built with -lineinfo).

An instruction inlined from a helper stands under the helper's line and
under each line that inlined it, so a line's figures include everything
inlined into it: the lines do not add up to 100 %.  For each line: its share
of the launch's stall samples, of the samples that waited for memory
(long_sb: a load that missed the L1) and for an instruction fetch (no_inst),
the function most of them fell in, and the line's text from SOURCE, the
source the plugin was built from (`psc GAME.txt --emit cuda --levels 0` of
the same psc writes the same text).

    bench/ncu_lines.py FOLDER GAME SOURCE [--from-line N] [--top 30]
"""
import argparse
import collections
import csv
import os


def csv_rows(path):
    with open(path, errors="replace") as f:
        return list(csv.reader(line for line in f if line.startswith('"')))


def lines_of_addresses(path):
    """SASS address -> the source lines it stands under."""
    lines = collections.defaultdict(set)
    line = None
    for row in csv_rows(path):
        if row and row[0].isdigit():
            line = int(row[0])
        elif len(row) > 2 and row[2].startswith("0x") and line is not None:
            lines[row[2]].add(line)
    return lines


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("folder")
    parser.add_argument("game")
    parser.add_argument("source")
    parser.add_argument("--from-line", type=int, default=0, help="leave out lines before this one (the templates' helpers)")
    parser.add_argument("--top", type=int, default=30)
    args = parser.parse_args()
    text = open(args.source, errors="replace").read().split("\n")
    lines = lines_of_addresses(os.path.join(args.folder, f"{args.game}_lines.csv"))
    totals = collections.Counter()
    by_line = collections.defaultdict(collections.Counter)
    functions = collections.defaultdict(collections.Counter)
    header, function = None, ""
    for row in csv_rows(os.path.join(args.folder, f"{args.game}_sass.csv")):
        if row and row[0] == "Kernel Name":
            function = row[1].split("(")[0].replace("psc_game::", "")
        elif "Instructions Executed" in row:
            header = {name: i for i, name in enumerate(row)}
        elif header and row and row[0].startswith("0x"):
            sample = {key: float(row[header[column]] or 0) for key, column in (
                ("samples", "Warp Stall Sampling (All Samples)"), ("long_sb", "stall_long_sb"), ("no_inst", "stall_no_inst"))}
            totals.update(sample)
            for line in lines.get(row[0], ()):
                if line >= args.from_line:
                    by_line[line].update(sample)
                    functions[line][function] += sample["samples"]
    share = lambda c, key: f"{100 * c[key] / max(totals['samples'], 1):.1f} %"
    print(f"{args.game}: {totals['samples']:.0f} stall samples, {share(totals, 'long_sb')} waiting for memory, "
          f"{share(totals, 'no_inst')} for an instruction fetch")
    print("| line | samples | long_sb | no_inst | function | source |")
    print("|---:|---:|---:|---:|---|---|")
    for line, c in sorted(by_line.items(), key=lambda item: -item[1]["samples"])[: args.top]:
        source = text[line - 1].strip() if 0 < line <= len(text) else "?"
        print(f"| {line} | {share(c, 'samples')} | {share(c, 'long_sb')} | {share(c, 'no_inst')} "
              f"| {functions[line].most_common(1)[0][0]} | `{source[:80]}` |")


if __name__ == "__main__":
    main()
