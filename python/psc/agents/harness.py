"""The evaluation harness: runs episodes of chosen levels with an agent,
many at once (one psc batch per wave of episodes, the agents' requests in
parallel), and writes what happened (docs/agents.md, "Logs").

Episode (level L, run r) has the seed r * 1000 + L (script-doctor's
convention): its random agent, its level's random stream and the seed sent to
chat endpoints all follow it, so a run is reproduced by its arguments, and
the logs do not depend on --concurrency.
"""

import collections
import json
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from typing import Callable, Dict, List, Optional, Sequence

from ..build import source_path_for
from .agents import Episode, agent_factory
from .client import ChatClient, ChatError
from .progress import Distances, InputPath, state_key
from .prompt import SYSTEM_PROMPT, Turn, build_prompt, messages, parse_reply
from .text_env import TextVectorEnv


def episode_seed(run: int, level: int) -> int:
    return run * 1000 + level


@dataclass
class EvalConfig:
    game: str
    out: str
    levels: Optional[List[int]] = None  # None: every level
    runs: int = 10
    max_steps: int = 100
    agent: str = "random"
    history: int = 0  # past turns shown in the prompt
    action_set: str = "full"
    concurrency: int = 16  # episodes played at once
    progress: bool = True  # solver distances of visited states
    solve_time_limit: float = 10.0  # seconds per psc solve
    endpoint: Optional[str] = None
    model: Optional[str] = None
    temperature: float = 0.0
    max_tokens: Optional[int] = None
    timeout: float = 60.0
    retries: int = 2
    psc_binary: Optional[str] = None
    api_key: Optional[str] = field(default=None, repr=False)


@dataclass
class _Slot:
    """One episode in flight."""

    episode: Episode
    agent: Callable[[List[dict]], str]
    path: InputPath
    history: collections.deque
    steps: List[dict] = field(default_factory=list)
    actions: List[Optional[str]] = field(default_factory=list)
    won: bool = False
    ended: bool = False
    total_reward: float = 0.0
    invalid: int = 0
    errors: int = 0
    start_distance: dict = field(default_factory=dict)
    distances: List[Optional[int]] = field(default_factory=list)


def _episode_summary(slot: _Slot, name: str, measured: bool) -> dict:
    """measured: the solver's distances were computed (--progress)."""
    known = [d for d in [slot.start_distance.get("distance")] + slot.distances if d is not None]
    start = slot.start_distance.get("distance")
    best = min(known) if known else None
    progress = None
    if measured and slot.won:
        progress = 1.0
    elif start and best is not None:
        progress = round((start - best) / start, 4)
    return {
        "episode": name,
        "level": slot.episode.level,
        "run": slot.episode.run,
        "seed": slot.episode.seed,
        "won": slot.won,
        "steps": len(slot.steps),
        "return": slot.total_reward,
        "invalid_actions": slot.invalid,
        "request_errors": slot.errors,
        "start_distance": start,
        "start_status": slot.start_distance.get("status"),
        "best_distance": best,
        "final_distance": slot.distances[-1] if slot.distances else start,
        "progress": progress,
        "solution_length": len(slot.path.inputs) if slot.won and slot.path.inputs is not None else None,
        "actions": slot.actions,
    }


def _summarise(episodes: Sequence[dict], levels: Sequence[int]) -> dict:
    per_level = {}
    for level in levels:
        mine = [e for e in episodes if e["level"] == level]
        if not mine:
            continue
        wins = [e for e in mine if e["won"]]
        progress = [e["progress"] for e in mine if e["progress"] is not None]
        optimum = next((e["start_distance"] for e in mine if e["start_distance"] is not None), None)
        lengths = [e["solution_length"] for e in wins if e["solution_length"] is not None]
        steps = sum(e["steps"] for e in mine)
        per_level[str(level)] = {
            "episodes": len(mine),
            "wins": len(wins),
            "win_rate": round(len(wins) / len(mine), 4),
            "mean_progress": round(sum(progress) / len(progress), 4) if progress else None,
            "optimal_length": optimum,
            "mean_solution_length": round(sum(lengths) / len(lengths), 2) if lengths else None,
            "invalid_rate": round(sum(e["invalid_actions"] for e in mine) / steps, 4) if steps else 0.0,
        }
    wins = sum(e["won"] for e in episodes)
    return {
        "episodes": len(episodes),
        "wins": wins,
        "win_rate": round(wins / len(episodes), 4) if episodes else None,
        "levels": per_level,
    }


