#!/usr/bin/python3
"""The groups layout (--gpu-state groups, templates/core.h): each rule group is
compiled with its rules inlined, on a copy of the state that ptxas keeps in
registers.  For each game:

- the groups on a copy, and the rules they inline, are defined in units
  1..PSC_GROUP_UNITS; functions that work in place (groups apart, and a split
  group's pass over its parts) are not on a copy;
- a group larger than the part budget passes over parts of its rules, and the
  parts call the rules in the order the memory layout's group calls them;
- no unit of 1..PSC_GROUP_UNITS is empty;
- NVRTC compiles and links every unit, and no group on a copy keeps a frame
  in local memory (the copy stayed in registers);
- with spans (PSC_GROUP_SPANS: no loops, rigid bodies or groups apart), each
  unit's early groups and its late groups run as one function on one copy,
  the groups in place with their rules in the span's unit; the spans, in the
  turn's order, call the groups in the memory layout's order, unsplit, and
  no span keeps its copy in local memory; the plugin's CPU backend, compiled
  from the same source, steps as the CPU plugin does.

    cuda_groups_layout.py PSC GAME... [--large-group GAME]

--large-group builds that game with one group of many rules added, which
must be split into parts."""
import argparse
import os
import random
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
import numpy as np  # noqa: E402
from psc import Plugin, _abi  # noqa: E402
from psc.batch import Batch  # noqa: E402

SPAN = re.compile(r"^\s*PSC_DEVICE PSC_SPAN void (\w+)\(Env& env, Turn& turn\) \{\n\s*PSC_GROUP_WORKING_COPY\(env, turn\);", re.M)
GROUP = re.compile(r"^\s*PSC_DEVICE PSC_GROUP bool (\w+)\(Env& env, Turn& turn\) \{\n\s*(PSC_GROUP_\w+)\(env, turn\);", re.M)
RULE = re.compile(r"^\s*PSC_DEVICE PSC_RULE bool (\w+)\(Env& e, Turn& t\) \{", re.M)


def units_of(source):
    """{unit: text} of the #if PSC_COMPILES_UNIT(k) blocks."""
    return {int(m.group(1)): m.group(2)
            for m in re.finditer(r"^#if PSC_COMPILES_UNIT\((\d+)\)\n(.*?)^#endif  // compile unit", source, re.M | re.S)}


def calls(body_start, source):
    """The functions a group body calls with `any |= f(e, t);` (or `any |= (PSC_RULE_NEEDS(...) && f(e, t));`), up to its `return`."""
    end = source.index("\n    }\n", body_start)
    return re.findall(r"any \|= (?:\(PSC_RULE_NEEDS\(.*?\) && )?(\w+)\(e, t\)\)?;", source[body_start:end])


def direction_copies(rule, source):
    """The copies a direction set's function (RuleCode's emitDirectionSet) calls, or [rule] for a rule."""
    m = re.search(rf"PSC_RULE(?:_APART)? bool {rule}\(Env& e, Turn& t\) \{{", source)
    if not rule.endswith("_directions") or m is None:
        return [rule]
    end = source.index("\n    }\n", m.end())
    return re.findall(r"changed \|= (?:\(PSC_RULE_NEEDS\(.*?\) && )?(\w+)\(e, t\)\)?;", source[m.end():end])


def rules_elsewhere(body_start, text):
    """The rules the group starting at body_start calls that its unit's text does not define."""
    return [r for r in calls(body_start, text) if not re.search(rf"PSC_RULE bool {r}\(Env& e, Turn& t\) \{{", text)]


def turn_calls(source, function):
    """The functions applyEarlyRules or applyLateRules calls, in order (a group `g(e, t)` or a span)."""
    m = re.search(rf"PSC_TURN void {function}\(Env& e, Turn& t\) \{{\n(.*?)\n    \}}\n", source, re.S)
    return re.findall(r"(\w+)\(e, t\)", m.group(1)) if m else []


