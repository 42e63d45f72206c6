"""The evaluation harness end to end, against a local chat-completions stub
(chat_stub.py) that replies with scripted moves: a win, bad replies,
timeouts, dropped connections; and the random and solver agents."""

import json

import pytest
from chat_stub import ChatStub, Close, Garbage, Reply, Sleep, Status
from helpers import GAMES, REPO

import psc
from psc.agents import ChatClient, ChatError
from psc.agents.__main__ import main as agents_main
from psc.agents.harness import EvalConfig, Harness

SOKOBAN = str(GAMES / "sokoban.txt")
NAMES = {"u": "up", "l": "left", "d": "down", "r": "right", "x": "action"}


def read_lines(path):
    with open(path) as f:
        return [json.loads(line) for line in f]


def chat_config(tmp_path, url, **options):
    settings = dict(game=SOKOBAN, out=str(tmp_path / "out"), levels=[0], runs=1, max_steps=10, agent="chat",
                    endpoint=url, model="stub-model", timeout=2.0, retries=0, concurrency=1)
    settings.update(options)
    return EvalConfig(**settings)


@pytest.fixture(scope="module")
def solution():
    record = psc.solve(SOKOBAN, 0)
    assert record["status"] == "solved" and record["length"] == 4
    return record["solution"]


def test_the_stub_loop_wins_sokoban_level_0_with_the_solvers_moves(tmp_path, solution):
    script = [Reply(f"The crate must go right.\nACTION: {NAMES[c]}") for c in solution]
    with ChatStub(script) as stub:
        summary = Harness(chat_config(tmp_path, stub.url)).run()
    assert summary["wins"] == 1 and summary["levels"]["0"]["win_rate"] == 1.0
    steps = read_lines(tmp_path / "out" / "steps.jsonl")
    assert [s["action"] for s in steps] == [NAMES[c] for c in solution]
    assert steps[-1]["terminated"] and steps[-1]["reward"] == 1.0
    assert steps[-1]["state"].startswith("Level 0 of 3: won")
    assert steps[0]["prompt"].count("#.*O..#") == 1 and "Rules:\n[ > Player | Crate ]" in steps[0]["prompt"]
    assert [s["distance"] for s in steps] == [3, 2, 1, 0]
    # The protocol: one POST per turn to /v1/chat/completions with the model, both messages and the seed.
    assert len(stub.requests) == 4
    request = stub.requests[0]
    assert request["path"] == "/v1/chat/completions" and request["model"] == "stub-model"
    assert [m["role"] for m in request["messages"]] == ["system", "user"] and request["seed"] == 0
    episode = read_lines(tmp_path / "out" / "episodes.jsonl")[0]
    assert episode["won"] and episode["solution_length"] == 4 and episode["start_distance"] == 4
    assert episode["progress"] == 1.0


def test_bad_replies_are_invalid_moves_that_are_logged(tmp_path, solution):
    bad = [Reply("I am not sure."), Reply("ACTION: jump"), Reply("ACTION: tick"), Garbage()]
    script = bad + [Reply(f"ACTION: {NAMES[c]}") for c in solution]
    with ChatStub(script) as stub:
        summary = Harness(chat_config(tmp_path, stub.url)).run()
    steps = read_lines(tmp_path / "out" / "steps.jsonl")
    assert summary["wins"] == 1 and len(steps) == 8
    reasons = [s["invalid"] for s in steps[:4]]
    assert "no 'ACTION: <name>'" in reasons[0]
    assert "'jump' is not an action" in reasons[1]
    assert "'tick' is not one of the actions offered" in reasons[2]
    assert "not a chat-completions answer" in reasons[3]
    assert all(s["action"] is None and s["reward"] == 0 for s in steps[:4])
    assert len({s["state"] for s in steps[:4]}) == 1  # invalid turns leave the level as it was
    episode = read_lines(tmp_path / "out" / "episodes.jsonl")[0]
    assert episode["invalid_actions"] == 4 and episode["request_errors"] == 1
    assert summary["levels"]["0"]["invalid_rate"] == 0.5


def test_a_timeout_is_retried(tmp_path, solution):
    script = [Sleep(1.5, "ACTION: up")] + [Reply(f"ACTION: {NAMES[c]}") for c in solution]
    with ChatStub(script) as stub:
        summary = Harness(chat_config(tmp_path, stub.url, timeout=0.5, retries=1)).run()
    assert summary["wins"] == 1
    steps = read_lines(tmp_path / "out" / "steps.jsonl")
    assert len(steps) == 4 and steps[0]["invalid"] is None  # the retry got the first move


