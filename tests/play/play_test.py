#!/usr/bin/env python3
"""psc play in a real terminal: tmux runs it, send-keys types, capture-pane reads the screen.

Usage: play_test.py PSC GAMES_DIR

Covers: games/sokoban.txt's first level solved with arrow keys and on to the
next level, the message screen before it, undo and restart, Q / Ctrl-C /
SIGTERM and a crash leaving the terminal as it was (main screen, cursor, cooked mode),
progress kept between runs, a resize redrawing the level as glyphs, the hint
key, and the --scripted, --replay, --record and bad-argument paths; and
games/kick.txt's `again` chain drawn a turn at a time, with the message its
rule shows held until X.
"""
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

PSC = os.path.abspath(sys.argv[1])
GAMES = os.path.abspath(sys.argv[2])
SOKOBAN = os.path.join(GAMES, "sokoban.txt")
# kick.txt level 1 is #P.o...G#: two steps right kick the ball, which rolls a cell per again turn into the goal.
KICK = os.path.join(GAMES, "kick.txt")
# Level 0 of sokoban.txt: the player goes round the crate's left and pushes it right onto the target.
HAND_SOLUTION = ["Left", "Left", "Up", "Right"]


def solver_solution():
    """psc solve's shortest solution of sokoban.txt level 0, as tmux key names (the issue's bar types it)."""
    r = subprocess.run([PSC, "solve", SOKOBAN, "--level", "0", "--format", "json", "--quiet"],
                       capture_output=True, text=True, timeout=600)
    record = json.loads(r.stdout.splitlines()[0]) if r.stdout.strip() else {}
    keys = {"u": "Up", "d": "Down", "l": "Left", "r": "Right", "x": "x"}
    return [keys[c] for c in record.get("solution") or ""]
LEVEL0_START = ["#######", "#.....#", "#.*O..#", "#..P..#", "#######"]

STATE = tempfile.mkdtemp(prefix="psc-play-test-")
ENV = dict(os.environ, XDG_STATE_HOME=STATE, COLORTERM="truecolor")
# The --scripted runs keep their progress apart from the tmux runs'.
SCRIPTED_ENV = dict(ENV, XDG_STATE_HOME=os.path.join(STATE, "scripted"))
SOCKET = "psc-play-test-%d" % os.getpid()

failures = []
passed = 0


def check(condition, what, detail=""):
    global passed
    if condition:
        passed += 1
        print("ok   " + what)
    else:
        failures.append(what)
        print("FAIL " + what + ("\n" + detail if detail else ""))


def tmux(*args, check_status=True):
    result = subprocess.run(["tmux", "-L", SOCKET, "-f", "/dev/null", *args], capture_output=True, text=True, env=ENV)
    if check_status and result.returncode != 0:
        raise RuntimeError("tmux %s: %s" % (" ".join(args), result.stderr))
    return result.stdout


class Pane:
    """A shell in a tmux window of a given size, in which commands are typed."""

    def __init__(self, columns=100, rows=30):
        tmux("kill-server", check_status=False)
        tmux("new-session", "-d", "-s", "play", "-x", str(columns), "-y", str(rows),
             "env -u PROMPT_COMMAND PS1='$ ' bash --norc --noprofile")
        self.wait_for(lambda s: "$" in s, "the shell's prompt")

    def screen(self):
        return tmux("capture-pane", "-p", "-t", "play")

    def lines(self):
        return self.screen().split("\n")

    def keys(self, *keys):
        for k in keys:
            tmux("send-keys", "-t", "play", k)
            time.sleep(0.05)

    def type_line(self, text):
        tmux("send-keys", "-t", "play", "-l", text)
        tmux("send-keys", "-t", "play", "Enter")

    def format(self, spec):
        return tmux("display-message", "-p", "-t", "play", spec).strip()

    def wait_for(self, condition, what, timeout=20):
        deadline = time.time() + timeout
        while time.time() < deadline:
            s = self.screen()
            if condition(s):
                return True
            time.sleep(0.05)
        print("timed out waiting for %s; the screen:\n%s" % (what, self.screen()))
        return False

    def run_psc_play(self, *args):
        self.type_line("clear; ulimit -c 0; %s play %s; echo EXIT=$?" % (PSC, " ".join(args)))

    def exit_status(self, timeout=20):
        if not self.wait_for(lambda s: "EXIT=" in s, "psc play to exit", timeout):
            return None
        for line in self.lines():
            if line.startswith("EXIT="):
                return int(line[5:])
        return None

    def close(self):
        tmux("kill-server", check_status=False)
        socket = os.path.join(os.environ.get("TMUX_TMPDIR", "/tmp"), "tmux-%d" % os.getuid(), SOCKET)
        if os.path.exists(socket):
            os.remove(socket)