def check_spans(name, source, units, copy_units, memory, failures):
    """The spans' structure and order; returns the functions on a copy (the spans)."""
    spans = {}
    for k, text in units.items():
        for m in SPAN.finditer(text):
            end = text.index("\n    }\n", m.end())
            groups = re.findall(r"(\w+)\(e, t\);", text[m.end():end])
            spans[m.group(1)] = groups
            if not 1 <= k <= copy_units:
                failures.append(f"{name}: span {m.group(1)} in unit {k}, past unit {copy_units}")
            for g in groups:
                body = re.search(rf"PSC_GROUP bool {g}\(Env& env, Turn& turn\) \{{\n\s*(PSC_GROUP_\w+)\(env, turn\);", text)
                if body is None:
                    failures.append(f"{name}: span {m.group(1)} calls {g}, not defined in its unit {k}")
                    continue
                if body.group(1) != "PSC_GROUP_IN_PLACE":
                    failures.append(f"{name}: {g} in a span makes a copy of its own ({body.group(1)})")
                missing = rules_elsewhere(body.end(), text)
                if missing:
                    failures.append(f"{name}: {g} calls rules defined in another unit: {missing}")
                if re.search(r"_part\d+\(", text[body.end():text.index("\n    }\n", body.end())]):
                    failures.append(f"{name}: {g} is split into parts inside a span")
    for phase in ("applyEarlyRules", "applyLateRules"):
        order = [g for span in turn_calls(source, phase) for g in spans.get(span, ["<missing " + span + ">"])]
        reference = turn_calls(memory, phase)
        if order != reference:
            failures.append(f"{name}: {phase}'s spans call {order}, the memory layout's turn {reference}")
    if not spans:
        failures.append(f"{name}: PSC_GROUP_SPANS is set and no span was emitted")
    return list(spans)


def observations(path, steps=1500, envs=4):
    """What envs environments on the CPU backend show after each of `steps` random inputs (auto reset)."""
    batch = Batch(Plugin(path), envs, _abi.BACKEND_CPU, 1, 0, 1, 0)
    batch.reset([0] * envs, [1] * envs)
    rng = random.Random(7)
    shown = []
    for _ in range(steps):
        batch.step([rng.randrange(5) for _ in range(envs)])
        shown.append(batch.observe().copy())
    return np.stack(shown)


def check_cpu_steps(psc, game, failures):
    """The spans plugin's CPU backend (compiled from the CUDA source's units) against the CPU plugin."""
    name = os.path.basename(game)
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, XDG_CACHE_HOME=tmp)
        built = {}
        for target, options in (("cpu", []), ("all", ["--gpu-state", "groups"])):
            path = os.path.join(tmp, f"{target}.so")
            r = subprocess.run([psc, game, "--levels", "0", "-o", path, "--target", target, *options],
                               capture_output=True, text=True, timeout=600, env=env)
            if r.returncode:
                failures.append(f"{name}: --target {target} failed: {r.stderr[-800:]}")
                return
            built[target] = observations(path)
    if not np.array_equal(built["cpu"], built["all"]):
        failures.append(f"{name}: the spans plugin's CPU backend steps otherwise than the CPU plugin")


def emit(psc, game, *options, env=None):
    return subprocess.run([psc, game, "--levels", "0", *options], capture_output=True, text=True, timeout=600, env=env)