def test_timeouts_and_dropped_connections_without_retries_are_invalid_turns(tmp_path):
    with ChatStub([Sleep(1.5), Close(), Status(503), Status(400)], default=Close()) as stub:
        summary = Harness(chat_config(tmp_path, stub.url, timeout=0.5, max_steps=5)).run()
    assert summary["wins"] == 0
    steps = read_lines(tmp_path / "out" / "steps.jsonl")
    assert len(steps) == 5 and all(s["action"] is None and s["reply"] is None for s in steps)
    assert "no answer within 0.5 s" in steps[0]["invalid"]
    assert "connection" in steps[1]["invalid"]
    assert "HTTP 503" in steps[2]["invalid"] and "HTTP 400" in steps[3]["invalid"]
    assert steps[-1]["truncated"]


def test_the_client_retries_then_gives_up_clearly():
    with ChatStub([Status(500), Close(), Reply("ACTION: up")]) as stub:
        client = ChatClient(stub.url, "m", timeout=2.0, retries=2, backoff=0.01)
        assert client.complete([{"role": "user", "content": "hi"}]) == "ACTION: up"
        assert len(stub.requests) == 3
    with ChatStub([], default=Close()) as stub:
        client = ChatClient(stub.url, "m", timeout=2.0, retries=1, backoff=0.01)
        with pytest.raises(ChatError, match="2 attempts failed"):
            client.complete([{"role": "user", "content": "hi"}])
    with ChatStub([Status(401)]) as stub:  # not retried: a wrong key stays wrong
        with pytest.raises(ChatError, match="HTTP 401"):
            ChatClient(stub.url, "m", retries=3, backoff=0.01).complete([])
        assert len(stub.requests) == 1


def test_no_server_at_all_is_no_crash(tmp_path):
    with ChatStub([]) as stub:
        url = stub.url  # a port that is closed once the stub is gone
    summary = Harness(chat_config(tmp_path, url, max_steps=2, progress=False)).run()
    steps = read_lines(tmp_path / "out" / "steps.jsonl")
    assert summary["wins"] == 0 and all("connection failed" in s["invalid"] for s in steps)


def test_many_episodes_at_once_give_the_same_logs(tmp_path):
    def run(concurrency, out):
        config = EvalConfig(game=SOKOBAN, out=str(tmp_path / out), levels=[0, 1], runs=3, max_steps=15,
                            agent="random", concurrency=concurrency, progress=False)
        return Harness(config).run()

    one, many = run(1, "one"), run(6, "many")
    assert one == many
    for name in ("steps.jsonl", "episodes.jsonl"):
        assert (tmp_path / "one" / name).read_text() == (tmp_path / "many" / name).read_text()


def test_concurrent_chat_requests_each_get_their_episodes_seed(tmp_path):
    seen = []

    def script(request):
        seen.append(request["seed"])
        return Reply("ACTION: left")

    with ChatStub(script) as stub:
        config = chat_config(tmp_path, stub.url, levels=[0, 1], runs=2, max_steps=3, concurrency=4, progress=False)
        Harness(config).run()
    assert sorted(set(seen)) == [0, 1, 1000, 1001] and len(seen) == 12


def test_the_solver_agent_wins_every_level(tmp_path):
    config = EvalConfig(game=SOKOBAN, out=str(tmp_path / "solver"), runs=1, agent="solver", max_steps=60)
    summary = Harness(config).run()
    assert summary["win_rate"] == 1.0
    episodes = read_lines(tmp_path / "solver" / "episodes.jsonl")
    assert all(e["solution_length"] == e["start_distance"] for e in episodes)


def test_a_level_its_start_wins_is_won_before_any_turn(tmp_path):
    game = str(REPO / "tests" / "search" / "games" / "start_wins.txt")
    config = EvalConfig(game=game, out=str(tmp_path / "start"), levels=[0, 1], runs=1, agent="solver", max_steps=10)
    summary = Harness(config).run()
    assert summary["win_rate"] == 1.0
    episodes = {e["level"]: e for e in read_lines(tmp_path / "start" / "episodes.jsonl")}
    assert episodes[0]["won"] and episodes[0]["steps"] == 0 and episodes[0]["solution_length"] == 0
    assert episodes[1]["won"] and episodes[1]["steps"] == 2 and episodes[1]["solution_length"] == 2


def test_the_command_line(tmp_path, capsys):
    out = tmp_path / "cli"
    assert agents_main(["eval", SOKOBAN, "--levels", "0", "--runs", "2", "--max-steps", "5", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "Crate Yard: " in printed and "win rate" in printed
    assert set(p.name for p in out.iterdir()) == {"config.json", "steps.jsonl", "episodes.jsonl", "summary.json"}
    assert agents_main(["eval", SOKOBAN, "--agent", "chat", "--out", str(out)]) == 2
    assert "--endpoint and --model" in capsys.readouterr().err
    assert agents_main(["eval", SOKOBAN, "--levels", "7", "--out", str(out)]) == 2
    assert agents_main(["eval", "no-such-game.txt", "--out", str(out)]) == 2
    assert agents_main(["prompt", SOKOBAN, "--level", "0"]) == 0
    assert "Map (7x5):" in capsys.readouterr().out
