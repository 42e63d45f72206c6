"""What a text agent is told about a game, taken from its source and IR: the
title and author, the rules, win conditions and legend as written (comments
stripped), the legend glyphs that stand for exactly one cell's objects, and
the actions with their meanings."""

import re
from dataclasses import dataclass
from typing import Dict, FrozenSet, List, Mapping, Optional, Sequence, Tuple

SECTIONS = ("objects", "legend", "sounds", "collisionlayers", "rules", "winconditions", "levels")

# psc_action numbers (runtime/psc_plugin.h) by name.
ACTION_IDS = {"up": 0, "left": 1, "down": 2, "right": 3, "action": 4, "undo": 5, "restart": 6, "tick": 7}
ACTION_NAMES = tuple(ACTION_IDS)

# Single letters accepted for actions: psc solve's solution letters (u d l r x)
# and PuzzleScript's undo key (z).  `d` is down, as in solutions, so WASD is
# not accepted; restart and tick are words only (PuzzleScript's R is restart,
# which would clash with r = right).
ACTION_LETTERS = {"u": "up", "l": "left", "d": "down", "r": "right", "x": "action", "z": "undo"}
LETTER_OF_ACTION = {"up": "u", "left": "l", "down": "d", "right": "r", "action": "x"}

ACTION_MEANINGS = {
    "up": "move up (the player moves one cell if the rules let it; the rules decide what else happens)",
    "left": "move left (likewise)",
    "down": "move down (likewise)",
    "right": "move right (likewise)",
    "action": "the game's action key (X in PuzzleScript): what it does, if anything, is up to the game's rules",
    "undo": "take back the last move that changed the level",
    "restart": "start the level again from its beginning (can itself be undone)",
    "tick": "let one turn pass without input (real-time games)",
}

# Flags of psc_game_info (runtime/psc_plugin.h).
FLAG_NOACTION = 1 << 0
FLAG_NOUNDO = 1 << 1
FLAG_NORESTART = 1 << 2
FLAG_REALTIME = 1 << 5


def strip_comments(source: str) -> str:
    """The source without its comments: PuzzleScript comments are parentheses,
    nested, and may span lines; line breaks are kept so line numbers hold."""
    out = []
    depth = 0
    for c in source:
        if c == "(":
            depth += 1
        elif c == ")" and depth > 0:
            depth -= 1
        elif depth == 0 or c == "\n":
            out.append(c)
    return "".join(out)


def split_sections(source: str, keep_blank: bool = False) -> Dict[str, List[str]]:
    """The comment-free lines of each section (a section starts at a line that
    is only its name, any case); separator lines of '=' are dropped, and blank
    lines unless keep_blank (they separate levels)."""
    sections: Dict[str, List[str]] = {"prelude": []}
    current = "prelude"
    for raw in strip_comments(source).splitlines():
        line = raw.rstrip()
        word = line.strip().lower()
        if word in SECTIONS:
            current = word
            sections.setdefault(current, [])
            continue
        if (not word and not keep_blank) or (word and set(word) == {"="}):
            continue
        sections.setdefault(current, []).append(line)
    return sections


def background_objects(ir: Mapping) -> FrozenSet[str]:
    """The objects of the background's collision layer."""
    layer = ir["background"]["layer"]
    return frozenset(o["name"] for o in ir["objects"] if o["layer"] == layer and layer is not None)


def written_levels(sections: Mapping[str, Sequence[str]]) -> List[Optional[List[str]]]:
    """The LEVELS section's entries as written: None for a message, else the
    rows (lower case; levels are separated by blank lines or messages)."""
    entries: List[Optional[List[str]]] = []
    rows: List[str] = []
    for line in sections.get("levels", []) + [""]:
        text = line.strip()
        if text.lower().startswith("message") and (len(text) == 7 or text[7].isspace()):
            if rows:
                entries.append(rows)
                rows = []
            entries.append(None)
        elif text:
            rows.append(text.lower())
        elif rows:
            entries.append(rows)
            rows = []
    return entries