class Harness:
    def __init__(self, config: EvalConfig, make_agent: Optional[Callable[[Episode], Callable]] = None):
        self.config = config
        probe = TextVectorEnv(config.game, 1, action_set=config.action_set, psc_binary=config.psc_binary)
        self.game = probe.game
        self.info = probe.info
        self.plugin_path = probe.plugin_path
        probe.close()
        self.levels = list(range(self.info.level_count)) if config.levels is None else list(config.levels)
        for level in self.levels:
            if not 0 <= level < self.info.level_count:
                raise ValueError(f"level {level} out of range [0, {self.info.level_count})")
        needs_solver = config.progress or config.agent == "solver"
        self.distances = (
            Distances(self._source_path(), self.plugin_path, self.info.uses_random, config.solve_time_limit, config.psc_binary)
            if needs_solver
            else None
        )
        if make_agent is None:
            client = None
            if config.agent == "chat":
                if not config.endpoint or not config.model:
                    raise ValueError("--agent chat needs --endpoint and --model")
                client = ChatClient(
                    config.endpoint, config.model, config.api_key, config.temperature, config.max_tokens,
                    config.timeout, config.retries,
                )
            make_agent = agent_factory(config.agent, self.distances, client)
        self.make_agent = make_agent

    def run(self) -> dict:
        config = self.config
        os.makedirs(config.out, exist_ok=True)
        episodes = [(level, run) for level in self.levels for run in range(config.runs)]
        summaries = []
        with open(os.path.join(config.out, "config.json"), "w") as f:
            settings = {k: v for k, v in asdict(config).items() if k != "api_key"}
            json.dump({**settings, "levels": self.levels, "system_prompt": SYSTEM_PROMPT, "title": self.game.title,
                       "actions": list(self.game.actions)}, f, indent=1)
        with ThreadPoolExecutor(max_workers=max(1, config.concurrency)) as pool, open(
            os.path.join(config.out, "steps.jsonl"), "w"
        ) as steps_file, open(os.path.join(config.out, "episodes.jsonl"), "w") as episodes_file:
            for start in range(0, len(episodes), max(1, config.concurrency)):
                wave = episodes[start : start + max(1, config.concurrency)]
                for name, slot in self._play_wave(wave, pool):
                    for line in slot.steps:
                        steps_file.write(json.dumps(line, ensure_ascii=False) + "\n")
                    summary = _episode_summary(slot, name, config.progress)
                    episodes_file.write(json.dumps(summary) + "\n")
                    summaries.append(summary)
        result = _summarise(summaries, self.levels)
        result.update({"game": config.game, "title": self.game.title, "agent": config.agent, "model": config.model})
        with open(os.path.join(config.out, "summary.json"), "w") as f:
            json.dump(result, f, indent=1)
        return result

    def _play_wave(self, wave, pool):
        config = self.config
        env = TextVectorEnv(
            self.plugin_path, len(wave), max_steps=config.max_steps, action_set=config.action_set,
            source=self._source_path(),
        )
        levels = [level for level, _ in wave]
        seeds = [episode_seed(run, level) for level, run in wave]
        texts, _ = env.reset(seeds, levels)
        slots = []
        for i, ((level, run), seed) in enumerate(zip(wave, seeds)):
            episode = Episode(level, run, seed, self.game.actions)
            slots.append(_Slot(episode, None, InputPath(self.info.uses_random), collections.deque(maxlen=config.history)))
            # A level its start wins is over before the agent's first turn, as in the original engine.
            slots[-1].won = slots[-1].ended = env.start_won(i)
        # Agents are made in parallel: the solver agent's search runs then.
        for slot, agent in zip(slots, pool.map(self.make_agent, [s.episode for s in slots])):
            slot.agent = agent
        if self.distances is not None and config.progress:
            starts = pool.map(lambda i: self._distance(env, i, slots[i], False), range(len(slots)))
            for slot, start in zip(slots, starts):
                slot.start_distance = start
        turn = 1
        while not all(slot.ended for slot in slots):
            active = [i for i, slot in enumerate(slots) if not slot.ended]
            prompts = {i: build_prompt(self.game, texts[i], turn, config.max_steps, list(slots[i].history)) for i in active}
            replies = dict(zip(active, pool.map(lambda i: self._ask(slots[i], prompts[i]), active)))
            before = {i: state_key(env.record(i)) for i in active}
            actions: List[Optional[str]] = [None] * len(slots)
            verdicts = {}
            for i in active:
                reply, error = replies[i]
                action, why = parse_reply(reply, self.game.actions)
                actions[i] = action
                verdicts[i] = (error or why) if action is None else None
            shown = texts
            texts, rewards, terminated, truncated, infos = env.step(actions)
            for i in active:
                slot = slots[i]
                changed = state_key(env.record(i)) != before[i]
                if actions[i] is not None:
                    slot.path.played(actions[i], changed)
                slot.won = slot.won or infos[i]["level_won"]
                slot.ended = terminated[i] or truncated[i]
                slot.total_reward += rewards[i]
                slot.invalid += actions[i] is None
                slot.errors += replies[i][1] is not None
                slot.actions.append(actions[i])
            distances = {}
            if self.distances is not None and config.progress:
                distances = dict(zip(active, pool.map(lambda i: self._distance(env, i, slots[i], slots[i].won), active)))
            for i in active:
                slot = slots[i]
                distance = distances.get(i, {})
                slot.distances.append(distance.get("distance"))
                slot.history.append(Turn(shown[i], actions[i]))
                slot.steps.append(
                    {
                        "episode": _name(slot.episode),
                        "level": slot.episode.level,
                        "run": slot.episode.run,
                        "seed": slot.episode.seed,
                        "step": turn,
                        "prompt": prompts[i],
                        "reply": replies[i][0],
                        "action": actions[i],
                        "invalid": verdicts[i],
                        "reward": rewards[i],
                        "terminated": terminated[i],
                        "truncated": truncated[i],
                        "state": texts[i],
                        "distance": distance.get("distance"),
                        "distance_status": distance.get("status"),
                    }
                )
            turn += 1
        env.close()
        return [(_name(slot.episode), slot) for slot in slots]

    def _source_path(self) -> str:
        """The game source: the game file, or the one kept beside a plugin."""
        game = self.config.game
        return source_path_for(game) if game.endswith((".so", ".dylib", ".dll")) else game

    def _ask(self, slot: _Slot, prompt: str):
        try:
            return slot.agent(messages(prompt)), None
        except ChatError as e:
            return None, str(e)

    def _distance(self, env: TextVectorEnv, i: int, slot: _Slot, won: bool) -> dict:
        return self.distances.distance(slot.episode.level, slot.episode.seed, slot.path.inputs, env.record(i), won)


def _name(episode: Episode) -> str:
    return f"L{episode.level}-r{episode.run}"
