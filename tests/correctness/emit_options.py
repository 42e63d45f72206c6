#!/usr/bin/python3
"""--emit cpp and --emit cuda print the source that a build with the same
options compiles: --levels sizes the boards for the levels built in both, the
header's regenerate command repeats the options that shaped the source, and
the same command prints the same bytes twice; --rules table writes the
rules as a table, which a small game does not get by default.

    emit_options.py PSC GAME    (GAME: a game whose level 0 is smaller than its largest level)"""
import re
import subprocess
import sys


def emit(psc, game, *options):
    r = subprocess.run([psc, game, *options], capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        raise SystemExit(f"FAIL: psc {' '.join(options)} exited {r.returncode}\n{r.stderr[-2000:]}")
    return r.stdout


def words(source):
    m = re.search(r"constexpr int kWords = (\d+);", source)
    return int(m.group(1)) if m else None


def regenerate(source):
    m = re.search(r"regenerate with `([^`]*)`", source)
    return m.group(1) if m else ""


def main():
    psc, game = sys.argv[1], sys.argv[2]
    failures = []
    cpp_all = emit(psc, game, "--emit", "cpp")
    cpp_level0 = emit(psc, game, "--emit", "cpp", "--levels", "0")
    cuda_level0 = emit(psc, game, "--emit", "cuda", "--levels", "0", "--gpu-state", "shared", "--cuda-units", "2")
    cpp_table = emit(psc, game, "--emit", "cpp", "--rules", "table")
    if not words(cpp_level0) or not words(cpp_all) or words(cpp_level0) >= words(cpp_all):
        failures.append(f"--emit cpp --levels 0 has {words(cpp_level0)} words a board, all levels {words(cpp_all)}")
    if words(cpp_level0) != words(cuda_level0):
        failures.append(f"--levels 0: --emit cpp sizes boards at {words(cpp_level0)} words, --emit cuda at {words(cuda_level0)}")
    expected = {
        "cpp all": (cpp_all, f"psc {game} --emit cpp"),
        "cpp level 0": (cpp_level0, f"psc {game} --emit cpp --levels 0"),
        "cuda level 0": (cuda_level0, f"psc {game} --emit cuda --levels 0 --gpu-state shared --cuda-units 2"),
        "cpp table": (cpp_table, f"psc {game} --emit cpp --rules table"),
    }
    for name, (source, command) in expected.items():
        if regenerate(source) != command:
            failures.append(f"{name}: the header says `{regenerate(source)}`, expected `{command}`")
    if "#define PSC_STATE_IN_SHARED 1" not in cuda_level0:
        failures.append("--gpu-state shared does not set PSC_STATE_IN_SHARED")
    if "PSC_TABLE int kRuleData[]" not in cpp_table or re.search(r"PSC_RULE bool rule_", cpp_table):
        failures.append("--rules table: no kRuleData, or rules still written as functions")
    if "kRuleData" in cpp_all or not re.search(r"PSC_RULE bool rule_", cpp_all):
        failures.append("a small game's rules are not written as code by default")
    if emit(psc, game, "--emit", "cpp", "--rules", "table") != cpp_table:
        failures.append("--emit cpp --rules table printed different bytes the second time")
    if emit(psc, game, "--emit", "cpp", "--levels", "0") != cpp_level0:
        failures.append("--emit cpp --levels 0 printed different bytes the second time")
    for f in failures:
        print("FAIL:", f)
    if not failures:
        print(f"{game}: --levels 0 boards {words(cpp_level0)} words (all levels {words(cpp_all)}), headers and bytes as expected")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
