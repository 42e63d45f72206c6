"""Bad input never crashes or hangs psc: each case must end, within a time
limit, with a non-zero exit and a located error message, the expected one
where the case names it (bad command-line arguments: exit 2 and a message
naming the problem)."""
import os
import re
import subprocess
import sys
import tempfile

PSC = sys.argv[1]
TIMEOUT_S = 60
LOCATED = re.compile(r"^[^:\n]+(:\d+:\d+)?: error: ", re.M)

MINIMAL = """OBJECTS
Background
black
Player
blue
LEGEND
. = Background
P = Player
SOUNDS
COLLISIONLAYERS
Background
Player
RULES
WINCONDITIONS
LEVELS
.P
"""


def splitting_properties():
    """Ten objects on ten layers, a property of them all, and a rule of six
    cells of it: 10^6 concrete rules."""
    names = [f"Stone{i}" for i in range(10)]
    game = MINIMAL.replace("Player\nblue\n", "Player\nblue\n" + "".join(f"{n}\ngray\n" for n in names))
    game = game.replace("P = Player\n", "P = Player\nStone = " + " or ".join(names) + "\n")
    game = game.replace("Player\nRULES", "Player\n" + "\n".join(names) + "\nRULES")
    return game.replace("RULES\n", "RULES\n[ " + " | ".join(["Stone"] * 6) + " ] -> [ " + " | ".join([""] * 6) + " ]\n")


def cases():
    yield "empty file", b""
    yield "binary garbage", bytes((i * 7919 + 13) % 256 for i in range(200_000))
    yield "50 MB file", b"a" * (50 * 1024 * 1024)
    yield "unterminated comment", MINIMAL.replace("RULES", "RULES\n(never closed").replace("LEVELS\n.P\n", "").encode()
    yield "missing sections", b"OBJECTS\nBackground\nblack\n\nLEVELS\n.\n"
    yield "unknown names", MINIMAL.replace("RULES\n", "RULES\n[ Ghost ] -> [ Player ]\n").encode()
    yield "absurd level size", (MINIMAL + ("." * 2000 + "\n") * 1000).encode()
    yield "deeply nested comments", ("(" * 100_000 + "\n" + MINIMAL).encode()
    yield "very long line", MINIMAL.replace("RULES\n", "RULES\n" + "[ Player ] " * 200_000 + "\n").encode()
    yield "rules splitting into millions (properties)", splitting_properties().encode(), "more than 65536 rules"
    yield "rules splitting into millions (movements)", MINIMAL.replace(
        "RULES\n", "RULES\n[ " + " | ".join(["moving Player"] * 8) + " ] -> [ " + " | ".join(["Player"] * 8) + " ]\n").encode(), "more than 65536 rules"
    yield "NUL bytes", MINIMAL.replace("Player\nblue", "Pla\0yer\nblue").encode()


GAME = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "games", "sokoban.txt")


def argument_cases():
    """Command lines psc refuses before building anything: exit 2 and a message naming the problem."""
    yield ["bench", GAME, "--devices", "0,1"], "--devices needs --backend cuda"
    yield ["bench", GAME, "--backend", "cuda", "--devices", "0,0"], "devices must be distinct"
    yield ["bench", GAME, "--backend", "cuda", "--devices", "0,-1"], "devices must be distinct"
    yield ["bench", GAME, "--backend", "cuda", "--devices", "0,1", "--expand"], "--expand measures one device"
    yield ["bench", GAME, "--backend", "cuda", "--devices", "0", "--device", "1"], "excludes"
    yield ["bench", GAME, "--device", "-1"], "--device"
    yield ["solve", GAME, "--device", "-2"], "--device"


def main():
    failures = 0
    for args, expected in argument_cases():
        r = subprocess.run([PSC] + args, capture_output=True, timeout=TIMEOUT_S)
        err = r.stderr.decode("utf-8", "replace")
        ok = r.returncode == 2 and expected in err
        print(f"{'ok  ' if ok else 'FAIL'} psc {' '.join(args[:1] + args[2:])}: exit {r.returncode}; {err.strip()[:120]}")
        failures += 0 if ok else 1
    with tempfile.TemporaryDirectory() as tmp:
        for name, data, *message in cases():
            path = os.path.join(tmp, "game.txt")
            with open(path, "wb") as f:
                f.write(data)
            try:
                r = subprocess.run([PSC, "check", path], capture_output=True, timeout=TIMEOUT_S)
            except subprocess.TimeoutExpired:
                print(f"FAIL {name}: no answer within {TIMEOUT_S} s")
                failures += 1
                continue
            err = r.stderr.decode("utf-8", "replace")
            ok = r.returncode == 1 and LOCATED.search(err) is not None and all(m in err for m in message)
            shown = next((line for line in err.splitlines() if message and message[0] in line), err.splitlines()[0] if err else "(no message)")
            print(f"{'ok  ' if ok else 'FAIL'} {name}: exit {r.returncode}; {shown}"[:200])
            failures += 0 if ok else 1
    # Inputs the front-end fuzzer found (tests/fuzz/regressions/frontend):
    # an answer, an error or not, and no crash.
    regressions = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "fuzz", "regressions", "frontend")
    for name in sorted(os.listdir(regressions)):
        try:
            r = subprocess.run([PSC, "check", os.path.join(regressions, name)], capture_output=True, timeout=TIMEOUT_S)
            ok = r.returncode in (0, 1)
        except subprocess.TimeoutExpired:
            ok = False
        print(f"{'ok  ' if ok else 'FAIL'} fuzz regression {name}")
        failures += 0 if ok else 1
    sys.exit(1 if failures else 0)


main()
