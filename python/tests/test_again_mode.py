"""A step's `again` chain, whole (the reference's test harness; the default)
or one turn a step (PSC_AGAIN_ONE_TURN, as the reference's player draws it),
and the messages rules show (psc_step_result.message).  games/kick.txt: a
kicked ball rolls right a cell per again turn; a rule says "Goal!" when it
reaches the goal, which wins the level.  Expected positions are read off the
level by hand: level 1 is `#P.o...G#` (player x=1, ball x=3, goal x=7)."""

import numpy as np
import pytest
from helpers import GAMES, REPO

import psc
from psc import _abi
from psc.batch import Batch

UP, LEFT, RIGHT, UNDO, TICK = 0, 1, 3, 5, 7


@pytest.fixture(scope="module")
def kick_plugin() -> psc.Plugin:
    return psc.Plugin(psc.compile(GAMES / "kick.txt"))


def make_batch(plugin: psc.Plugin, mode: int, level: int = 0) -> Batch:
    batch = Batch(plugin, 1, _abi.BACKEND_CPU, 1, 100, _abi.AUTO_RESET_OFF, 0, again_mode=mode)
    batch.reset([level], [0])
    return batch


def columns(batch: Batch, name: str):
    """The x of every `name` object, row by row."""
    planes = batch.observe()[0]
    channel = batch.plugin.info.object_names.index(name)
    ys, xs = np.nonzero(planes[channel])
    return sorted(zip(ys.tolist(), xs.tolist()))


def test_the_game_lists_its_rule_messages(kick_plugin):
    assert kick_plugin.info.rule_messages == ("Goal!",)
    assert kick_plugin.info.again_interval == pytest.approx(0.2)


def test_settle_runs_the_whole_chain_and_reports_the_message(kick_plugin):
    batch = make_batch(kick_plugin, _abi.AGAIN_SETTLE)
    first = batch.step([RIGHT])[0]
    assert (first["message"], first["againing"], first["won"]) == (-1, 0, 0)
    kick = batch.step([RIGHT])[0]
    assert kick["won"] == 1 and kick["againing"] == 0
    assert kick_plugin.info.rule_messages[kick["message"]] == "Goal!"


def test_one_turn_a_step_rolls_the_ball_a_cell_a_step(kick_plugin):
    batch = make_batch(kick_plugin, _abi.AGAIN_ONE_TURN)
    batch.step([RIGHT])
    kick = batch.step([RIGHT])[0]
    assert (kick["againing"], kick["message"], kick["won"]) == (1, -1, 0)
    assert columns(batch, "rolling") == [(1, 4)] and columns(batch, "player") == [(1, 3)]
    turn = batch.step([TICK])[0]
    assert turn["againing"] == 1 and columns(batch, "rolling") == [(1, 5)]
    # An input while a turn is due runs that turn instead: the player stays.
    dropped = batch.step([LEFT])[0]
    assert dropped["againing"] == 1 and columns(batch, "rolling") == [(1, 6)]
    assert columns(batch, "player") == [(1, 3)]
    last = batch.step([TICK])[0]
    assert (last["won"], last["againing"]) == (1, 0)
    assert kick_plugin.info.rule_messages[last["message"]] == "Goal!"


def test_undo_during_a_chain_goes_back_before_the_input(kick_plugin):
    batch = make_batch(kick_plugin, _abi.AGAIN_ONE_TURN)
    batch.step([RIGHT])
    before_kick = batch.observe().copy()
    batch.step([RIGHT])
    batch.step([TICK])
    undone = batch.step([UNDO])[0]
    assert undone["againing"] == 0
    assert np.array_equal(batch.observe(), before_kick)