def check(psc, game, failures, expect_parts=False):
    name = os.path.basename(game)
    groups = emit(psc, game, "--emit", "cuda", "--gpu-state", "groups")
    memory = emit(psc, game, "--emit", "cuda", "--gpu-state", "memory", "--cuda-units", "1")
    if groups.returncode or memory.returncode:
        failures.append(f"{name}: --emit cuda failed: {groups.stderr[-800:]}{memory.stderr[-800:]}")
        return
    source = groups.stdout
    copy_units = int(re.search(r"^#define PSC_GROUP_UNITS (\d+)", source, re.M).group(1))
    if "#define PSC_STATE_IN_GROUPS 1" not in source or copy_units < 1:
        failures.append(f"{name}: not built in the groups layout ({copy_units} copy units)")
        return
    units = units_of(source)
    empty = [k for k in range(1, copy_units + 1) if not units.get(k, "").strip()]
    if empty:
        failures.append(f"{name}: compile units {empty} of 1..{copy_units} hold no code")
    on_copy, split = [], {}
    uses_spans = "#define PSC_GROUP_SPANS 1" in source
    if uses_spans:
        on_copy = check_spans(name, source, units, copy_units, memory.stdout, failures)
    else:
        for k, text in units.items():
            for m in GROUP.finditer(text):
                function, state = m.group(1), m.group(2)
                if state == "PSC_GROUP_WORKING_COPY":
                    on_copy.append(function)
                    if not 1 <= k <= copy_units:
                        failures.append(f"{name}: {function} works on a copy in unit {k}, past unit {copy_units}")
                    missing = rules_elsewhere(m.end(), text)
                    if missing:
                        failures.append(f"{name}: {function} calls rules defined in another unit: {missing}")
                elif re.search(r"_part\d+\(", text[m.end():text.index("\n    }\n", m.end())]):
                    split[function] = calls(m.end(), text)
        if not on_copy:
            failures.append(f"{name}: no group works on a copy")
    # The memory layout's groups call the same rules in the same order (a
    # direction set there, which the groups layout leaves out, by its copies).
    reference = {m.group(1): [copy for rule in calls(m.end(), memory.stdout) for copy in direction_copies(rule, memory.stdout)]
                 for m in GROUP.finditer(memory.stdout)}
    bodies = {m.group(1): calls(m.end(), text) for text in units.values() for m in GROUP.finditer(text)}
    for group, parts in split.items():
        flattened = [rule for part in parts for rule in bodies.get(part, ["<missing " + part + ">"])]
        if flattened != reference.get(group):
            failures.append(f"{name}: {group}'s parts call {flattened}, the memory layout's group {reference.get(group)}")
    if expect_parts and not uses_spans and not split:
        failures.append(f"{name}: its large group was not split into parts")
    with tempfile.TemporaryDirectory() as cache:
        ptx = emit(psc, game, "--emit", "ptx", "--gpu-state", "groups", "--verbose",
                   env=dict(os.environ, XDG_CACHE_HOME=cache))
    if ptx.returncode != 0:
        failures.append(f"{name}: NVRTC failed on the groups layout: {ptx.stderr[-1500:]}")
        return
    for function in on_copy:
        body = re.search(rf"^\.visible \.func\s+(?:\([^)]*\)\s*)?\w*{function}\w*\(.*?^\}}", ptx.stdout, re.M | re.S)
        if body is None:
            failures.append(f"{name}: {function} not found in the PTX")
        elif "__local_depot" in body.group(0):
            failures.append(f"{name}: {function} keeps its copy in local memory")
    if uses_spans:
        check_cpu_steps(psc, game, failures)
    print(f"{name}: {copy_units} copy units, {len(on_copy)} functions on a copy ({'spans' if uses_spans else 'groups'}), "
          f"{len(split)} groups split into parts")
    return on_copy


# Two small groups, then one of eleven rules, whose weight's midpoint lies past
# the second of four units: placed by that alone, unit 2 was left empty.
HEAVY_LAST = "\n".join(
    ["[ Player | Crate | Crate | Crate ] -> [ Player | Crate | Crate | Crate ]",
     "[ Crate | Player | Crate | Crate ] -> [ Crate | Player | Crate | Crate ]",
     "[ > Player | Crate ] -> [ > Player | > Crate ]"] +
    [f"+ [ > Player | Crate | {'| ' * k}Crate ] -> [ > Player | > Crate | {'| ' * k}Crate ]" for k in range(10)])

LARGE_GROUP = "\n".join(
    ["[ > Player | Crate ] -> [ > Player | > Crate ]"] +
    [f"+ [ > Player | Crate | {'| ' * k}Crate ] -> [ > Player | > Crate | {'| ' * k}Crate ]" for k in range(12)])


def with_rules(game, tmp, rules_text, prefix):
    """The game with rules_text added at the start of its rules."""
    text = open(game).read()
    rules = re.search(r"^=+\s*\nRULES\s*\n=+\s*\n", text, re.M | re.I)
    path = os.path.join(tmp, prefix + os.path.basename(game))
    with open(path, "w") as f:
        f.write(text[:rules.end()] + rules_text + "\n" + text[rules.end():])
    return path


def check_spans_in_units(psc, game, units, failures):
    """check(), and where it passes, the game's spans lie in at least `units` compile units."""
    before = len(failures)
    spans = check(psc, game, failures)
    if len(failures) == before and len(set(re.findall(r"_rules_unit(\d+)", " ".join(spans or [])))) < units:
        failures.append(f"{os.path.basename(game)}: spans in fewer than {units} units: {spans}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("psc")
    ap.add_argument("games", nargs="+")
    ap.add_argument("--large-group")
    a = ap.parse_args()
    failures = []
    for game in a.games:
        check(a.psc, game, failures)
    if a.large_group:
        with tempfile.TemporaryDirectory() as tmp:
            check(a.psc, with_rules(a.large_group, tmp, LARGE_GROUP, "large_group_"), failures, expect_parts=True)
            # The same rules as groups of their own: spans over several units.
            check_spans_in_units(a.psc, with_rules(a.large_group, tmp, LARGE_GROUP.replace("\n+ ", "\n"), "many_groups_"),
                                 2, failures)
            check_spans_in_units(a.psc, with_rules(a.large_group, tmp, HEAVY_LAST, "heavy_last_"), 4, failures)
    for f in failures:
        print("FAIL", f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
