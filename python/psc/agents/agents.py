"""Agents: one object per episode, called with the turn's chat messages and
answering with a reply string (TextArena's `str -> str`, with the system and
user messages), from which the harness reads the action (prompt.parse_reply).

- random: a uniformly random offered action (seeded by the episode's seed);
- solver: plays `psc solve`'s solution of the level from its start, random
  once it has none (or has played it): an upper bound for the others;
- chat: asks a chat-completions endpoint (client.ChatClient).
"""

import random
from dataclasses import dataclass
from typing import Callable, List, Optional, Sequence

from .client import ChatClient
from .game_text import ACTION_LETTERS
from .progress import Distances

AGENTS = ("random", "solver", "chat")


@dataclass(frozen=True)
class Episode:
    """Which episode an agent plays."""

    level: int
    run: int
    seed: int
    offered: Sequence[str]  # action names the agent may choose


class RandomAgent:
    def __init__(self, episode: Episode):
        self._rng = random.Random(episode.seed)
        self._offered = list(episode.offered)

    def __call__(self, messages: List[dict]) -> str:
        return f"ACTION: {self._rng.choice(self._offered)}"


class SolverAgent:
    """Plays the solver's solution; random when there is none."""

    def __init__(self, episode: Episode, distances: Distances):
        record = distances.solve_level(episode.level, episode.seed)
        self.solution: Optional[str] = record.get("solution") if record.get("status") == "solved" else None
        self._plan = list(self.solution or "")
        self._fallback = RandomAgent(episode)

    def __call__(self, messages: List[dict]) -> str:
        if self._plan:
            return f"ACTION: {ACTION_LETTERS[self._plan.pop(0)]}"
        return self._fallback(messages)


class ChatAgent:
    """Each turn one chat-completions request; the episode's seed goes with
    it (endpoints that honour `seed` then answer reproducibly)."""

    def __init__(self, episode: Episode, client: ChatClient):
        self._client = client
        self._seed = episode.seed

    def __call__(self, messages: List[dict]) -> str:
        return self._client.complete(messages, seed=self._seed)


def agent_factory(
    kind: str, distances: Optional[Distances] = None, client: Optional[ChatClient] = None
) -> Callable[[Episode], Callable[[List[dict]], str]]:
    """A function making each episode's agent."""
    if kind == "random":
        return RandomAgent
    if kind == "solver":
        if distances is None:
            raise ValueError("the solver agent needs the game's Distances (psc solve)")
        return lambda episode: SolverAgent(episode, distances)
    if kind == "chat":
        if client is None:
            raise ValueError("the chat agent needs --endpoint and --model")
        return lambda episode: ChatAgent(episode, client)
    raise ValueError(f"unknown agent {kind!r} (known: {', '.join(AGENTS)})")
