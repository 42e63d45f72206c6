"""Random play on the CPU: steps per second and episodes, through VectorEnv.step and the fused rollout.

    /usr/bin/python3 examples/random_rollout.py                       # games/sokoban.txt, level 0
    /usr/bin/python3 examples/random_rollout.py --game games/gems.txt --num-envs 1024 --steps 500
    /usr/bin/python3 examples/random_rollout.py --gif docs/images/sokoban_random.gif --num-envs 1 --steps 60

--gif saves environment 0's frames as an animation.
"""

import argparse
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))  # run from a checkout without installing the package


import psc  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--game", default=str(REPO / "games" / "sokoban.txt"), help="a game source, compiled on the fly"
    )
    parser.add_argument("--plugin", help="a prebuilt plugin (.so) instead of --game")
    parser.add_argument("--level", type=int, default=0, help="playable level, from 0")
    parser.add_argument("--num-envs", type=int, default=256)
    parser.add_argument("--steps", type=int, default=2000, help="steps of every environment")
    parser.add_argument("--max-episode-steps", type=int, default=200)
    parser.add_argument("--threads", type=int, default=0, help="CPU threads (0: one per core)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--gif", help="save environment 0's frames to this GIF")
    parser.add_argument("--scale", type=int, default=4, help="GIF pixels per sprite pixel")
    args = parser.parse_args()

    env = psc.VectorEnv(
        args.plugin or args.game,
        num_envs=args.num_envs,
        levels=args.level,
        seed=args.seed,
        max_episode_steps=args.max_episode_steps,
        threads=args.threads,
    )
    print(f"{env.info.title}: level {args.level}, {args.num_envs} environments")
    env.reset(seed=args.seed)
    frames = [env.render(0, scale=args.scale)] if args.gif else []
    episodes = wins = 0
    start = time.perf_counter()
    for _ in range(args.steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        episodes += int((terminated | truncated).sum())
        wins += int(terminated.sum())
        if args.gif:
            frames.append(env.render(0, scale=args.scale))
    seconds = time.perf_counter() - start
    total = args.steps * args.num_envs
    print(f"{total} steps in {seconds:.2f} s: {total / seconds:,.0f} steps/s (VectorEnv.step with numpy copies)")
    print(f"{episodes} episodes ended, {wins} won")
    start = time.perf_counter()
    stats = env.random_rollout(args.steps, seed=args.seed)
    seconds = time.perf_counter() - start
    print(f"{stats['steps']} steps in {seconds:.2f} s: {stats['steps'] / seconds:,.0f} steps/s (fused psc_rollout)")
    print(f"{stats['episodes']} episodes ended, {stats['wins']} won")
    if args.gif:
        psc.save_gif(frames, args.gif, fps=8)
        print(f"wrote {args.gif} ({len(frames)} frames)")
    env.close()


if __name__ == "__main__":
    main()
