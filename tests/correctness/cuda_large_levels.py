#!/usr/bin/python3
"""Games with large levels on the GPU: an environment too large for a
thread's stack is stepped where it lies in the batch, and so are its turns'
largest locals (templates/core.h, TurnScratch), so the kernels' stack stays
far below the 512 kB a thread that the driver allows (and reserves for every
thread the GPU can hold).

    cuda_large_levels.py PSC RIGID_GAME

The rigid-body game gets one level of about 38,000 cells (an environment of
about 130 kB: over the 128 kB kEnvInBatch bound); its CUDA code is compiled
(no GPU needed) with its rules as code, and with them as a table and a rule
of nine rows added (the table's visit of a rule's matches once kept three
boards a row on the stack: 240 kB here), and psc --verbose's bound on the
kernels' stack must stay under STACK_LIMIT."""
import os
import re
import subprocess
import sys
import tempfile

WIDTH, HEIGHT = 200, 190
STACK_LIMIT = 128 * 1024  # a quarter of the driver's 512 kB; such a game needed more than 512 kB before


def walled_level(width, height, middle):
    """A level of floor walled round, `middle` (legend characters) at the middle row's middle."""
    rows = ["#" * width]
    for y in range(1, height - 1):
        row = ["."] * width
        row[0] = row[-1] = "#"
        if y == height // 2:
            row[width // 2 - 1:width // 2 - 1 + len(middle)] = list(middle)
        rows.append("".join(row))
    rows.append("#" * width)
    return "\n".join(rows) + "\n"


NINE_ROWS = ("late [ Hole | Hole ]" + " [ Hole ]" * 8 + " -> [ | ]" + " [ Hole ]" * 8 + "\n")


def with_nine_row_rule(text):
    """The game `text` with NINE_ROWS as its first late rule."""
    at = text.index("late [")
    return text[:at] + NINE_ROWS + text[at:]


def with_level(text, level):
    """The game `text` with `level` as its only level."""
    return text[:text.index("LEVELS")] + "LEVELS\n=======\n\n" + level


def main():
    psc, rigid_game = sys.argv[1], sys.argv[2]
    text = open(rigid_game).read()
    failures = []
    with tempfile.TemporaryDirectory() as work:
        level = walled_level(WIDTH, HEIGHT, "PLRH")
        games = {"code": with_level(text, level), "table": with_level(with_nine_row_rule(text), level)}
        for rules, source in games.items():
            game = os.path.join(work, f"large_{rules}.txt")
            with open(game, "w") as f:
                f.write(source)
            r = subprocess.run([psc, game, "--emit", "ptx", "--verbose", "--rules", rules], capture_output=True, text=True,
                               timeout=600, env=dict(os.environ, XDG_CACHE_HOME=os.path.join(work, "cache-" + rules)))
            stack = re.search(r"kernels' stack: at most (\d+) bytes", r.stderr)
            words = re.search(r"constexpr int kWords = (\d+);", subprocess.run(
                [psc, game, "--emit", "cuda", "--rules", rules], capture_output=True, text=True, timeout=600).stdout)
            if r.returncode != 0 or not stack or not words:
                failures.append(f"rules as {rules}: the build failed or printed no stack bound: {r.stderr[-800:]}")
                continue
            print(f"rules as {rules}: {words.group(1)} words a board, kernels' stack at most {stack.group(1)} bytes a thread")
            if int(stack.group(1)) > STACK_LIMIT:
                failures.append(f"rules as {rules}: the kernels need {stack.group(1)} bytes of stack a thread, over {STACK_LIMIT}")
    for f in failures:
        print("FAIL", f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
