"""Corpus traces played through psc.TextEnv: every state's text parses back
to exactly the recorded objects (tools/text_roundtrip.py does all traces)."""

import json

import pytest
from test_corpus import CASES, CORPUS

import psc
from psc.agents.text_state import cells_of_record

REPLAY_UNDO_DEPTH = 4096  # as cli/Replay.cpp: deep enough for any trace


@pytest.mark.parametrize("case_id", CASES)
def test_trace_states_parse_back_from_their_text(case_id, tmp_path):
    path = CORPUS / "testsuite" / f"{case_id}.json"
    if not path.exists():
        pytest.skip(f"corpus case {path} is absent (set PSC_CORPUS_DIR)")
    case = json.loads(path.read_text())
    game = tmp_path / f"{case_id}.txt"
    game.write_text(case["game"])
    with psc.TextEnv(game, play_through=True, undo_depth=REPLAY_UNDO_DEPTH, keep_going=True) as env:
        text, _ = env.reset_to_entry(case["start_level"], case["level_seed"])
        assert psc.TextEnv.parse(text) == cells_of_record(case["initial"]), f"{case_id} at the start"
        for i, (name, record) in enumerate(zip(case["inputs"], case["steps"])):
            text, *_ = env.step(name)
            assert psc.TextEnv.parse(text) == cells_of_record(record), f"{case_id} after input {i} ({name})"