def level_fills(ir: Mapping, sections: Mapping[str, Sequence[str]]) -> Tuple[FrozenSet[str], ...]:
    """What each playable level puts under a glyph that has nothing in the
    background's layer: the background-layer objects of the level's first
    cell (column by column, as levels are loaded) whose glyph has some, else
    the background object.  Levels of the source that do not line up with the
    IR's get the background object."""
    glyphs = ir["legend"]["glyphs"]
    background = background_objects(ir)
    default = frozenset([ir["background"]["name"]])
    written = [rows for rows in written_levels(sections) if rows is not None]
    loaded = [entry for entry in ir["levels"]["entries"] if entry["kind"] == "level"]
    fills = []
    for i, entry in enumerate(loaded):
        rows = written[i] if len(written) == len(loaded) else None
        fill = default
        if rows and len(rows) == entry["height"]:
            width = max(len(row) for row in rows)
            cells = ((x, row) for x in range(width) for row in rows)
            for x, row in cells:
                objects = background.intersection(glyphs.get(row[x] if x < len(row) else row[-1], ()))
                if objects:
                    fill = frozenset(objects)
                    break
        fills.append(fill)
    return tuple(fills)


@dataclass(frozen=True)
class GameText:
    """The static text of one game, shared by every environment of it."""

    title: str
    author: str
    homepage: str
    rules: Tuple[str, ...]  # RULES lines as written, comments stripped
    win_conditions: Tuple[str, ...]  # WINCONDITIONS lines
    legend: Tuple[str, ...]  # LEGEND lines (the names the rules use)
    collision_layers: Tuple[str, ...]  # COLLISIONLAYERS lines
    object_order: Tuple[str, ...]  # object names by collision layer: the order of a cell's objects in text
    glyphs: Tuple[Tuple[str, FrozenSet[str]], ...]  # (glyph as written, its objects), preferred first
    background: FrozenSet[str]  # the objects of the background's layer
    level_fills: Tuple[FrozenSet[str], ...]  # per playable level: what a glyph without background gets
    default_fill: FrozenSet[str]  # the background object
    reserved: FrozenSet[str]  # every legend glyph, both cases: never used for generated symbols
    level_cells: Tuple[FrozenSet[str], ...]  # cell object sets of all levels as loaded, first appearance order
    actions: Tuple[str, ...]  # the actions offered to agents, in psc_action order
    flags: int

    def glyph_cells(self, level: Optional[int]) -> Dict[str, FrozenSet[str]]:
        """Each glyph (as written) and the objects of a cell written with it in
        playable level `level` (None: with the background object as fill)."""
        fill = self.level_fills[level] if level is not None and level < len(self.level_fills) else self.default_fill
        return {glyph: objects if objects & self.background else objects | fill for glyph, objects in self.glyphs}

    def glyph_table(self, level: Optional[int]) -> Dict[FrozenSet[str], str]:
        """A cell's objects -> the glyph standing for exactly them in playable level `level`."""
        table: Dict[FrozenSet[str], str] = {}
        for glyph, cell in self.glyph_cells(level).items():
            table.setdefault(cell, glyph)
        return table

    def describe_actions(self) -> List[str]:
        return [f"{name}: {ACTION_MEANINGS[name]}" for name in self.actions]


def offered_actions(flags: int, action_set: str = "full") -> Tuple[str, ...]:
    """The actions an agent may choose: the four directions, action unless the
    game says noaction; with action_set "full" also undo and restart unless
    the game forbids them, and tick in real-time games.  "basic" is the
    PuzzleJAX paper's set (directions and action)."""
    if action_set not in ("basic", "full"):
        raise ValueError(f"action_set must be 'basic' or 'full', not {action_set!r}")
    names = ["up", "left", "down", "right"]
    if not flags & FLAG_NOACTION:
        names.append("action")
    if action_set == "full":
        if not flags & FLAG_NOUNDO:
            names.append("undo")
        if not flags & FLAG_NORESTART:
            names.append("restart")
        if flags & FLAG_REALTIME:
            names.append("tick")
    return tuple(names)


