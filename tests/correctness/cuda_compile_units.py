#!/usr/bin/python3
"""CUDA compile units (templates/core.h): a game's CUDA source split over
several NVRTC programs must define each rule and group function in exactly one
unit, the kernels in unit 0 and the turn in the last unit (PSC_TURN_UNIT)
alone, link into one cubin, and come out the same every time.  The registers
layout's two units: the stepping kernel alone in unit 0, the other kernels
and the level changes it calls in unit 1.  Rules as a table (`--rules
table`): two units, the kernels in unit 0 and the turn, with the table's
interpreter, in unit 1 alone, so that no kernel inlines the turn.

    cuda_compile_units.py PSC GAME... [--units N]

Each game is built with the memory layout (the one whose rules are split)
and N units (the turn's among them), or fewer where it has fewer rule and
group functions, and with the registers layout.  The memory layout inlines a
group's rules into it, unless the group is heavier than kInlinedGroupWeight
(codegen/CppSource.cpp): the last game, given a level of 5-word boards and a
group of many rules, must keep that group's rules out of line and the other
group's rules in its unit, and compile and link."""
import argparse
import os
import re
import subprocess
import sys
import tempfile

DEFINITION = re.compile(r"^\s*PSC_DEVICE PSC_(?:RULE|GROUP) [\w ]+? (\w+)\([^;]*\) \{$")
DECLARATION = re.compile(r"^\s*PSC_DEVICE PSC_(?:RULE|GROUP) [\w ]+? (\w+)\([^{]*\);$")


# What the turn's unit compiles (PSC_TURN), out of every other unit.
TURN_FUNCTIONS = {"playTurn", "applyEarlyRules", "applyLateRules"}


def demangled(symbol):
    """The function's name in a psc_game symbol (_ZN8psc_game8playTurnE... -> playTurn)."""
    m = re.match(r"_ZN8psc_game(\d+)(\w+)", symbol)
    return m.group(2)[:int(m.group(1))] if m else symbol


def unit_definitions(source):
    """{unit: [function names defined in it]} from the #if PSC_COMPILES_UNIT(k) blocks."""
    units, unit = {}, None
    for line in source.splitlines():
        opened = re.match(r"#if PSC_COMPILES_UNIT\((\d+)\)", line)
        if opened:
            unit = int(opened.group(1))
            units.setdefault(unit, [])
        elif line.startswith("#endif  // compile unit"):
            unit = None
        elif unit is not None:
            m = DEFINITION.match(line)
            if m:
                units[unit].append(m.group(1))
    return units


def linked_units(base, failures, game, units):
    """Each unit's PTX of a build linked from `units` units: (exported functions, entries) per unit."""
    with tempfile.TemporaryDirectory() as cache:
        ptx = subprocess.run(base + ["--emit", "ptx", "--verbose"], capture_output=True, text=True, timeout=600,
                             env=dict(os.environ, XDG_CACHE_HOME=cache))
    if ptx.returncode != 0 or f"{units} compile units at once" not in ptx.stderr:
        failures.append(f"{game}: compiling and linking {units} units failed: {ptx.stderr[-1500:]}")
        return None
    parts = re.split(r"^// ---- compile unit \d+ of \d+$", ptx.stdout, flags=re.M)[1:]
    if len(parts) != units:
        failures.append(f"{game}: {len(parts)} PTX units, expected {units}")
        return None
    visible = [re.findall(r"^\.visible \.func\s+(?:\([^)]*\)\s*)?(\w+)\(", p, re.M) for p in parts]
    entries = [sorted(re.findall(r"^\.visible \.entry (\w+)\(", p, re.M)) for p in parts]
    return visible, entries


