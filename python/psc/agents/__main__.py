"""python3 -m psc.agents eval GAME [--levels 0,1] [--runs 10] [--max-steps 100]
                        [--agent random|solver|chat --endpoint URL --model NAME] --out DIR
python3 -m psc.agents prompt GAME [--level 0]

eval: runs episodes with an agent and writes DIR/steps.jsonl, episodes.jsonl,
summary.json and config.json (docs/agents.md); prints win rates per level.
prompt: prints the system and user messages of a level's first turn.
"""

import argparse
import os
import sys

from ..build import CompileError
from ..plugin import PscError
from .agents import AGENTS
from .harness import EvalConfig, Harness, episode_seed
from .prompt import SYSTEM_PROMPT, build_prompt
from .text_env import TextEnv


def parse_levels(text: str):
    """'0,2,5-7' -> [0, 2, 5, 6, 7]."""
    levels = []
    for part in text.split(","):
        part = part.strip()
        if "-" in part:
            first, last = part.split("-", 1)
            levels += range(int(first), int(last) + 1)
        elif part:
            levels.append(int(part))
    if not levels:
        raise ValueError(f"no levels in {text!r}")
    return levels


def _positive(kind):
    def convert(text):
        value = kind(text)
        if value <= 0:
            raise argparse.ArgumentTypeError(f"must be positive, not {text}")
        return value

    return convert


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python3 -m psc.agents", description="Language-model agents on psc games.")
    commands = parser.add_subparsers(dest="command", required=True)
    ev = commands.add_parser("eval", help="evaluate an agent on levels of a game")
    ev.add_argument("game", help="the game (.txt) or a plugin built by psc.compile / python3 -m psc build")
    ev.add_argument("--levels", help="playable levels, e.g. 0,1,3-5 (default: all)")
    ev.add_argument("--runs", type=_positive(int), default=10, help="episodes per level (default 10)")
    ev.add_argument("--max-steps", type=_positive(int), default=100, help="turns per episode (default 100)")
    ev.add_argument("--agent", choices=AGENTS, default="random")
    ev.add_argument("--endpoint", help="chat: an OpenAI-compatible server, e.g. http://127.0.0.1:8080/v1")
    ev.add_argument("--model", help="chat: the model name sent with each request")
    ev.add_argument("--api-key-env", default="OPENAI_API_KEY", help="chat: environment variable holding the key")
    ev.add_argument("--temperature", type=float, default=0.0)
    ev.add_argument("--max-tokens", type=_positive(int))
    ev.add_argument("--timeout", type=_positive(float), default=60.0, help="chat: seconds per request attempt")
    ev.add_argument("--retries", type=int, default=2, help="chat: further attempts after a failed request")
    ev.add_argument("--history", type=int, default=0, help="past turns (state and action) shown in the prompt")
    ev.add_argument("--action-set", choices=("basic", "full"), default="full",
                    help="basic: directions and action (the paper's); full: also undo, restart (and tick in "
                         "real-time games)")
    ev.add_argument("--concurrency", type=_positive(int), default=16, help="episodes played at once")
    ev.add_argument("--no-progress", dest="progress", action="store_false",
                    help="skip the solver distances of visited states")
    ev.add_argument("--solve-time-limit", type=_positive(float), default=10.0, help="seconds per psc solve")
    ev.add_argument("--psc", dest="psc_binary", help="the psc compiler (default: $PSC_BINARY, build/cli/psc, PATH)")
    ev.add_argument("--out", required=True, help="directory for the logs")
    pr = commands.add_parser("prompt", help="print the messages of a level's first turn")
    pr.add_argument("game")
    pr.add_argument("--level", type=int, default=0)
    pr.add_argument("--max-steps", type=_positive(int), default=100)
    pr.add_argument("--action-set", choices=("basic", "full"), default="full")
    pr.add_argument("--psc", dest="psc_binary")
    return parser


def _print_summary(summary: dict) -> None:
    print(f"{summary['title']}: {summary['wins']}/{summary['episodes']} episodes won ({summary['agent']})")
    print(f"{'level':>5} {'episodes':>8} {'wins':>5} {'win rate':>8} {'progress':>8} {'optimum':>7} {'invalid':>7}")
    for level, row in summary["levels"].items():
        progress = "-" if row["mean_progress"] is None else f"{row['mean_progress']:.2f}"
        optimum = "-" if row["optimal_length"] is None else str(row["optimal_length"])
        print(f"{level:>5} {row['episodes']:>8} {row['wins']:>5} {row['win_rate']:>8.2f} {progress:>8} "
              f"{optimum:>7} {row['invalid_rate']:>7.2f}")


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    try:
        if not os.path.isfile(args.game):
            raise FileNotFoundError(f"no such game file: {args.game}")
        if args.command == "prompt":
            with TextEnv(args.game, level=args.level, action_set=args.action_set, psc_binary=args.psc_binary) as env:
                text, _ = env.reset(seed=episode_seed(0, args.level))
                print("=== system ===\n" + SYSTEM_PROMPT)
                print("=== user ===\n" + build_prompt(env.game, text, 1, args.max_steps))
            return 0
        config = EvalConfig(
            game=args.game, out=args.out, levels=None if args.levels is None else parse_levels(args.levels),
            runs=args.runs, max_steps=args.max_steps, agent=args.agent, history=max(0, args.history),
            action_set=args.action_set, concurrency=args.concurrency, progress=args.progress,
            solve_time_limit=args.solve_time_limit, endpoint=args.endpoint, model=args.model,
            temperature=args.temperature, max_tokens=args.max_tokens, timeout=args.timeout,
            retries=max(0, args.retries), psc_binary=args.psc_binary, api_key=os.environ.get(args.api_key_env),
        )
        summary = Harness(config).run()
    except (ValueError, FileNotFoundError, CompileError, PscError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    _print_summary(summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
