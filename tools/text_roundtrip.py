#!/usr/bin/python3
"""Checks that corpus trace states parse back from their text (psc.TextEnv's
format) to the recorded objects, and prints the share that do.

    tools/text_roundtrip.py [--corpus ../shared/corpus] [--suite testsuite|scraped|all]
                            [--replay] [--sample N] [--jobs N] [--min PERCENT] [--psc build/cli/psc]

Default: every recorded state of every trace is rendered as text (the game's
glyphs and symbols from its source and IR, `psc --emit ir`) and parsed back.
It also checks, once per game, that every cell of its levels as written
holds exactly the objects the text says its glyph stands for.  Exits 1 when
either share is below --min.
--replay: each trace is played through a TextEnv instead (its game compiled
to a plugin, started with the trace's entry and seed, its inputs stepped),
and the text of every state the environment reaches is parsed and compared
with the recorded state: this also checks the states themselves.
"""
import argparse
import hashlib
import json
import multiprocessing
import os
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

import psc  # noqa: E402
from psc.agents.game_text import make_game_text  # noqa: E402
from psc.build import find_psc_binary  # noqa: E402
from psc.agents.text_state import Symbols, cells_of_record, level_of_entry, parse_text, state_text  # noqa: E402

REPLAY_UNDO_DEPTH = 4096  # as cli/Replay.cpp: deep enough for any trace


def _game_file(case: dict, directory: str) -> str:
    path = os.path.join(directory, hashlib.sha1(case["game"].encode()).hexdigest() + ".txt")
    if not os.path.exists(path):
        Path(path).write_text(case["game"], encoding="utf-8")
    return path


def state_level(entries, record):
    return level_of_entry(entries, int(record["level"]))


