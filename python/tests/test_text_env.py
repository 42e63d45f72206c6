"""psc.TextEnv: text observations, actions by name, the parse round trip."""

import os
import shutil

import pytest
from helpers import GAMES, SOKOBAN_LEVEL0_SOLUTION

import psc
from psc.agents import game_text
from psc.agents.prompt import parse_reply
from psc.agents.text_state import CANDIDATE_SYMBOLS

SOKOBAN_LEVEL0_TEXT = """Level 0 of 3: playing
Map (7x5):
#######
#.....#
#.*O..#
#..P..#
#######
Symbols:
# = background and wall
. = background
* = background and crate
O = background and target
P = background and player"""

# SOKOBAN_LEVEL0_SOLUTION as letters: hand-checked in games/sokoban.txt.
SOKOBAN_LEVEL0_LETTERS = "".join("uldr"[a] for a in SOKOBAN_LEVEL0_SOLUTION)


@pytest.fixture
def sokoban():
    with psc.TextEnv(GAMES / "sokoban.txt", level=0, seed=0, max_steps=20) as env:
        yield env


def test_the_first_text_is_the_level_as_written(sokoban):
    text, info = sokoban.reset()
    assert text == SOKOBAN_LEVEL0_TEXT
    assert info == {"level": 0, "entry": 1, "screen": "level", "level_won": False, "steps": 0}


def test_every_level_starts_as_its_source_rows():
    # Every cell of games/sokoban.txt's levels is one legend glyph: the map is the level as written.
    source = (GAMES / "sokoban.txt").read_text().splitlines()
    levels = [[]]
    for line in source[source.index("LEVELS") + 2 :]:
        if line.startswith("message"):
            continue
        if line.strip():
            levels[-1].append(line)
        elif levels[-1]:
            levels.append([])
    levels = [rows for rows in levels if rows]
    with psc.TextEnv(GAMES / "sokoban.txt") as env:
        for level, rows in enumerate(levels):
            text, _ = env.reset(options={"level": level})
            lines = text.splitlines()
            assert lines[2 : 2 + len(rows)] == rows


def test_the_hand_written_solution_wins_level_0(sokoban):
    sokoban.reset()
    for i, letter in enumerate(SOKOBAN_LEVEL0_LETTERS):
        text, reward, terminated, truncated, info = sokoban.step(letter.upper() if i % 2 else letter)
    assert (reward, terminated, truncated) == (1.0, True, False)
    assert text.splitlines()[0] == "Level 0 of 3: won"
    assert info["level_won"] and info["action"] == "right"
    with pytest.raises(RuntimeError, match="ended"):
        sokoban.step("up")


def test_actions_by_name_letter_and_number_any_case():
    expected = {"up": 0, "LEFT": 1, " Down ": 2, "r": 3, "X": 4, "undo": 5, "z": 5, "Restart": 6, "tick": 7, 3: 3, "2": 2}
    for action, number in expected.items():
        assert game_text.parse_action(action) == number
    for bad in ("jump", "", "w", "upp", 8, -1, None, 1.5, True):
        with pytest.raises(ValueError):
            game_text.parse_action(bad)


def test_a_bad_action_is_a_clear_error(sokoban):
    sokoban.reset()
    with pytest.raises(ValueError, match=r"unknown action 'jump' \(actions: up, left"):
        sokoban.step("jump")


def test_undo_and_restart(sokoban):
    start, _ = sokoban.reset()
    moved, *_ = sokoban.step("left")
    assert moved != start
    assert sokoban.step("undo")[0] == start
    sokoban.step("up")
    sokoban.step("up")
    assert sokoban.step("restart")[0] == start
    assert sokoban.actions == ("up", "left", "down", "right", "action", "undo", "restart")


def test_truncation_after_max_steps():
    with psc.TextEnv(GAMES / "sokoban.txt", max_steps=3) as env:
        env.reset()
        results = [env.step("action")[2:4] for _ in range(3)]
    assert results == [(False, False), (False, False), (False, True)]


def test_new_combinations_get_symbols_that_are_no_glyph_of_the_game(sokoban):
    # Player on the target (no legend glyph): level 0, player from (3,3) up to (3,2) = the target.
    sokoban.reset()
    text, *_ = sokoban.step("up")
    cells = sokoban.cells()
    assert cells[2][3] == {"background", "target", "player"}
    symbol = text.splitlines()[2 + 2][3]
    assert symbol not in "#.*@OoPp"
    assert symbol == CANDIDATE_SYMBOLS[0]  # the first free generated symbol
    assert f"{symbol} = background and target and player" in text.splitlines()
    assert psc.TextEnv.parse(text) == cells


def test_parse_round_trips_a_random_walk(sokoban):
    import random

    rng = random.Random(5)
    text, _ = sokoban.reset(options={"level": 2})
    for _ in range(60):
        assert psc.TextEnv.parse(text) == sokoban.cells()
        text, _, terminated, truncated, _ = sokoban.step(rng.choice(sokoban.actions))
        if terminated or truncated:
            text, _ = sokoban.reset()


