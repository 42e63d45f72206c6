#!/usr/bin/python3
"""setGeometry (templates/core.h) builds a level's masks a board at a time:
`inside` holds every position x * (height + 1) + y with x < width and
y < height, and `rowStart` those with y == 0.  This compiles the generated
CPU source of a small game whose one level makes boards of 1, 2, 4 and 20
words (the single-word, selected-word and indexed-word code of Board), and
checks both masks against that definition for every level size the boards
hold.

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
    int sizes = 0, wrong = 0;
    for (int width = 1; width <= 64 * kWords; ++width) {
        for (int height = 1; width * (height + 1) <= 64 * kWords; ++height) {
            Env e{};
            setGeometry(e, width, height);
            for (int p = 0; p < 64 * kWords; ++p) {
                const int x = p / (height + 1), y = p % (height + 1);
                const bool inside = x < width && y < height;
                const bool rowStart = x < width && y == 0;
                if (e.inside.test(p) != inside || e.rowStart.test(p) != rowStart) {
                    if (wrong++ < 5) std::printf("width %d height %d: position %d wrong\n", width, height, p);
                    break;
                }
            }
            ++sizes;
        }
    }
    std::printf("%d words: %d level sizes, %d wrong\n", kWords, sizes, wrong);
    return wrong != 0;
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
            rows = ["#" * width] + ["#" + "." * (width - 2) + "#"] * (height - 2) + ["#" * width]
            rows[1] = "#P" + rows[1][2:]
            game = os.path.join(tmp, f"masks_{words}.txt")
            with open(game, "w") as f:
                f.write(GAME + "\n".join(rows) + "\n")
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
