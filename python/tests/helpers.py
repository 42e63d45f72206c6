"""Helpers shared by the tests (expected values built independently of psc)."""

from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
GAMES = REPO / "games"
TEST_GAMES = Path(__file__).resolve().parent / "data"


def planes_from_record(record: dict, object_names, max_height: int, max_width: int) -> np.ndarray:
    """Multi-hot planes (C, max_height, max_width) built from a canonical state
    record (rows of palette indices, palette entries = space-joined names)."""
    channel = {name: c for c, name in enumerate(object_names)}
    planes = np.zeros((len(object_names), max_height, max_width), dtype=np.uint8)
    for y, row in enumerate(record["rows"]):
        for x, index in enumerate(row):
            for name in record["palette"][index].split():
                planes[channel[name], y, x] = 1
    return planes


# Solves games/sokoban.txt level 0 (7x5): walk round the crate and push it right onto the target.
SOKOBAN_LEVEL0_SOLUTION = [1, 1, 0, 3]  # left, left, up, right
