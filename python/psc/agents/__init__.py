"""Language-model agents on psc games: text observations (TextEnv), prompts,
a chat-completions client, agents and an evaluation harness
(`python -m psc.agents eval`, docs/agents.md)."""

from .client import ChatClient, ChatError
from .text_env import TextEnv, TextVectorEnv
from .text_state import parse_text

__all__ = ["ChatClient", "ChatError", "TextEnv", "TextVectorEnv", "parse_text"]
