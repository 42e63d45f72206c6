#!/usr/bin/python3
"""A level's start gives the environment its geometry masks (the level tables
that codegen/CppSource.cpp writes, copied by loadLevelCells): `inside` holds
every position x * (height + 1) + y with x < width and y < height, and
`rowStart` those with y == 0.  This compiles the generated CPU source of
small games whose largest level makes boards of 1, 2, 4 and 20 words (the
single-word, selected-word and indexed-word code of Board), each with levels
of many sizes below it, and checks both masks of every level against that
definition.

    level_masks.py PSC CXX"""
import os
import subprocess
import sys
import tempfile

CHECK = r"""
namespace psc_host { int64_t steadyNanoseconds() { return 0; } }
#include <cstdio>
int main() {
    using namespace psc_game;
    int levels = 0, wrong = 0;
    for (int entry = 0; entry < kEntries; ++entry) {
        Env e{};
        loadLevelCells(e, entry);
        const int width = kEntryWidth[entry], height = kEntryHeight[entry];
        if (e.width != width || e.height != height) {
            if (wrong++ < 5) std::printf("level %d: size %dx%d, not %dx%d\n", entry, e.width, e.height, width, height);
            continue;
        }
        for (int p = 0; p < 64 * kWords; ++p) {
            const int x = p / (height + 1), y = p % (height + 1);
            const bool inside = x < width && y < height;
            const bool rowStart = x < width && y == 0;
            if (e.inside.test(p) != inside || e.rowStart.test(p) != rowStart) {
                if (wrong++ < 5) std::printf("level %d (%dx%d): position %d wrong\n", entry, width, height, p);
                break;
            }
        }
        ++levels;
    }
    std::printf("%d words: %d level sizes, %d wrong\n", kWords, levels, wrong);
    return wrong != 0 || levels != kEntries;
}
"""


GAME = """title Level masks

========
OBJECTS
========

Background
black

Wall
white

Player
blue

=======
LEGEND
=======

. = Background
# = Wall
P = Player

=======
SOUNDS
=======

================
COLLISIONLAYERS
================

Background
Player, Wall

======
RULES
======

==============
WINCONDITIONS
==============

=======
LEVELS
=======

"""


def main():
    psc, cxx = sys.argv[1:3]
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        for width, height, words in ((5, 5, 1), (9, 9, 2), (15, 15, 4), (40, 31, 20)):
            # The largest level, then every size whose columns fit its boards
            # in steps that cross word boundaries at many offsets.
            sizes = [(width, height)] + [(w, h) for w in range(1, 64 * words, 3) for h in range(1, 40, 4)
                                         if w * (h + 1) <= width * (height + 1)]
            levels = []
            for w, h in sizes:
                rows = ["." * w] * h
                rows[0] = "P" + rows[0][1:]
                levels.append("\n".join(rows))
            game = os.path.join(tmp, f"masks_{words}.txt")
            with open(game, "w") as f:
                f.write(GAME + "\n\n".join(levels) + "\n")
            r = subprocess.run([psc, game, "--emit", "cpp"], capture_output=True, text=True, timeout=120)
            if r.returncode or f"constexpr int kWords = {words};" not in r.stdout:
                failures.append(f"{width}x{height}: --emit cpp failed or not {words} words: {r.stderr[-500:]}")
                continue
            source = os.path.join(tmp, f"masks_{words}.cpp")
            with open(source, "w") as f:
                f.write(r.stdout + CHECK)
            binary = os.path.join(tmp, f"masks_{words}")
            r = subprocess.run([cxx, "-std=c++20", "-O1", "-w", source, "-o", binary], capture_output=True, text=True,
                               timeout=600)
            if r.returncode:
                failures.append(f"{words} words: compiling the check failed: {r.stderr[-1500:]}")
                continue
            r = subprocess.run([binary], capture_output=True, text=True, timeout=120)
            print(r.stdout.strip())
            if r.returncode:
                failures.append(f"{words} words: masks differ from their definition")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
