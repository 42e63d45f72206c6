"""The win-condition distance and shaped rewards."""

import shutil

import numpy as np
import pytest
from helpers import GAMES, SOKOBAN_LEVEL0_SOLUTION

import psc
from psc.shaped_reward import WinDistance, manhattan_distance_to

NAMES = ("background", "a", "b", "c")
A, B, C = 1, 2, 3


def board(cells, height=4, width=6):
    """One observation (1, C, H, W) with objects at (x, y) cells: {(x, y): [channels]}."""
    planes = np.zeros((1, len(NAMES), height, width), dtype=np.uint8)
    planes[0, 0] = 1
    for (x, y), channels in cells.items():
        for c in channels:
            planes[0, c, y, x] = 1
    return planes


def condition(quantifier, objects, on=None, aggregate1=False, aggregate2=False):
    return {"quantifier": quantifier, "objects": objects, "on": on, "aggregate1": aggregate1, "aggregate2": aggregate2}


def distance(conditions, planes):
    return float(WinDistance(conditions, NAMES, max_width=6, max_height=4)(planes)[0])


def test_manhattan_distance_transform_is_exact():
    rng = np.random.default_rng(0)
    mask = rng.random((3, 5, 7)) < 0.1
    mask[2] = False
    got = manhattan_distance_to(mask)
    for n in range(2):
        points = np.argwhere(mask[n])
        for y in range(5):
            for x in range(7):
                expected = min(abs(y - py) + abs(x - px) for py, px in points) if len(points) else None
                assert got[n, y, x] == expected
    assert (got[2] > 7 + 5).all()  # no target: farther than any cell


def test_all_x_on_y_sums_each_x_distance_to_its_nearest_y():
    # a at (0,0) and (5,3); b at (2,0) and (5,1): distances 2 and 2.
    planes = board({(0, 0): [A], (5, 3): [A], (2, 0): [B], (5, 1): [B]})
    assert distance([condition("all", ["a"], ["b"])], planes) == 4.0
    # An a already on a b counts 0.
    planes = board({(2, 0): [A, B], (5, 3): [A], (5, 1): [B]})
    assert distance([condition("all", ["a"], ["b"])], planes) == 2.0
    # No b at all: PuzzleJAX counts 0.
    assert distance([condition("all", ["a"], ["b"])], board({(0, 0): [A]})) == 0.0


def test_some_x_on_y_takes_the_closest_pair():
    planes = board({(0, 0): [A], (5, 3): [A], (2, 0): [B], (4, 3): [B]})
    assert distance([condition("some", ["a"], ["b"])], planes) == 1.0
    assert distance([condition("some", ["a"], ["b"])], board({(1, 1): [A, B]})) == 0.0
    # Nothing to pair: the width + height of the planes.
    assert distance([condition("some", ["a"], ["b"])], board({(1, 1): [A]})) == 10.0


def test_some_x_and_no_x():
    assert distance([condition("some", ["a"])], board({})) == 1.0
    assert distance([condition("some", ["a"])], board({(3, 3): [A]})) == 0.0
    planes = board({(0, 0): [A], (1, 0): [A, B], (2, 0): [A, B]})
    assert distance([condition("no", ["a"])], planes) == 3.0
    assert distance([condition("no", ["a"], ["b"])], planes) == 2.0


def test_properties_and_aggregates():
    planes = board({(0, 0): [A], (1, 0): [B], (2, 0): [A, B], (5, 3): [C]})
    assert distance([condition("no", ["a", "b"])], planes) == 3.0  # a property: any of them
    assert distance([condition("no", ["a", "b"], aggregate1=True)], planes) == 1.0  # an aggregate: all of them
    # Conditions add up.
    assert distance([condition("no", ["a"]), condition("no", ["c"])], planes) == 3.0


def test_unknown_objects_are_reported():
    with pytest.raises(ValueError, match="not observation channels"):
        WinDistance([condition("no", ["ghost"])], NAMES, 6, 4)


def test_shaped_rewards_on_sokoban(sokoban_plugin):
    # Level 0: the target is one step right of the crate; the solution pushes it there on its last move.
    with psc.VectorEnv(sokoban_plugin, num_envs=1, levels=0, reward="shaped") as env:
        env.reset(seed=0)
        rewards = [env.step([action])[1][0] for action in SOKOBAN_LEVEL0_SOLUTION]
        assert rewards == [0.0, 0.0, 0.0, 2.0]  # distance 1 -> 0, plus the win
        assert env.step([0])[1][0] == 0.0  # the restart step
        # Pushing the crate away is penalised: step left under the crate and push it up, from
        # (2, 2) to (2, 1), two cells from the target at (3, 2).
        rewards = [env.step([action])[1][0] for action in [1, 0]]
        assert rewards == [0.0, -1.0]


def test_shaped_rewards_need_the_ir_beside_a_copied_plugin(sokoban_plugin, tmp_path):
    copy = tmp_path / "sokoban.so"
    shutil.copyfile(sokoban_plugin, copy)
    with pytest.raises(FileNotFoundError, match="sokoban.ir.json"):
        psc.VectorEnv(copy, reward="shaped")
    shutil.copyfile(psc.build.ir_path_for(sokoban_plugin), tmp_path / "sokoban.ir.json")
    with psc.VectorEnv(copy, reward="shaped") as env:
        env.reset(seed=0)


def test_shaped_rewards_from_a_game_source():
    with psc.VectorEnv(GAMES / "sokoban.txt", num_envs=1, reward="shaped") as env:
        env.reset(seed=0)
        assert env.step([3])[1][0] == 0.0