def test_one_turn_steps_end_where_settling_does(kick_plugin):
    # Level 2: `#Po..#..#`; the kicked ball rolls until the wall stops it at x=4.
    settled = make_batch(kick_plugin, _abi.AGAIN_SETTLE, level=1)
    settled.step([RIGHT])
    turns = make_batch(kick_plugin, _abi.AGAIN_ONE_TURN, level=1)
    steps = 1
    result = turns.step([RIGHT])[0]
    while result["againing"]:
        result = turns.step([TICK])[0]
        steps += 1
    assert steps == 2  # the kick (ball to x=3), then one again turn (x=4)
    assert columns(turns, "rolling") == [(2, 4)]
    assert np.array_equal(turns.observe(), settled.observe())
    assert turns.encode_states([0])[0].tobytes() == settled.encode_states([0])[0].tobytes()


def test_games_without_rule_messages_report_none(sokoban_plugin):
    batch = Batch(psc.Plugin(sokoban_plugin), 2, _abi.BACKEND_CPU, 1, 0, _abi.AUTO_RESET_OFF, 0)
    results = batch.step([LEFT, UP])
    assert list(results["message"]) == [-1, -1] and list(results["againing"]) == [0, 0]


def test_step_results_reserved_bytes_are_zero(kick_plugin, sokoban_plugin):
    # psc_plugin.h promises zeros there, so that a later ABI can give them a meaning.
    for plugin in (kick_plugin, psc.Plugin(sokoban_plugin)):
        for mode in (_abi.AGAIN_SETTLE, _abi.AGAIN_ONE_TURN):
            batch = Batch(plugin, 3, _abi.BACKEND_CPU, 1, 10, _abi.AUTO_RESET_SAME_STEP, 0, again_mode=mode)
            batch.reset([0, 1, 0], [0, 0, 0])
            for action in (RIGHT, RIGHT, UP, UNDO, LEFT, TICK):
                results = batch.step([action] * 3)
                assert results["reserved"].tolist() == [[0, 0, 0]] * 3, (mode, action)


def test_an_unknown_again_mode_is_refused(kick_plugin):
    with pytest.raises(psc.PscError, match="again_mode"):
        Batch(kick_plugin, 1, _abi.BACKEND_CPU, 1, 0, _abi.AUTO_RESET_OFF, 0, again_mode=2)


def test_cuda_batches_step_turns_and_messages_as_the_cpu():
    """Skipped unless a CUDA device is usable (the GPU check runs it)."""
    try:
        plugin = psc.Plugin(psc.compile(GAMES / "kick.txt", target="all"))
    except psc.CompileError as e:
        pytest.skip(f"this psc builds no CUDA plugins: {e}")
    actions = [RIGHT, RIGHT, TICK, LEFT, TICK, TICK, RIGHT, UP, RIGHT, RIGHT, TICK, TICK, UNDO, RIGHT, TICK]
    for mode in (_abi.AGAIN_SETTLE, _abi.AGAIN_ONE_TURN):
        try:
            cuda = Batch(plugin, 2, _abi.BACKEND_CUDA, 1, 100, _abi.AUTO_RESET_OFF, 0, again_mode=mode)
        except psc.PscError as e:
            pytest.skip(f"no usable CUDA device: {e}")
        cpu = Batch(plugin, 2, _abi.BACKEND_CPU, 1, 100, _abi.AUTO_RESET_OFF, 0, again_mode=mode)
        for batch in (cuda, cpu):
            batch.reset([0, 1], [0, 0])
        for action in actions:
            got, want = cuda.step([action, action]), cpu.step([action, action])
            for field in ("won", "againing", "message", "reward"):
                assert list(got[field]) == list(want[field]), (mode, action, field)
            assert got["reserved"].tolist() == [[0, 0, 0]] * 2, (mode, action)
            assert np.array_equal(cuda.observe(), cpu.observe())


def test_a_start_whose_chain_never_settles_says_so():
    # tests/search/games/endless.txt: level 2's shuttle runs from the start and never stops; levels 0 and 1 settle.
    plugin = psc.compile(REPO / "tests" / "search" / "games" / "endless.txt")
    with psc.VectorEnv(plugin, num_envs=3, levels=[0, 1, 2]) as env:
        env.reset(seed=0)
        assert [env.start_cut_off(i) for i in range(3)] == [False, False, True]
