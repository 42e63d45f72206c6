"""A level state as text and back.

The text is a header line, a map with one character per cell and the meaning
of every character on the map:

    Level 0 of 3: playing
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
    P = background and player

A cell whose objects are exactly those of one of the game's legend glyphs (as
a level would be written: a glyph without a background-layer object gets the
background) shows that glyph, spelled as the game's levels spell it.  Any
other combination gets a generated symbol that is none of the game's glyphs
(in either case): first those of the game's levels as written, then new
combinations in the order an episode meets them, so a state's text depends
only on the episode, not on what else ran beside it.
"""

from typing import Dict, FrozenSet, List, Mapping, Optional, Sequence, Set

from .game_text import GameText

EMPTY_CELL = "(nothing)"


def _candidate_symbols() -> List[str]:
    symbols = list(
        "0123456789"
        "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
        "abcdefghijklmnopqrstuvwxyz"
        "!$%&*+-/:;<>?@^_~|'\"`,.#=()[]{}\\"
    )
    ranges = [
        (0x00C0, 0x00FF),  # Latin-1 letters
        (0x0391, 0x03C9),  # Greek
        (0x0410, 0x044F),  # Cyrillic
        (0x4E00, 0x9FFF),  # CJK ideographs: more than any level needs
    ]
    for first, last in ranges:
        symbols += [chr(code) for code in range(first, last + 1) if chr(code).isalpha()]
    return symbols


CANDIDATE_SYMBOLS = _candidate_symbols()


class Symbols:
    """The character of each cell combination within one episode: the
    game's glyphs as they read in the level shown, and symbols generated for
    every other combination, kept for the whole episode."""

    def __init__(self, game: GameText, level: Optional[int] = None):
        self._game = game
        self._level = level
        self._glyphs = game.glyph_table(level)
        self._generated: Dict[FrozenSet[str], str] = {}
        self._next = 0  # the next CANDIDATE_SYMBOLS index to try
        for cell in game.level_cells:
            self.symbol(cell)

    def copy(self) -> "Symbols":
        clone = Symbols.__new__(Symbols)
        clone.__dict__.update(self.__dict__)
        clone._generated = dict(self._generated)
        return clone

    def show_level(self, level: Optional[int]) -> None:
        """The level shown changed (playing through): glyphs read as they do there."""
        if level != self._level:
            self._level = level
            self._glyphs = self._game.glyph_table(level)

    def symbol(self, cell: FrozenSet[str]) -> str:
        symbol = self._glyphs.get(cell) or self._generated.get(cell)
        if symbol is None:
            used = set(self._generated.values())
            while self._next < len(CANDIDATE_SYMBOLS):
                candidate = CANDIDATE_SYMBOLS[self._next]
                self._next += 1
                if candidate not in self._game.reserved and candidate not in used:
                    symbol = candidate
                    break
            else:
                raise RuntimeError("out of symbols for new cell combinations")
            self._generated[cell] = symbol
        return symbol


def cells_of_record(record: Mapping) -> List[List[FrozenSet[str]]]:
    """The objects of each cell of a state record (psc_dump_state or corpus form), top row first."""
    palette = [frozenset(entry.split()) for entry in record["palette"]]
    return [[palette[index] for index in row] for row in record["rows"]]


def _describe_cell(cell: FrozenSet[str], order: Mapping[str, int]) -> str:
    if not cell:
        return EMPTY_CELL
    return " and ".join(sorted(cell, key=lambda name: (order.get(name, len(order)), name)))


def render_map(cells: Sequence[Sequence[FrozenSet[str]]], symbols: Symbols, object_order: Sequence[str]) -> str:
    """The "Map" and "Symbols" parts of a state's text."""
    order = {name: i for i, name in enumerate(object_order)}
    lines = []
    legend: Dict[str, FrozenSet[str]] = {}
    for row in cells:
        chars = []
        for cell in row:
            c = symbols.symbol(cell)
            legend.setdefault(c, cell)
            chars.append(c)
        lines.append("".join(chars))
    height = len(lines)
    width = len(cells[0]) if cells else 0
    text = [f"Map ({width}x{height}):"] + lines + ["Symbols:"]
    text += [f"{c} = {_describe_cell(cell, order)}" for c, cell in legend.items()]
    return "\n".join(text)


def header(game_levels: int, level: Optional[int], screen: str, won: bool, message: Optional[str]) -> List[str]:
    """The lines before the map: where the game is and whether the level was won."""
    if screen == "title":
        return ["The game is complete (every level won)."]
    if screen == "message":
        where = f"before level {level} of {game_levels}" if level is not None else "after the last level"
        return [f"Message screen {where}:", f"Message: {message}", "(The map is the level behind the message.)"]
    return [f"Level {level} of {game_levels}: {'won' if won else 'playing'}"]


def level_of_entry(level_entries: Sequence[int], entry: int) -> Optional[int]:
    """The playable level shown at LEVELS entry `entry`, or for a message
    entry the level after it (None after the last level)."""
    for level, level_entry in enumerate(level_entries):
        if level_entry >= entry:
            return level
    return None


def state_text(record: Mapping, symbols: Symbols, game: GameText, level_entries: Sequence[int], won: bool) -> str:
    """The text of a state record (psc_dump_state or corpus form); won: the level was won in this step."""
    level = level_of_entry(level_entries, int(record["level"]))
    if record["screen"] == "level":  # message and title screens show the last level's buffer
        symbols.show_level(level)
    lines = header(len(level_entries), level, record["screen"], won, record.get("message"))
    return "\n".join(lines) + "\n" + render_map(cells_of_record(record), symbols, game.object_order)


def parse_text(text: str) -> List[List[FrozenSet[str]]]:
    """Each cell's objects (sets of lower-case names), top row first, from a
    state's text; ValueError when the text has no well-formed map."""
    lines = text.splitlines()
    start = next((i for i, line in enumerate(lines) if line.startswith("Map (") and line.endswith("):")), None)
    if start is None:
        raise ValueError("no 'Map (WxH):' line in the text")
    try:
        width, height = (int(n) for n in lines[start][len("Map (") : -len("):")].split("x"))
    except ValueError:
        raise ValueError(f"bad map header {lines[start]!r}") from None
    rows = lines[start + 1 : start + 1 + height]
    if len(rows) != height or any(len(row) != width for row in rows):
        raise ValueError(f"the map is not {height} rows of {width} characters")
    if start + 1 + height >= len(lines) or lines[start + 1 + height] != "Symbols:":
        raise ValueError("no 'Symbols:' line after the map")
    meaning: Dict[str, FrozenSet[str]] = {}
    for line in lines[start + 2 + height :]:
        if not line.strip():
            break
        if len(line) < 4 or line[1:4] != " = ":
            raise ValueError(f"bad symbol line {line!r} (expected 'S = object and object')")
        body = line[4:]
        meaning[line[0]] = frozenset() if body == EMPTY_CELL else frozenset(body.split(" and "))
    try:
        return [[meaning[c] for c in row] for row in rows]
    except KeyError as e:
        raise ValueError(f"map symbol {e.args[0]!r} has no meaning under 'Symbols:'") from None
