"""The prompt a chat model gets each turn, and reading the action from its reply.

The prompt follows the PuzzleJAX paper's agent (script-doctor's
llm_agent_loop.py): the state as ASCII with the meaning of its characters, the
game's rules, the action space and what each action means; optionally the
last k turns.  The reply may think aloud; its action is the last
`ACTION: <name>` line (BALROG's convention), or the whole reply when it is
just an action name or letter (TextArena's).
"""

import re
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

from .game_text import ACTION_NAMES, GameText, parse_action

SYSTEM_PROMPT = (
    "You are playing a PuzzleScript puzzle game, one action per turn. Each turn you get the level as a grid "
    "of characters with the objects each character stands for, the game's rules (PuzzleScript source) and "
    "the actions you may take. You may reason first; end your reply with one line of the form "
    "ACTION: <name>, where <name> is one of the listed actions."
)

_ACTION_LINE = re.compile(r"ACTION\s*:\s*\**\s*[`'\"\[(]?\s*([A-Za-z0-9]+)", re.IGNORECASE)


def describe_game(game: GameText) -> str:
    """The game as the prompt presents it: title, author, legend, collision
    layers, rules and win conditions, as the source writes them."""
    by = f" by {game.author}" if game.author else ""
    parts = [f"Game: {game.title or '(untitled)'}{by}"]
    if game.legend:
        parts.append("Legend (names used in the rules):\n" + "\n".join(game.legend))
    if game.collision_layers:
        parts.append(
            "Collision layers (objects of one layer cannot share a cell; moving into a cell taken in the mover's "
            "layer is blocked unless a rule moves the other object first):\n" + "\n".join(game.collision_layers)
        )
    parts.append("Rules:\n" + ("\n".join(game.rules) if game.rules else "(none)"))
    parts.append(
        "Win conditions (the level is won when all hold):\n"
        + ("\n".join(game.win_conditions) if game.win_conditions else "(none)")
    )
    return "\n\n".join(parts)


def describe_actions(game: GameText) -> str:
    return "Actions:\n" + "\n".join(game.describe_actions())


@dataclass(frozen=True)
class Turn:
    """One past turn, for the history part of a prompt."""

    state: str
    reply_action: Optional[str]  # the action played, None when the reply was invalid


def build_prompt(
    game: GameText, state: str, step: int, max_steps: Optional[int], history: Sequence[Turn] = ()
) -> str:
    """The user message of one turn."""
    parts = [describe_game(game), describe_actions(game)]
    if history:
        lines = [f"The last {len(history)} turns, oldest first:"]
        first = step - len(history)
        for offset, turn in enumerate(history):
            played = turn.reply_action if turn.reply_action is not None else "(no valid action)"
            lines.append(f"Turn {first + offset}:\n{turn.state}\nAction: {played}")
        parts.append("\n\n".join(lines))
    budget = f" of at most {max_steps}" if max_steps else ""
    parts.append(f"Current state (turn {step}{budget}):\n{state}")
    parts.append(f"Choose your action ({', '.join(game.actions)}). End your reply with: ACTION: <name>")
    return "\n\n".join(parts)


def messages(user_prompt: str) -> List[dict]:
    """The chat-completions messages of one turn."""
    return [{"role": "system", "content": SYSTEM_PROMPT}, {"role": "user", "content": user_prompt}]


def parse_reply(reply: Optional[str], offered: Sequence[str]) -> Tuple[Optional[str], Optional[str]]:
    """(action name, None) from a reply, or (None, why) when it names no
    offered action.  Names and letters of any case are accepted, and
    psc_action numbers."""
    if reply is None:
        return None, "no reply"
    matches = _ACTION_LINE.findall(reply)
    if matches:
        word = matches[-1]
    else:
        word = reply.strip().strip("`*'\".").strip()
        if not word or any(c.isspace() for c in word):
            return None, "no 'ACTION: <name>' in the reply"
    try:
        name = ACTION_NAMES[parse_action(word)]
    except ValueError:
        return None, f"{word!r} is not an action"
    if name not in offered:
        return None, f"{name!r} is not one of the actions offered ({', '.join(offered)})"
    return name, None