def check(psc, game, units, failures):
    base = [psc, game, "--levels", "0", "--gpu-state", "memory", "--cuda-units", str(units)]
    first = subprocess.run(base + ["--emit", "cuda"], capture_output=True, text=True, timeout=120)
    second = subprocess.run(base + ["--emit", "cuda"], capture_output=True, text=True, timeout=120)
    if first.returncode != 0 or first.stdout != second.stdout:
        failures.append(f"{game}: --emit cuda failed or differs between runs: {first.stderr[-500:]}")
        return
    source = first.stdout
    declared = [m.group(1) for m in map(DECLARATION.match, source.splitlines()) if m]
    defined = unit_definitions(source)
    names = [n for fs in defined.values() for n in fs]
    declared_units = re.search(r"^#define PSC_COMPILE_UNITS (\d+)", source, re.M)
    units = int(declared_units.group(1)) if declared_units else 1
    turn_unit = re.search(r"^#define PSC_TURN_UNIT (\d+)", source, re.M)
    turn_unit = int(turn_unit.group(1)) if turn_unit else 0
    if units < 3 or turn_unit != units - 1 or sorted(defined) != list(range(1, units - 1)):
        failures.append(f"{game}: expected the kernels alone in unit 0, rules in units 1..{units - 2} and the turn "
                        f"in unit {units - 1}, found rule units {sorted(defined)} and the turn in unit {turn_unit}")
        return
    if sorted(names) != sorted(set(names)) or sorted(names) != sorted(declared):
        failures.append(f"{game}: rule/group functions not defined exactly once each "
                        f"({len(names)} defined, {len(set(names))} distinct, {len(declared)} declared)")
    linked = linked_units(base, failures, game, units)
    if not linked:
        return
    visible, entries = linked
    everywhere = [n for v in visible for n in v]
    if len(everywhere) != len(set(everywhere)):
        failures.append(f"{game}: a function is defined in two units' PTX")
    elif entries[0] != ["psc_observe_kernel", "psc_reset_kernel", "psc_run_kernel"] or any(entries[1:]):
        failures.append(f"{game}: the kernels must all be in unit 0, found {entries}")
    elif not TURN_FUNCTIONS <= {demangled(n) for n in visible[turn_unit]}:
        failures.append(f"{game}: the turn's unit {turn_unit} does not export {sorted(TURN_FUNCTIONS)}: "
                        f"{sorted(demangled(n) for n in visible[turn_unit])}")
    print(f"{os.path.basename(game)}: {units} units, {len(names)} rule/group functions, "
          f"{len(everywhere)} exported from the PTX units")


def check_registers(psc, game, failures):
    base = [psc, game, "--levels", "0", "--gpu-state", "registers"]
    source = subprocess.run(base + ["--emit", "cuda"], capture_output=True, text=True, timeout=120).stdout
    if "#define PSC_COMPILE_UNITS 2 " not in source:
        failures.append(f"{game}: the registers layout should compile as two units")
        return
    linked = linked_units(base, failures, game, 2)
    if not linked:
        return
    visible, entries = linked
    exported = [{demangled(n) for n in v} for v in visible]
    if entries != [["psc_run_kernel"], ["psc_observe_kernel", "psc_reset_kernel"]]:
        failures.append(f"{game}: registers layout: expected the stepping kernel alone in unit 0, found {entries}")
    elif exported[0] or not {"stepEvent", "nextLevel"} <= exported[1]:
        failures.append(f"{game}: registers layout: the level changes must be exported from unit 1 alone, "
                        f"found {exported}")
    else:
        print(f"{os.path.basename(game)}: registers layout in 2 units, unit 1 exports {sorted(exported[1])}")


def check_table(psc, game, failures):
    base = [psc, game, "--levels", "0", "--rules", "table"]
    source = subprocess.run(base + ["--emit", "cuda"], capture_output=True, text=True, timeout=120).stdout
    if "#define PSC_COMPILE_UNITS 2 " not in source or "#define PSC_TURN_UNIT 1 " not in source:
        failures.append(f"{game}: rules as a table should compile as two units, the turn in unit 1")
        return
    linked = linked_units(base, failures, f"{game}, table", 2)
    if not linked:
        return
    visible, entries = linked
    exported = [{demangled(n) for n in v} for v in visible]
    if entries[0] != ["psc_observe_kernel", "psc_reset_kernel", "psc_run_kernel"] or entries[1]:
        failures.append(f"{game}: rules as a table: the kernels must all be in unit 0, found {entries}")
    elif not TURN_FUNCTIONS <= exported[1] or TURN_FUNCTIONS & exported[0]:
        failures.append(f"{game}: rules as a table: the turn must be exported from unit 1 alone, found {exported}")
    else:
        print(f"{os.path.basename(game)}: rules as a table in 2 units, unit 1 exports {sorted(TURN_FUNCTIONS)}")