def test_parse_rejects_malformed_text():
    for bad in ("", "Map (2x1):\n..\n", "Map (2x1):\n.\nSymbols:\n. = background", "Map (1x1):\nQ\nSymbols:\n. = a"):
        with pytest.raises(ValueError):
            psc.TextEnv.parse(bad)


def test_a_plugin_with_its_source_beside_it(tmp_path):
    plugin = psc.compile(GAMES / "sokoban.txt")
    copy = tmp_path / "sokoban.so"
    shutil.copyfile(plugin, copy)
    shutil.copyfile(psc.build.ir_path_for(plugin), tmp_path / "sokoban.ir.json")
    with pytest.raises(FileNotFoundError, match="source"):
        psc.TextEnv(str(copy))
    shutil.copyfile(psc.build.source_path_for(plugin), tmp_path / "sokoban.source.txt")
    with psc.TextEnv(str(copy)) as env:
        assert env.reset()[0] == SOKOBAN_LEVEL0_TEXT
    assert os.path.exists(psc.build.source_path_for(plugin))


def test_message_screens_show_their_text():
    with psc.TextEnv(GAMES / "sokoban.txt", play_through=True) as env:
        text, info = env.reset_to_entry(0, "seed")
        assert text.splitlines()[:2] == ["Message screen before level 0 of 3:", "Message: Push each crate onto a target."]
        assert info["screen"] == "message"
        env.reset_to_entry(1, "seed")
        for letter in SOKOBAN_LEVEL0_LETTERS:
            text, reward, terminated, *_ = env.step(letter)
        # Playing through: the win goes on to level 1 at once.
        assert (reward, terminated) == (1.0, False)
        assert text.splitlines()[0] == "Level 1 of 3: playing"


def test_rules_text_strips_comments():
    with psc.TextEnv(GAMES / "sokoban.txt") as env:
        rules = env.rules_text()
    assert rules.startswith("Game: Crate Yard by psc")
    assert "[ > Player | Crate ] -> [ > Player | > Crate ]" in rules
    assert "All Target on Crate" in rules
    assert "Player, Wall, Crate" in rules  # the collision layers


def test_sections_drop_comments_inside_them():
    source = "RULES\n(a comment)\n[ a ] -> [ b ] (why)\n\nWINCONDITIONS\nno a (never)\n"
    sections = game_text.split_sections(source)
    assert sections["rules"] == ["[ a ] -> [ b ]"] and sections["winconditions"] == ["no a"]


def test_comment_stripping_nests_and_spans_lines():
    assert game_text.strip_comments("a (b (c) d) e\n(x\ny) z") == "a  e\n\n z"


def test_glyphs_stand_for_their_objects_with_the_levels_background():
    with psc.TextEnv(GAMES / "sokoban.txt") as env:
        cells = env.game.glyph_cells(0)
    assert cells["@"] == {"background", "crate", "target"}
    assert cells["."] == {"background"} and cells["P"] == {"background", "player"}
    # The IR's own level cells agree with the glyphs written in the source (level 0, row 2: "#.*O..#").
    row = psc.emit_ir(GAMES / "sokoban.txt")["levels"]["entries"][1]["rows"][2]
    assert [frozenset(cell) for cell in row] == [cells[c] for c in "#.*O..#"]


def test_a_glyph_without_background_gets_the_levels_own(tmp_path):
    # As levels load: the first cell (column by column) with a background-layer object fills the others.
    source = (GAMES / "sokoban.txt").read_text()
    source = source.replace("Background\n#2e2e2e", "Background\n#2e2e2e\n\nGrass\ngreen")
    source = source.replace(". = Background", ". = Background\n, = Grass")
    source = source.replace("Background\nTarget\n", "Background, Grass\nTarget\n")
    source = source.replace("#######\n#.....#\n#.*O..#", ",######\n#.....#\n#.*O..#")
    game_file = tmp_path / "grass.txt"
    game_file.write_text(source)
    # Background shares its layer with Grass: an error the reference engine plays through.
    game = game_text.make_game_text(source, psc.emit_ir(game_file, keep_going=True), 0, ())
    assert game.level_fills[0] == {"grass"} and game.level_fills[1] == {"background"}
    assert game.glyph_cells(0)["#"] == {"grass", "wall"} and game.glyph_cells(1)["#"] == {"background", "wall"}


def test_reply_parsing():
    offered = ("up", "left", "down", "right", "action", "undo", "restart")
    assert parse_reply("I push the crate.\nACTION: right", offered) == ("right", None)
    assert parse_reply("action: LEFT", offered) == ("left", None)
    assert parse_reply("ACTION: up ... no wait. ACTION: **down**", offered) == ("down", None)
    assert parse_reply("ACTION: `x`", offered) == ("action", None)
    assert parse_reply("Left", offered) == ("left", None)  # a bare action, TextArena style
    assert parse_reply("ACTION: 3", offered) == ("right", None)
    for bad in ("I would go left", "ACTION: jump", "", "ACTION: tick", None):
        action, why = parse_reply(bad, offered)
        assert action is None and why
    assert parse_reply("ACTION: action", ("up", "left", "down", "right"))[0] is None
