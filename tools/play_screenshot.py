#!/usr/bin/env python3
"""Regenerates docs/play.md's screenshots of psc play: the game runs in tmux,
capture-pane reads the screen back, and the colour capture is drawn as a PNG
(each character cell 8x16 pixels; half blocks as two 8x8 pixels).

Usage: tools/play_screenshot.py [--psc build/cli/psc]
Writes docs/images/play_sokoban.png and prints the --glyphs capture (as
docs/play.md shows it) on standard output.  Needs tmux and python3-pil.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

from PIL import Image, ImageDraw

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOCKET = "psc-play-screenshot-%d" % os.getpid()
COLUMNS, ROWS = 80, 24


def tmux(*args):
    return subprocess.run(["tmux", "-L", SOCKET, "-f", "/dev/null", *args], check=True, capture_output=True,
                          text=True).stdout


def capture(psc, args, keys, colour):
    env = dict(os.environ, XDG_STATE_HOME=tempfile.mkdtemp(), COLORTERM="truecolor", TERM="xterm-256color")
    command = " ".join([psc, "play", *args]) + "; sleep 60"
    tmux("new-session", "-d", "-s", "shot", "-x", str(COLUMNS), "-y", str(ROWS), "-e",
         "XDG_STATE_HOME=" + env["XDG_STATE_HOME"], "-e", "COLORTERM=truecolor", command)
    try:
        deadline = time.time() + 120  # the first start may build the plugin
        while "level 3 of 3" not in tmux("capture-pane", "-p", "-t", "shot") and time.time() < deadline:
            time.sleep(0.1)
        for key in keys:
            tmux("send-keys", "-t", "shot", key)
            time.sleep(0.1)
        time.sleep(0.5)
        return tmux("capture-pane", "-p", *(["-e", "-N"] if colour else []), "-t", "shot")
    finally:
        tmux("kill-server")
        socket = os.path.join(os.environ.get("TMUX_TMPDIR", "/tmp"), "tmux-%d" % os.getuid(), SOCKET)
        if os.path.exists(socket):
            os.remove(socket)


def xterm256(n):
    if n < 16:
        base = [(0, 0, 0), (205, 0, 0), (0, 205, 0), (205, 205, 0), (0, 0, 238), (205, 0, 205), (0, 205, 205),
                (229, 229, 229), (127, 127, 127), (255, 0, 0), (0, 255, 0), (255, 255, 0), (92, 92, 255),
                (255, 0, 255), (0, 255, 255), (255, 255, 255)]
        return base[n]
    if n < 232:
        n -= 16
        steps = [0, 95, 135, 175, 215, 255]
        return (steps[n // 36], steps[n // 6 % 6], steps[n % 6])
    grey = 8 + 10 * (n - 232)
    return (grey, grey, grey)


def draw(text, path):
    cell_w, cell_h = 8, 16
    default_fg, default_bg = (220, 220, 220), (0, 0, 0)
    image = Image.new("RGB", (COLUMNS * cell_w, ROWS * cell_h), default_bg)
    pen = ImageDraw.Draw(image)
    for y, line in enumerate(text.split("\n")[:ROWS]):
        fg, bg, reverse, x, i = default_fg, default_bg, False, 0, 0
        while i < len(line):
            sgr = re.match(r"\x1b\[([0-9;]*)m", line[i:])
            if sgr:
                params = [int(p) if p else 0 for p in sgr.group(1).split(";")]
                k = 0
                while k < len(params):
                    p = params[k]
                    if p == 0:
                        fg, bg, reverse = default_fg, default_bg, False
                    elif p == 7:
                        reverse = True
                    elif p in (38, 48):
                        if params[k + 1] == 5:
                            colour, k = xterm256(params[k + 2]), k + 2
                        else:
                            colour, k = tuple(params[k + 2:k + 5]), k + 4
                        fg, bg = (colour, bg) if p == 38 else (fg, colour)
                    elif p == 39:
                        fg = default_fg
                    elif p == 49:
                        bg = default_bg
                    k += 1
                i += sgr.end()
                continue
            ch = line[i]
            i += 1
            front, back = (bg, fg) if reverse else (fg, bg)
            box = [x * cell_w, y * cell_h, x * cell_w + cell_w - 1, y * cell_h + cell_h - 1]
            pen.rectangle(box, fill=back)
            if ch == "\u2580":
                pen.rectangle([box[0], box[1], box[2], box[1] + cell_h // 2 - 1], fill=front)
            elif ch != " ":
                pen.text((box[0], box[1] + 2), ch, fill=front)
            x += 1
    image.save(path)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--psc", default=os.path.join(ROOT, "build", "cli", "psc"))
    args = parser.parse_args()
    game = os.path.join("games", "sokoban.txt")
    os.chdir(ROOT)
    sprites = capture(os.path.abspath(args.psc), [game, "--level", "2"], ["Down", "Left"], colour=True)
    draw(sprites, os.path.join(ROOT, "docs", "images", "play_sokoban.png"))
    glyphs = capture(os.path.abspath(args.psc), [game, "--level", "2", "--glyphs"], ["Down", "Left"], colour=False)
    sys.stdout.write("\n".join(line.rstrip() for line in glyphs.rstrip("\n").split("\n")) + "\n")


if __name__ == "__main__":
    main()
