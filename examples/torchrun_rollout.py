"""One psc VectorEnv per GPU under torchrun, episode statistics all-reduced with NCCL.

    torchrun --nproc-per-node 2 examples/torchrun_rollout.py --game games/sokoban.txt
    torchrun --nproc-per-node 1 examples/torchrun_rollout.py     # the same program on one GPU
    python3 examples/torchrun_rollout.py                          # so is this

Each rank steps its own batch on its own GPU (LOCAL_RANK): first --steps
steps with random actions drawn by PyTorch on that GPU and read by the plugin
in place (step_device), counting finished episodes and wins there; then the
plugin's fused random rollout, timed, for throughput.  The counts and the
timings are all-reduced through torch.distributed, and rank 0 prints the
totals and the aggregate steps/s (all ranks' steps over the slowest rank's
time).  psc brings no distribution layer of its own: ranks, devices and
collectives are PyTorch's.  Exits 1 if a rank finds its batch or PyTorch's
current device anywhere but on its own GPU.
"""

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))  # run from a checkout without installing the package

import torch  # noqa: E402
import torch.distributed as dist  # noqa: E402

import psc  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--game", default=str(REPO / "games" / "sokoban.txt"))
    parser.add_argument("--level", type=int, default=0)
    parser.add_argument("--num-envs", type=int, default=65536, help="environments per GPU")
    parser.add_argument("--steps", type=int, default=200, help="step_device steps counted into the statistics")
    parser.add_argument("--rollout-steps", type=int, default=0, help="steps of one timed rollout; 0: about 0.25 s")
    parser.add_argument("--repeats", type=int, default=5, help="timed rollouts (the median is reported)")
    parser.add_argument("--json", help="rank 0 writes the results here")
    args = parser.parse_args()

    if "RANK" not in os.environ:  # plain python3: a world of one
        os.environ.update(RANK="0", LOCAL_RANK="0", WORLD_SIZE="1", MASTER_ADDR="127.0.0.1", MASTER_PORT="29500")
    dist.init_process_group("nccl")
    rank, world = dist.get_rank(), dist.get_world_size()
    local_rank = int(os.environ.get("LOCAL_RANK", rank))
    torch.cuda.set_device(local_rank)
    device = torch.device("cuda", local_rank)

    # Rank 0 builds the plugin while the others wait, then they find it in the cache (builds at
    # once are safe too, but each rank would compile the same code).
    if rank == 0:
        plugin = psc.compile(args.game, target="all", levels=[args.level])
    dist.barrier(device_ids=[local_rank])
    if rank != 0:
        plugin = psc.compile(args.game, target="all", levels=[args.level])

    env = psc.VectorEnv(plugin, args.num_envs, backend="cuda", device=local_rank, levels=args.level)
    env.set_stream(torch.cuda.current_stream(device).cuda_stream)
    env.reset(seed=1000 * rank)
    problems = []
    if env.buffers.device != local_rank:
        problems.append(f"rank {rank}: batch on device {env.buffers.device}, not {local_rank}")

    # Statistics: episodes end on a win or on the step after one (next-step auto-reset).
    terminated = torch.from_dlpack(env.buffers.terminated)
    won = torch.from_dlpack(env.buffers.won)
    if terminated.device != device:
        problems.append(f"rank {rank}: buffers seen on {terminated.device}, not {device}")
    episodes = torch.zeros((), dtype=torch.int64, device=device)
    wins = torch.zeros((), dtype=torch.int64, device=device)
    generator = torch.Generator(device=device).manual_seed(rank)
    action_count = env.single_action_space.n
    for _ in range(args.steps):
        actions = torch.randint(0, action_count, (args.num_envs,), device=device, dtype=torch.int32, generator=generator)
        env.step_device(actions)
        episodes += terminated.sum()
        wins += won.sum()
    env.synchronize()
    if torch.cuda.current_device() != local_rank:
        problems.append(f"rank {rank}: PyTorch's current device became {torch.cuda.current_device()}")

    # Throughput: the fused rollout, calibrated to about 0.25 s, every rank starting together.
    steps = args.rollout_steps
    if steps <= 0:
        steps = 16
        while True:
            start = time.perf_counter()
            env.random_rollout(steps, seed=rank)
            seconds = time.perf_counter() - start
            if seconds > 0.05 or steps >= 1 << 20:
                break
            steps *= 4
        steps = max(1, int(steps * 0.25 / seconds))
        calibrated = torch.tensor([steps], device=device)
        dist.all_reduce(calibrated, op=dist.ReduceOp.MIN)  # every rank runs the same steps
        steps = int(calibrated.item())
    env.random_rollout(steps, seed=rank)  # warm-up
    aggregate = []
    for repeat in range(args.repeats):
        dist.barrier(device_ids=[local_rank])
        start = time.perf_counter()
        stats = env.random_rollout(steps, seed=repeat * world + rank)  # returns once the GPU is done
        seconds = torch.tensor([time.perf_counter() - start], dtype=torch.float64, device=device)
        done = torch.tensor([stats["steps"]], dtype=torch.float64, device=device)
        dist.all_reduce(seconds, op=dist.ReduceOp.MAX)
        dist.all_reduce(done, op=dist.ReduceOp.SUM)
        aggregate.append(done.item() / seconds.item())

    counts = torch.stack([episodes, wins, torch.tensor(args.steps * args.num_envs, device=device)])
    dist.all_reduce(counts, op=dist.ReduceOp.SUM)
    failed = torch.tensor([len(problems)], device=device)
    dist.all_reduce(failed, op=dist.ReduceOp.SUM)
    for line in problems:
        print(f"FAIL  {line}", flush=True)
    if rank == 0:
        result = {
            "game": Path(args.game).stem,
            "level": args.level,
            "gpus": world,
            "envs_per_gpu": args.num_envs,
            "gpu": torch.cuda.get_device_name(device),
            "episodes": int(counts[0]),
            "wins": int(counts[1]),
            "stepped": int(counts[2]),
            "rollout_steps": steps,
            "aggregate_steps_per_s": statistics.median(aggregate),
            "aggregate_min": min(aggregate),
            "failures": int(failed.item()),
        }
        print(
            f"{result['game']} level {args.level}: {world} GPU(s) x {args.num_envs} environments ({result['gpu']}); "
            f"step_device: {result['stepped']} steps, {result['episodes']} episodes ended, {result['wins']} wins; "
            f"rollout: {result['aggregate_steps_per_s']:.4g} steps/s together (median of {args.repeats}, "
            f"min {result['aggregate_min']:.4g})",
            flush=True,
        )
        if args.json:
            Path(args.json).write_text(json.dumps(result) + "\n")
    env.close()
    dist.destroy_process_group()
    return 1 if failed.item() else 0


if __name__ == "__main__":
    sys.exit(main())