# A group of LONG_GROUP_RULES rules (each in four directions), heavier than
# kInlinedGroupWeight over 5-word boards; the game's own rules stay a small group.
LONG_GROUP_RULES = 12


def with_long_group_and_large_level(text):
    """The game `text` with a group of LONG_GROUP_RULES pushes of crate rows added and
    one level of 20 x 14 cells (300 positions: 5 words a board)."""
    rules = ["[ > Player" + " | Crate" * (k + 1) + " | no Wall ] -> [ > Player" + " | > Crate" * (k + 1) + " | ]"
             for k in range(LONG_GROUP_RULES)]
    group = "\n".join(rules[:1] + ["+ " + r for r in rules[1:]]) + "\n"
    at = text.index("==============\nWINCONDITIONS")
    text = text[:at] + group + "\n" + text[at:]
    rows = ["#" * 20] + ["#" + "." * 18 + "#" for _ in range(12)] + ["#" * 20]
    rows[6] = "#..P.*.O" + "." * 11 + "#"
    return text[:text.index("LEVELS")] + "LEVELS\n=======\n\n" + "\n".join(rows) + "\n"


def group_units(source):
    """({rule name: (unit, out of line)}, {group name: (unit, [rules it calls])}) of a memory-layout source."""
    rules, groups, unit, group = {}, {}, None, None
    for line in source.splitlines():
        opened = re.match(r"#if PSC_COMPILES_UNIT\((\d+)\)", line)
        if opened:
            unit = int(opened.group(1))
        elif line.startswith("#endif  // compile unit"):
            unit = None
        elif unit is not None:
            m = re.match(r"^\s*PSC_DEVICE (PSC_RULE|PSC_RULE_APART) bool (\w+)\(Env& e, Turn& t\) \{$", line)
            if m:
                rules[m.group(2)] = (unit, m.group(1) == "PSC_RULE_APART")
            m = re.match(r"^\s*PSC_DEVICE PSC_GROUP bool (\w+)\(Env& env, Turn& turn\) \{$", line)
            if m:
                group = m.group(1)
                groups[group] = (unit, [])
            elif group and line.strip() == "}":
                group = None
            elif group:
                groups[group][1].extend(re.findall(r"(\w+)\(e, t\)", line))
    return rules, groups


def check_inlined_groups(psc, game, failures):
    with tempfile.TemporaryDirectory() as work:
        path = os.path.join(work, "long_group.txt")
        with open(path, "w") as f:
            f.write(with_long_group_and_large_level(open(game).read()))
        base = [psc, path, "--levels", "0", "--gpu-state", "memory"]
        source = subprocess.run(base + ["--emit", "cuda"], capture_output=True, text=True, timeout=120).stdout
        if "constexpr int kWords = 5;" not in source:
            failures.append(f"{game}, long group: expected 5-word boards")
            return
        rules, groups = group_units(source)
        apart = {g for g, (_, called) in groups.items() if any(rules.get(r, (0, False))[1] for r in called)}
        inlined = {g for g, (_, called) in groups.items() if any(r in rules and not rules[r][1] for r in called)}
        if len(apart) != 1 or apart & inlined or not inlined:
            failures.append(f"{game}, long group: expected one group with its rules out of line and the others' "
                            f"inlined, found out of line {sorted(apart)}, inlined {sorted(inlined)}")
            return
        for g, (unit, called) in groups.items():
            strays = [r for r in called if r in rules and not rules[r][1] and rules[r][0] != unit]
            if strays:
                failures.append(f"{game}, long group: {g} (unit {unit}) inlines {strays} from other units")
        units = int(re.search(r"^#define PSC_COMPILE_UNITS (\d+)", source, re.M).group(1))
        if linked_units(base, failures, f"{game}, long group", units):
            print(f"{os.path.basename(game)} with a long group: {sorted(apart)} calls its rules, "
                  f"{len(inlined)} groups inline theirs, {units} units linked")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("psc")
    ap.add_argument("games", nargs="+")
    ap.add_argument("--units", type=int, default=4)
    a = ap.parse_args()
    failures = []
    for game in a.games:
        check(a.psc, game, a.units, failures)
        check_registers(a.psc, game, failures)
        check_table(a.psc, game, failures)
    check_inlined_groups(a.psc, a.games[-1], failures)
    for f in failures:
        print("FAIL", f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
