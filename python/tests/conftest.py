"""Shared fixtures: plugins of the bundled games, built once per session."""

import pytest
from helpers import GAMES

import psc


@pytest.fixture(scope="session")
def sokoban_plugin() -> str:
    """games/sokoban.txt: three playable levels (7x5, 8x5, 9x7) after a message; win: all target on crate."""
    return psc.compile(GAMES / "sokoban.txt")


@pytest.fixture(scope="session")
def gems_plugin() -> str:
    """games/gems.txt: random spawns and directions, run_rules_on_level_start."""
    return psc.compile(GAMES / "gems.txt")