def terminal_restored(pane, what):
    """After psc play: main screen, cursor shown, and the line discipline cooked again."""
    check(pane.format("#{alternate_on}") == "0", what + ": back on the main screen")
    check(pane.format("#{cursor_flag}") == "1", what + ": the cursor is shown")
    pane.type_line("clear; echo \"modes: $(stty -a | tr ' ;' '\\n\\n' | grep -x -e icanon -e -icanon -e echo -e -echo "
                   "-e isig -e -isig | sort | tr '\\n' ' ')\"")
    answer = lambda: [l for l in pane.lines() if l.startswith("modes: ")]
    ok = pane.wait_for(lambda s: answer(), "stty's answer")
    check(ok and answer()[-1].split() == ["modes:", "echo", "icanon", "isig"],
          what + ": echo, icanon and isig are on again", pane.screen())


def children_running(parent, argument):
    """The processes whose parent is `parent` and whose command line has `argument`."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            with open("/proc/%s/cmdline" % entry, "rb") as f:
                args = f.read().split(b"\0")
        except (OSError, ValueError, IndexError):
            continue
        if ppid == parent and argument.encode() in args:
            found.append(int(entry))
    return found


def level_rows(pane):
    """The glyph rows of the level (lines made of the level's glyphs)."""
    return [l.strip() for l in pane.lines()[1:-1] if l.strip() and set(l.strip()) <= set("#.*@OP")]


def scripted(*args, keys=b"", timeout=120, game=SOKOBAN):
    return subprocess.run([PSC, "play", game, "--scripted", *args], input=keys, capture_output=True,
                          timeout=timeout, env=SCRIPTED_ENV)


def kick_row(pane):
    """Level 1 of kick.txt's row with the player, as glyphs."""
    rows = [l.strip() for l in pane.lines()[1:-1] if l.strip().startswith("#") and "P" in l]
    return rows[0] if rows else None


def kick_tests():
    warm = scripted("--level", "0", game=KICK, timeout=600)
    check(warm.returncode == 0, "kick.txt: --scripted with no keys exits 0", warm.stderr.decode())
    pane = Pane()
    try:
        pane.run_psc_play(KICK, "--level", "0", "--glyphs")
        check(pane.wait_for(lambda s: kick_row(pane) == "#P.o...G#", "kick level 1"), "kick.txt: level 1 as glyphs")
        pane.keys("Right", "Right")
        frames = []
        deadline = time.time() + 10
        while time.time() < deadline and "Goal!" not in pane.screen():
            row = kick_row(pane)
            if row and (not frames or frames[-1] != row):
                frames.append(row)
            time.sleep(0.02)
        rolling = [f for f in frames if "R" in f]
        check(len(rolling) >= 2 and all(f.index("R") < g.index("R") for f, g in zip(rolling, rolling[1:])),
              "the again chain is drawn a turn at a time: the ball rolls right frame by frame", str(frames))
        check(pane.wait_for(lambda s: "Goal!" in s and "X to continue" in s and "message" in s.split("\n")[0],
                            "the rule's message"), "the rule's message is shown, with X to continue")
        pane.keys("Left")
        time.sleep(0.3)
        check("Goal!" in pane.screen(), "keys other than X leave the message shown")
        pane.keys("x")
        check(pane.wait_for(lambda s: "level 2 of 2" in s.split("\n")[0], "level 2"),
              "X closes the message: the level won with it gives way to level 2")
        pane.keys("q")
        check(pane.exit_status() == 0, "q exits with status 0 after the kick")
    finally:
        pane.close()

    out = scripted("--level", "0", game=KICK, keys=b"dddx").stdout.decode()
    lines = out.split("\n")
    check("message: Goal!" in lines and "solved level 1" in lines and
          lines.index("message: Goal!") < lines.index("solved level 1"),
          "--scripted: the rule's message comes before the win, as the reference checks it on closing", out)
    check("Kick \u00b7 level 2 of 2 \u00b7 moves 0" in out,
          "--scripted: a key while the message shows is dropped, X goes on to level 2", out)
    replayed = scripted("--level", "0", "--replay", "rr", game=KICK).stdout.decode()
    check("message: Goal!" in replayed and "solved level 1" in replayed,
          "--replay waits for the again chain and shows the message", replayed)


def main():
    # Builds the plugin once (cached after), so that the timed waits below measure psc play itself.
    warm = scripted("--level", "0", timeout=600)
    check(warm.returncode == 0, "--scripted with no keys exits 0", warm.stderr.decode())
    solution = solver_solution()
    check(len(solution) == len(HAND_SOLUTION), "psc solve finds a shortest solution of level 1",
          f"{solution} against the hand-checked {HAND_SOLUTION}")

    pane = Pane()
    try:
        # The title screen, then the message screen before level 1, then level 1 solved with arrow keys.
        pane.run_psc_play(SOKOBAN)
        check(pane.wait_for(lambda s: "start game" in s, "the title screen"), "the title screen shows")
        pane.keys("x")
        check(pane.wait_for(lambda s: "Push each crate onto a target." in s and "X to continue" in s,
                            "the message screen"), "the first entry's message screen shows")
        pane.keys("Enter")
        check(pane.wait_for(lambda s: "level 1 of 3" in s.split("\n")[0], "level 1"), "X closes the message: level 1 of 3")
        check(any("\u2580" in l for l in pane.lines()), "the level is drawn with half-block sprites")
        pane.keys(*solution)
        check(pane.wait_for(lambda s: "level 2 of 3" in s.split("\n")[0], "level 2"),
              "the solution typed as arrow keys moves on to level 2", pane.screen())
        pane.keys("q")
        check(pane.exit_status() == 0, "q exits with status 0")
        check("level 2 of 3" not in pane.screen(), "q leaves no trace of the game on the screen")
        terminal_restored(pane, "q")

        # Progress: level 1 solved, and the title screen offers to continue at level 2.
        files = os.listdir(os.path.join(STATE, "psc", "play"))
        progress = json.load(open(os.path.join(STATE, "psc", "play", files[0]))) if len(files) == 1 else {}
        check(progress.get("solved") == [0], "progress records level 1 as solved", str(progress))
        pane.run_psc_play(SOKOBAN)
        check(pane.wait_for(lambda s: "continue from level 2" in s, "continue"), "the title screen offers to continue at level 2")
        pane.keys("Enter")
        check(pane.wait_for(lambda s: "level 2 of 3" in s.split("\n")[0], "level 2"), "continue resumes at level 2")
        pane.keys("C-c")
        check(pane.exit_status() == 130, "Ctrl-C exits with status 130")
        terminal_restored(pane, "Ctrl-C")

        # Undo and restart, on the level drawn as glyphs.
        pane.run_psc_play(SOKOBAN, "--level", "0", "--glyphs")
        check(pane.wait_for(lambda s: level_rows(pane) == LEVEL0_START, "level 1 as glyphs"), "--glyphs draws the legend's glyphs")
        pane.keys("Left")
        check(pane.wait_for(lambda s: "moves 1" in s.split("\n")[0], "a move"), "a move counts")
        check(level_rows(pane)[3] == "#.P...#", "the player moved left", "\n".join(level_rows(pane)))
        pane.keys("z")
        check(pane.wait_for(lambda s: "moves 0" in s.split("\n")[0] and level_rows(pane) == LEVEL0_START, "undo"),
              "Z undoes the move")
        pane.keys("Left", "Left", "Up")
        check(pane.wait_for(lambda s: "moves 3" in s.split("\n")[0], "three moves"), "three moves count")
        pane.keys("r")
        check(pane.wait_for(lambda s: "moves 0" in s.split("\n")[0] and level_rows(pane) == LEVEL0_START, "restart"),
              "R restarts the level")
        pane.keys("z")
        check(pane.wait_for(lambda s: "moves 3" in s.split("\n")[0], "undo of restart"), "Z after R goes back to before the restart")

        # A smaller terminal: the level no longer fits as sprites; drawn again, as glyphs.
        pane.keys("Escape")
        check(pane.wait_for(lambda s: "continue from level" in s or "start game" in s, "title"), "Esc goes back to the title screen")
        pane.keys("Enter")
        tmux("resize-window", "-t", "play", "-x", "100", "-y", "30")
        pane.wait_for(lambda s: "level 1 of 3" in s.split("\n")[0], "level 1")
        pane.keys("n")
        check(pane.wait_for(lambda s: "level 2 of 3" in s.split("\n")[0], "next level"), "N goes to the next level")
        pane.keys("p")
        check(pane.wait_for(lambda s: "level 1 of 3" in s.split("\n")[0], "previous level"), "P goes to the previous level")
        pane.keys("l")
        check(pane.wait_for(lambda s: "Level select" in s and "1*" in s, "level select"), "L shows the level select, level 1 marked solved")
        pane.keys("Right", "Right", "Enter")
        check(pane.wait_for(lambda s: "level 3 of 3" in s.split("\n")[0], "level 3"), "the level select starts the chosen level")
        children = children_running(int(pane.format("#{pane_pid}")), "play")
        check(len(children) == 1, "psc play runs in the pane's shell", str(children))
        if children:
            os.kill(children[0], signal.SIGTERM)
        check(pane.exit_status() == 143, "SIGTERM exits with status 143")
        terminal_restored(pane, "SIGTERM")

        # A crash: the terminal is restored before the signal's default action.
        pane.run_psc_play(SOKOBAN, "--level", "0")
        pane.wait_for(lambda s: "level 1 of 3" in s.split("\n")[0], "level 1")
        for child in children_running(int(pane.format("#{pane_pid}")), "play"):
            os.kill(child, signal.SIGSEGV)
        check(pane.exit_status() == 139, "SIGSEGV ends psc play with status 139")
        terminal_restored(pane, "SIGSEGV")
    finally:
        pane.close()

    # A window too small for sprites: glyphs, redrawn when it grows.
    pane = Pane(columns=40, rows=12)
    try:
        pane.run_psc_play(SOKOBAN, "--level", "2")
        check(pane.wait_for(lambda s: "#########" in s, "glyphs"), "a small terminal shows the level as glyphs")
        tmux("resize-window", "-t", "play", "-x", "100", "-y", "40")
        check(pane.wait_for(lambda s: "\u2580" in s and "#########" not in s, "sprites"),
              "growing the terminal redraws the level as sprites", pane.screen())
        pane.keys("q")
        check(pane.exit_status() == 0, "q exits with status 0 after a resize")
    finally:
        pane.close()

    # --scripted: keys from a pipe, what happens on standard output.
    solved = scripted("--level", "0", keys=b"\x1b[D\x1b[D\x1b[A\x1b[C")
    out = solved.stdout.decode()
    check(solved.returncode == 0 and "solved level 1" in out and "level 2 of 3" in out,
          "--scripted: the arrow keys' escape sequences solve level 1", out + solved.stderr.decode())
    replayed = scripted("--level", "0", "--replay", "llur")
    check("solved level 1" in replayed.stdout.decode(), "--replay plays psc solve's letters", replayed.stdout.decode())
    record = os.path.join(STATE, "record.txt")
    recorded = scripted("--level", "0", "--record", record, keys=b"aazraawd")
    with open(record) as f:
        text = f.read()
    check(recorded.returncode == 0 and "".join(l for l in text.split("\n") if not l.startswith("#")) == "llz!llur",
          "--record writes the inputs played", text)
    again = scripted("--level", "0", "--replay-file", record)
    check("solved level 1" in again.stdout.decode(), "--replay-file replays a record", again.stdout.decode())
    hint = scripted("--level", "0", keys=b"ah")
    check("hint: \u2190 (left), 3 inputs to win" in hint.stdout.decode(), "H asks the solver: the next move and the distance",
          hint.stdout.decode() + hint.stderr.decode())

    # Errors: no terminal, bad arguments.
    piped = subprocess.run([PSC, "play", SOKOBAN], stdin=subprocess.DEVNULL, capture_output=True, env=ENV, timeout=60)
    check(piped.returncode == 2 and b"standard output is not a terminal" in piped.stderr,
          "standard output that is not a terminal is a clear error", piped.stderr.decode())
    bad = scripted("--replay", "llq")
    check(bad.returncode == 2 and b"is not an input" in bad.stderr, "a bad --replay letter is an error", bad.stderr.decode())
    far = scripted("--level", "3")
    check(far.returncode == 2 and b"out of range" in far.stderr, "a level out of range is an error", far.stderr.decode())

    kick_tests()

    shutil.rmtree(STATE, ignore_errors=True)
    print("%d passed, %d failed" % (passed, len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