def check_glyphs(game_path: str, ir: dict) -> tuple:
    """(cells, cells that hold exactly the objects their glyph stands for in
    the text, GameText.glyph_table) over the game's levels as psc loads them."""
    done = subprocess.run(
        [find_psc_binary(), game_path, "--emit", "ast", "--format", "json", "--keep-going"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
    )
    ast = json.loads(done.stdout)
    order = [o["name"] for o in ir["objects"]]
    game = make_game_text(Path(game_path).read_text(encoding="utf-8"), ir, 0, order)
    total = agree = 0
    level = 0
    for written, loaded in zip(ast["levels"], ir["levels"]["entries"]):
        if loaded["kind"] != "level":
            continue
        objects = {glyph.lower(): cell for glyph, cell in game.glyph_cells(level).items()}
        for row, cell_row in zip(written.get("rows", []), loaded.get("rows", [])):
            for c, cell in zip(row, cell_row):
                total += 1
                agree += objects.get(c) == frozenset(cell)
        level += 1
    return total, agree


def check_records(case: dict, game_path: str) -> tuple:
    """(states that round-trip, states, first failure) from the recorded states."""
    ir = psc.emit_ir(game_path, keep_going=True)
    order = [o["name"] for o in sorted(ir["objects"], key=lambda o: (o["layer"] is None, o["layer"] or 0, o["id"]))]
    game = make_game_text(case["game"], ir, 0, order)
    entries = [i for i, e in enumerate(ir["levels"]["entries"]) if e["kind"] == "level"]
    symbols = Symbols(game, state_level(entries, case["initial"]))
    ok, failure = 0, None
    records = [case["initial"]] + case["steps"]
    for i, record in enumerate(records):
        text = state_text(record, symbols, game, entries, False)
        if parse_text(text) == cells_of_record(record):
            ok += 1
        elif failure is None:
            failure = f"state {i}: text does not parse back:\n{text}"
    return ok, len(records), failure


def check_replay(case: dict, game_path: str) -> tuple:
    """(states that round-trip, states, first failure) from a TextEnv driven through the trace."""
    with psc.TextEnv(game_path, play_through=True, undo_depth=REPLAY_UNDO_DEPTH, keep_going=True) as env:
        text, _ = env.reset_to_entry(case["start_level"], case["level_seed"])
        ok, failure = 0, None
        for i, record in enumerate([case["initial"]] + case["steps"]):
            if i > 0:
                text, *_ = env.step(case["inputs"][i - 1])
            if parse_text(text) == cells_of_record(record):
                ok += 1
            elif failure is None:
                failure = f"state {i}: the text's objects differ from the recorded state:\n{text}"
    return ok, len(case["steps"]) + 1, failure


def run_case(job):
    """(id, states that round-trip, states, first failure, glyph check of a game met first or None)."""
    path, replay, directory = job
    with open(path) as f:
        case = json.load(f)
    states = len(case["steps"]) + 1
    try:
        game_path = _game_file(case, directory)
        ok, total, failure = (check_replay if replay else check_records)(case, game_path)
        glyphs = None
        marker = game_path + ".glyphs"
        if not replay and not os.path.exists(marker):  # once per distinct game
            Path(marker).touch()
            glyphs = check_glyphs(game_path, psc.emit_ir(game_path, keep_going=True))
    except Exception as e:  # a game psc cannot build counts as failed states, never stops the run
        return case["id"], 0, states, f"{type(e).__name__}: {str(e)[:300]}", None
    return case["id"], ok, total, failure, glyphs


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--corpus", default=str(REPO.parent / "shared" / "corpus"))
    ap.add_argument("--suite", choices=("testsuite", "scraped", "all"), default="all")
    ap.add_argument("--replay", action="store_true", help="drive a TextEnv through each trace (compiles each game)")
    ap.add_argument("--sample", type=int, help="only the first N cases by sha1 of their id")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--min", type=float, default=0.0, help="exit 1 when fewer states (percent) round-trip")
    ap.add_argument("--psc", help="the psc compiler (default: $PSC_BINARY, build/cli/psc)")
    a = ap.parse_args()
    if a.psc:
        os.environ["PSC_BINARY"] = os.path.abspath(a.psc)
    with open(os.path.join(a.corpus, "INDEX.json")) as f:
        index = [e for e in json.load(f) if e["kind"] == "trace" and a.suite in ("all", e["suite"])]
    index.sort(key=lambda e: hashlib.sha1(e["id"].encode()).hexdigest())
    if a.sample:
        index = index[: a.sample]
    with tempfile.TemporaryDirectory(prefix="text-roundtrip-") as directory:
        jobs = [(os.path.join(a.corpus, e["path"]), a.replay, directory) for e in index]
        with multiprocessing.Pool(a.jobs) as pool:
            results = pool.map(run_case, jobs, chunksize=1)
    ok = sum(r[1] for r in results)
    total = sum(r[2] for r in results)
    failed = [r for r in results if r[1] < r[2]]
    for case_id, good, states, failure, _ in failed:
        print(f"FAIL {case_id}: {good}/{states} states; {failure.splitlines()[0] if failure else ''}")
    percent = 100.0 * ok / total if total else 0.0
    mode = "replayed through TextEnv" if a.replay else "rendered from the records"
    print(f"{ok}/{total} states ({percent:.2f} %) of {len(results)} traces ({a.suite}, {mode}) parse back; "
          f"{len(results) - len(failed)}/{len(results)} traces entirely")
    glyph_checks = [r[4] for r in results if r[4] is not None]
    glyph_percent = 100.0
    if glyph_checks:
        cells, agree = sum(g[0] for g in glyph_checks), sum(g[1] for g in glyph_checks)
        glyph_percent = 100.0 * agree / cells if cells else 100.0
        print(f"{agree}/{cells} level cells as written ({len(glyph_checks)} games, {glyph_percent:.2f} %) hold "
              f"exactly the objects their glyph stands for in the text")
    return 0 if min(percent, glyph_percent) >= a.min else 1


if __name__ == "__main__":
    sys.exit(main())
