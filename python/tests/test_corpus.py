"""Replays of reference-engine traces (../shared/corpus/testsuite) through
VectorEnv: every observation must equal the recorded state.

The harness semantics (corpus FORMAT.md, as cli/Replay.cpp drives them): the
case starts at LEVELS entry `start_level` with every level load seeded by
`level_seed`; wins play on to the next entry (no auto-reset); undo, restart
and tick are actions 5, 6 and 7.
"""

import json
import os
from pathlib import Path

import numpy as np
import pytest
from helpers import REPO, planes_from_record

import psc
from psc._abi import ACTION_NAMES

CORPUS = Path(os.environ.get("PSC_CORPUS_DIR", REPO.parent / "shared" / "corpus"))
REPLAY_UNDO_DEPTH = 4096  # as cli/Replay.cpp: deep enough for any trace

CASES = [
    "ts-0001-sokoban-with-win-condition",  # a win, then the next level
    "ts-0094-50-objects",  # random rules, the action input
    "ts-0130-undoing-reset-undoes-two-steps-not-one-453",  # restart and undo
    "ts-0132-test-travelling-through-multiple-levels",
    "ts-0325-undo-and-real-time-796",  # tick inputs of a realtime game
    "ts-0387-aggregates-in-win-conditions-5",
    "ts-0412-cover-random-bit-of-getpropertiesfromcell",  # random, restart, undo
]


@pytest.fixture(scope="module")
def games_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("corpus-games")


@pytest.mark.parametrize("case_id", CASES)
def test_replay_matches_the_reference(case_id, games_dir):
    path = CORPUS / "testsuite" / f"{case_id}.json"
    if not path.exists():
        pytest.skip(f"corpus case {path} is absent (set PSC_CORPUS_DIR)")
    case = json.loads(path.read_text())
    game = games_dir / f"{case_id}.txt"
    game.write_text(case["game"])
    plugin = psc.compile(game, keep_going=True)  # the reference plays games with up to five errors
    with psc.VectorEnv(
        plugin, num_envs=1, autoreset=False, undo_depth=REPLAY_UNDO_DEPTH, full_action_space=True
    ) as env:
        info = env.info

        def check(observations, record, label):
            expected = planes_from_record(record, env.object_names, info.max_height, info.max_width)
            np.testing.assert_array_equal(observations[0], expected, err_msg=f"{case_id} {label}")
            recorded = {k: v for k, v in record.items() if k != "sfx"}  # psc does not reproduce sounds
            assert env.dump_state(0) == recorded, f"{case_id} {label}"

        env.reset_to_entry(0, case["start_level"], case["level_seed"])
        check(env.observe(), case["initial"], "at the start")
        for i, (name, record) in enumerate(zip(case["inputs"], case["steps"])):
            observations, *_ = env.step([ACTION_NAMES.index(name)])
            check(observations, record, f"after input {i} ({name})")