def _written_case(sections: Mapping[str, Sequence[str]]) -> Dict[str, str]:
    """Each character's first spelling in the LEVELS section, then the LEGEND's
    left-hand sides: glyphs are shown the way the game's author wrote them."""
    case: Dict[str, str] = {}
    for line in sections.get("levels", []):
        if line.strip().lower().startswith("message"):
            continue
        for c in line.strip():
            case.setdefault(c.lower(), c)
    for line in sections.get("legend", []):
        name = line.split("=", 1)[0].strip()
        if len(name) == 1:
            case.setdefault(name.lower(), name)
    return case


def _first_positions(sections: Mapping[str, Sequence[str]]) -> Dict[str, int]:
    """Where each character first appears in the levels, then in the legend (for tie-breaks)."""
    text = "\n".join(sections.get("levels", [])) + "\n" + "\n".join(sections.get("legend", []))
    positions: Dict[str, int] = {}
    for i, c in enumerate(text.lower()):
        positions.setdefault(c, i)
    return positions


def _level_cells(ir: Mapping) -> Tuple[FrozenSet[str], ...]:
    seen = {}
    for entry in ir["levels"]["entries"]:
        for row in entry.get("rows", []):
            for cell in row:
                seen.setdefault(frozenset(cell), None)
    return tuple(seen)


def make_game_text(
    source: str, ir: Mapping, flags: int, object_order: Sequence[str], action_set: str = "full",
    title: Optional[str] = None, author: Optional[str] = None, homepage: Optional[str] = None,
) -> GameText:
    """GameText of a game from its source text and IR (psc --emit ir --format json)."""
    sections = split_sections(source)
    metadata = ir.get("metadata", {})
    case = _written_case(sections)
    positions = _first_positions(sections)
    # Of several glyphs for the same objects, the one the levels use first (then the legend) is shown.
    glyphs = tuple(
        (case.get(glyph, glyph), frozenset(objects))
        for glyph, objects in sorted(
            ir["legend"]["glyphs"].items(), key=lambda item: (positions.get(item[0], 1 << 30), item[0])
        )
        if len(glyph) == 1 and not glyph.isspace()
    )
    reserved = set()
    for glyph in ir["legend"]["glyphs"]:
        if len(glyph) == 1:
            reserved.update({glyph, glyph.lower(), glyph.upper()})
    return GameText(
        title=title if title is not None else metadata.get("title", ""),
        author=author if author is not None else metadata.get("author", ""),
        homepage=homepage if homepage is not None else metadata.get("homepage", ""),
        rules=tuple(line.strip() for line in sections.get("rules", [])),
        win_conditions=tuple(line.strip() for line in sections.get("winconditions", [])),
        legend=tuple(line.strip() for line in sections.get("legend", [])),
        collision_layers=tuple(line.strip() for line in sections.get("collisionlayers", [])),
        object_order=tuple(object_order),
        glyphs=glyphs,
        background=background_objects(ir),
        level_fills=level_fills(ir, split_sections(source, keep_blank=True)),
        default_fill=frozenset([ir["background"]["name"]]),
        reserved=frozenset(reserved),
        level_cells=_level_cells(ir),
        actions=offered_actions(flags, action_set),
        flags=flags,
    )


def parse_action(action) -> int:
    """A psc_action number from an action name or letter (any case, surrounding
    spaces ignored) or from a psc_action number; ValueError otherwise."""
    if isinstance(action, bool):
        raise ValueError(f"not an action: {action!r}")
    if isinstance(action, int) or (hasattr(action, "__index__") and not isinstance(action, str)):
        number = int(action)
        if 0 <= number < len(ACTION_NAMES):
            return number
        raise ValueError(f"action {number} out of range [0, {len(ACTION_NAMES)})")
    if not isinstance(action, str):
        raise ValueError(f"an action is a name, a letter or a number, not {type(action).__name__}")
    word = action.strip().lower()
    word = ACTION_LETTERS.get(word, word)
    if word in ACTION_IDS:
        return ACTION_IDS[word]
    if re.fullmatch(r"[0-9]+", word):
        return parse_action(int(word))
    known = ", ".join(ACTION_NAMES)
    letters = " ".join(f"{k}={v}" for k, v in ACTION_LETTERS.items())
    raise ValueError(f"unknown action {action!r} (actions: {known}; letters: {letters}; any case)")
