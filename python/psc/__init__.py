"""psc: PuzzleScript games compiled to step-function plugins, as vectorised environments."""

__version__ = "0.1.0"  # pyproject.toml reads it from here

from .build import CompileError, compile, emit_ir
from .plugin import GameInfo, Plugin, PscError
from .render import render_planes, save_gif
from .solve import SolveError, solve
from .vector_env import Buffers, EnvState, VectorEnv
from .agents.text_env import TextEnv, TextVectorEnv

__all__ = [
    "Buffers",
    "CompileError",
    "EnvState",
    "GameInfo",
    "Plugin",
    "PscError",
    "TextEnv",
    "TextVectorEnv",
    "VectorEnv",
    "compile",
    "emit_ir",
    "render_planes",
    "save_gif",
    "solve",
    "SolveError",
]
