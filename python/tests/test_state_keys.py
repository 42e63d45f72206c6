"""State keys and batched expansion (psc_encode_states, psc_decode_state,
psc_canonical_keys, psc_expand): a key's children must be exactly what
stepping the environment it came from gives, in search's form, for every
input, along random walks of bundled games, and a child decoded over a fresh
start of the level must show the stepped environment's objects (keys leave out
objects that never change) or, where search's form took one object for
another (gems' colours), behave as it under the inputs that follow."""

import numpy as np
import pytest
from helpers import GAMES

import psc
from psc import _abi
from psc.batch import Batch

EXPAND_WON, EXPAND_UNCHANGED, EXPAND_INVALID, EXPAND_TIMED_OUT = 1, 2, 8, 16
INPUTS = [0, 1, 2, 3, 4, 5, 6]  # up, left, down, right, action, undo, restart


def cpu_batch(plugin_path: str, num_envs: int) -> Batch:
    # Undo off (a key has no history) and episodes that stop at a win, as expansion does.
    return Batch(psc.Plugin(plugin_path), num_envs, _abi.BACKEND_CPU, 1, 0, 2, 0)


@pytest.mark.parametrize("game", ["sokoban", "gems", "rigid", "ice"])
def test_children_equal_stepping_every_input(game):
    batch = cpu_batch(psc.compile(GAMES / f"{game}.txt"), 3)
    rng = np.random.default_rng(7)
    info = batch.plugin.info
    checked = 0
    folds_seen = False
    for level in batch.plugin.playable_levels():
        batch.reset([level, level, level], [11, 11, 11])
        for _ in range(40):
            parent, parent_hash = batch.encode_states([0])
            children, flags, hashes, estimates = batch.expand(0, parent, INPUTS)
            assert np.array_equal(estimates, batch.estimate_distance(0, children))
            saved = batch.save_state(0)
            for a, action in enumerate(INPUTS):
                batch.load_state(1, saved)
                won = batch.step([0, action, 0])[1]["won"]
                stepped, _ = batch.encode_states([1])
                folded, folded_hash = batch.canonical_keys(stepped)
                assert np.array_equal(children[a], folded[0]), f"{game} level {level} input {action}"
                assert hashes[a] == folded_hash[0]
                assert bool(flags[a] & EXPAND_WON) == bool(won)
                assert bool(flags[a] & EXPAND_UNCHANGED) == np.array_equal(children[a], parent[0])
                batch.reset([level], [11], env_ids=[2])
                batch.decode_state(2, children[a])
                if np.array_equal(folded, stepped):
                    assert batch.dump_state(2) == batch.dump_state(1), f"{game} level {level} input {action}: decoded"
                else:
                    folds_seen = True
                    for follow in rng.integers(0, 5, size=4):
                        results = batch.step([0, int(follow), int(follow)])
                        assert results[1]["won"] == results[2]["won"]
                        keys, _ = batch.canonical_keys(batch.encode_states([1, 2])[0])
                        assert np.array_equal(keys[0], keys[1]), f"{game} level {level} input {action}: decoded's future"
                checked += 1
            step = batch.step([int(rng.integers(0, 5)), 0, 0])[0]
            if step["won"]:
                break
    assert checked > 0
    assert folds_seen == (game == "gems")  # gems' three colours are alike to every rule
    assert info.state_key_bytes % 8 == 0


def test_decode_gives_back_the_state_and_its_future():
    batch = cpu_batch(psc.compile(GAMES / "gems.txt"), 2)  # random spawns: the stream is in the key
    batch.reset([0, 0], [5, 5])
    for action in [3, 3, 2, 1, 0, 3]:
        batch.step([action, 0])
    key, h = batch.encode_states([0])
    batch.decode_state(1, key[0])
    again, h2 = batch.encode_states([1])
    assert np.array_equal(key, again) and h[0] == h2[0]
    for action in [2, 2, 3, 1, 4]:
        batch.step([action, action])
        assert batch.dump_state(0) == batch.dump_state(1)


def test_keys_of_different_states_differ_and_of_equal_states_agree():
    batch = cpu_batch(psc.compile(GAMES / "sokoban.txt"), 3)
    batch.reset([0, 0, 0], [1, 1, 1])
    batch.step([1, 3, 1])  # left / right / left
    keys, hashes = batch.encode_states([0, 1, 2])
    assert not np.array_equal(keys[0], keys[1]) and hashes[0] != hashes[1]
    assert np.array_equal(keys[0], keys[2]) and hashes[0] == hashes[2]


def test_misuse_is_refused():
    batch = cpu_batch(psc.compile(GAMES / "sokoban.txt"), 2)
    batch.reset([0, 1], [1, 1])
    key, _ = batch.encode_states([1])
    with pytest.raises(psc.PscError, match="BAD_STATE"):
        batch.expand(0, key, [0])  # a key of level 1 over a template on level 0
    with pytest.raises(psc.PscError, match="BAD_STATE"):
        batch.decode_state(0, key[0])
    own, _ = batch.encode_states([0])
    with pytest.raises(psc.PscError, match="BAD_ACTION"):
        batch.expand(0, own, [8])
    with pytest.raises(psc.PscError, match="BAD_ENV"):
        batch.expand(2, own, [0])


def test_estimate_is_the_distance_of_targets_to_crates():
    # games/sokoban.txt wins with `all target on crate`: the estimate adds, for
    # each target without a crate, the Manhattan distance to the nearest crate.
    batch = cpu_batch(psc.compile(GAMES / "sokoban.txt"), 1)
    for level in batch.plugin.playable_levels():
        batch.reset([level], [1])
        state = batch.dump_state(0)
        cells = {}
        for y, row in enumerate(state["rows"]):
            for x, index in enumerate(row):
                cells[(x, y)] = set(state["palette"][index].split())
        crates = [p for p, names in cells.items() if "crate" in names]
        open_targets = [p for p, names in cells.items() if "target" in names and "crate" not in names]
        expected = sum(min(abs(tx - cx) + abs(ty - cy) for cx, cy in crates) for tx, ty in open_targets)
        key, _ = batch.encode_states([0])
        assert batch.estimate_distance(0, key)[0] == expected > 0


def test_a_passed_deadline_leaves_every_child_out():
    batch = cpu_batch(psc.compile(GAMES / "sokoban.txt"), 1)
    batch.reset([0], [0])
    parent, _ = batch.encode_states([0])
    batch.set_deadline(1e-9)  # passed before the first child
    _, flags, _, _ = batch.expand(0, parent, INPUTS[:5])
    assert list(flags) == [EXPAND_TIMED_OUT] * 5
    batch.set_deadline(0)  # none
    _, flags, _, _ = batch.expand(0, parent, INPUTS[:5])
    assert not any(f & EXPAND_TIMED_OUT for f in flags)
    with pytest.raises(psc.PscError):
        batch.set_deadline(-1)
