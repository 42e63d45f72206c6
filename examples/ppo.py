"""PPO on a psc game, in one file (PyTorch).

    python3 examples/ppo.py --plugin sokoban.so          # CUDA, zero-copy (plugin built with --target all)
    python3 examples/ppo.py --backend cpu --num-envs 64   # CPU batch, torch on the CPU

Learns games/sokoban.txt level 0 (push one crate one cell; four moves) by
default.  The environments and the network share the GPU: observations,
rewards and episode ends are torch views of the plugin's own buffers
(env.buffers through DLPack) and actions go back as a device tensor
(env.step_device), so no step copies anything to the host.  Rewards are the
plugin's: 1 for winning the level.  Each update appends its mean episode
return, win rate and losses to the CSV (--csv); training stops at
--time-limit seconds, --total-steps, or when the win rate reaches
--target-win-rate.

Next-step auto-reset: the step after an episode ends only restarts that
environment (its action is ignored, reward 0).  Such steps are masked out of
the loss, and a truncated episode bootstraps from its final observation,
which the ending step returned.
"""

import argparse
import csv
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))  # run from a checkout without installing the package

import torch  # noqa: E402
import torch.nn as nn  # noqa: E402

import psc  # noqa: E402


CSV_COLUMNS = ("update", "env_steps", "seconds", "episodes", "mean_return", "win_rate", "mean_length",
               "policy_loss", "value_loss", "entropy")  # fmt: skip


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--plugin", help="a prebuilt plugin (.so; --target all for CUDA) instead of --game")
    p.add_argument("--game", default=str(REPO / "games" / "sokoban.txt"))
    p.add_argument("--level", type=int, default=0, help="playable level, from 0")
    p.add_argument("--backend", default="cuda", choices=["cuda", "cpu"])
    p.add_argument("--num-envs", type=int, default=1024)
    p.add_argument("--rollout-steps", type=int, default=32, help="steps of every environment per update")
    p.add_argument("--max-episode-steps", type=int, default=20, help="truncate episodes (level 0 takes 4 moves)")
    p.add_argument("--total-steps", type=int, default=50_000_000)
    p.add_argument("--time-limit", type=float, default=170.0, help="seconds of training")
    p.add_argument("--target-win-rate", type=float, default=0.98, help="stop when an update's episodes win this often")
    p.add_argument("--lr", type=float, default=2.5e-4)
    p.add_argument("--gamma", type=float, default=0.99)
    p.add_argument("--gae-lambda", type=float, default=0.95)
    p.add_argument("--clip", type=float, default=0.2)
    p.add_argument("--epochs", type=int, default=4)
    p.add_argument("--minibatches", type=int, default=4)
    p.add_argument("--ent-coef", type=float, default=0.01)
    p.add_argument("--vf-coef", type=float, default=0.5)
    p.add_argument("--max-grad-norm", type=float, default=0.5)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--csv", default="ppo_log.csv")
    return p.parse_args()


class Agent(nn.Module):
    """A small CNN over the multi-hot planes, with policy and value heads."""

    def __init__(self, channels: int, height: int, width: int, actions: int):
        super().__init__()
        self.body = nn.Sequential(
            nn.Conv2d(channels, 32, 3, padding=1),
            nn.ReLU(),
            nn.Conv2d(32, 64, 3, padding=1),
            nn.ReLU(),
            nn.Flatten(),
            nn.Linear(64 * height * width, 256),
            nn.ReLU(),
        )
        self.policy = nn.Linear(256, actions)
        self.value = nn.Linear(256, 1)

    def forward(self, observations: torch.Tensor):
        hidden = self.body(observations.float())
        return self.policy(hidden), self.value(hidden).squeeze(-1)


def main() -> None:
    args = parse_args()
    torch.manual_seed(args.seed)
    # Argument checks of torch.distributions read values back to the host at every step.
    torch.distributions.Distribution.set_default_validate_args(False)
    device = torch.device("cuda" if args.backend == "cuda" else "cpu")
    if args.backend == "cuda":
        plugin = args.plugin or psc.compile(args.game, levels=[args.level], target="all")
    else:
        plugin = args.plugin or psc.compile(args.game, levels=[args.level], target="cpu")
    env = psc.VectorEnv(
        plugin,
        num_envs=args.num_envs,
        backend=args.backend,
        levels=args.level,
        seed=args.seed,
        max_episode_steps=args.max_episode_steps,
    )
    if args.backend == "cuda":
        env.set_stream(torch.cuda.current_stream().cuda_stream)  # plugin work ordered with torch's
    env.reset(seed=args.seed)
    # Views of the plugin's buffers: each step_device() updates them in place.
    observations = torch.from_dlpack(env.buffers.observations)
    step_rewards = torch.from_dlpack(env.buffers.rewards)
    step_terminated = torch.from_dlpack(env.buffers.terminated)
    step_truncated = torch.from_dlpack(env.buffers.truncated)

    n, t_max = args.num_envs, args.rollout_steps
    agent = Agent(*env.single_observation_space.shape, env.single_action_space.n).to(device)
    optimizer = torch.optim.Adam(agent.parameters(), lr=args.lr, eps=1e-5)
    print(
        f"{env.info.title} level {args.level}: {n} environments on {args.backend}, "
        f"observations {tuple(observations.shape)}, {env.single_action_space.n} actions"
    )

    buffer_obs = torch.zeros((t_max, *observations.shape), dtype=torch.uint8, device=device)
    buffer_actions = torch.zeros((t_max, n), dtype=torch.long, device=device)
    buffer_logprobs = torch.zeros((t_max, n), device=device)
    buffer_values = torch.zeros((t_max, n), device=device)
    buffer_rewards = torch.zeros((t_max, n), device=device)
    buffer_terminated = torch.zeros((t_max, n), device=device)
    buffer_done = torch.zeros((t_max, n), device=device)
    buffer_valid = torch.zeros((t_max, n), device=device)
    previous_done = torch.zeros(n, device=device)  # the next step of these environments is a restart
    episode_return = torch.zeros(n, device=device)
    episode_length = torch.zeros(n, device=device)

    log = open(args.csv, "w", newline="")
    writer = csv.writer(log)
    writer.writerow(CSV_COLUMNS)
    start = time.perf_counter()
    env_steps = 0
    update = 0
    while env_steps < args.total_steps and time.perf_counter() - start < args.time_limit:
        update += 1
        finished = torch.zeros((), device=device)
        finished_return = torch.zeros((), device=device)
        finished_wins = torch.zeros((), device=device)
        finished_length = torch.zeros((), device=device)

        # --- rollout: everything stays on the device
        for t in range(t_max):
            buffer_obs[t] = observations
            with torch.no_grad():
                logits, value = agent(observations)
            distribution = torch.distributions.Categorical(logits=logits)
            action = distribution.sample()
            buffer_actions[t] = action
            buffer_logprobs[t] = distribution.log_prob(action)
            buffer_values[t] = value
            buffer_valid[t] = 1.0 - previous_done
            env.step_device(action.to(torch.int32))
            reward = step_rewards.float()
            terminated = step_terminated.float()
            done = torch.maximum(terminated, step_truncated.float())
            buffer_rewards[t] = reward
            buffer_terminated[t] = terminated
            buffer_done[t] = done
            valid = buffer_valid[t]
            episode_return = (episode_return + reward) * valid
            episode_length = (episode_length + 1) * valid
            finished += done.sum()
            finished_return += (episode_return * done).sum()
            finished_wins += terminated.sum()
            finished_length += (episode_length * done).sum()
            previous_done = done
        env_steps += n * t_max

        # --- advantages (GAE); restart steps are cut off by the done that precedes them
        with torch.no_grad():
            _, next_value = agent(observations)
            advantages = torch.zeros_like(buffer_rewards)
            running = torch.zeros(n, device=device)
            for t in reversed(range(t_max)):
                if t + 1 < t_max:
                    next_value = buffer_values[t + 1]
                # A truncated episode's next observation is its final one: bootstrap from it.
                delta = buffer_rewards[t] + args.gamma * next_value * (1.0 - buffer_terminated[t]) - buffer_values[t]
                running = delta + args.gamma * args.gae_lambda * (1.0 - buffer_done[t]) * running
                advantages[t] = running * buffer_valid[t]
            returns = advantages + buffer_values

        # --- PPO update over valid steps
        flat_valid = buffer_valid.reshape(-1).bool()
        b_obs = buffer_obs.reshape(-1, *observations.shape[1:])[flat_valid]
        b_actions = buffer_actions.reshape(-1)[flat_valid]
        b_logprobs = buffer_logprobs.reshape(-1)[flat_valid]
        b_advantages = advantages.reshape(-1)[flat_valid]
        b_returns = returns.reshape(-1)[flat_valid]
        b_advantages = (b_advantages - b_advantages.mean()) / (b_advantages.std() + 1e-8)
        size = b_obs.shape[0]
        minibatch = max(1, size // args.minibatches)
        for _ in range(args.epochs):
            order = torch.randperm(size, device=device)
            for begin in range(0, size - minibatch + 1, minibatch):  # equal minibatches; the remainder waits
                index = order[begin : begin + minibatch]
                logits, value = agent(b_obs[index])
                distribution = torch.distributions.Categorical(logits=logits)
                ratio = (distribution.log_prob(b_actions[index]) - b_logprobs[index]).exp()
                advantage = b_advantages[index]
                policy_loss = torch.max(
                    -advantage * ratio, -advantage * ratio.clamp(1 - args.clip, 1 + args.clip)
                ).mean()
                value_loss = 0.5 * (value - b_returns[index]).pow(2).mean()
                entropy = distribution.entropy().mean()
                loss = policy_loss + args.vf_coef * value_loss - args.ent_coef * entropy
                optimizer.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(agent.parameters(), args.max_grad_norm)
                optimizer.step()

        # --- log: the host reads the statistics once per update
        episodes = int(finished.item())
        mean_return = finished_return.item() / max(episodes, 1)
        win_rate = finished_wins.item() / max(episodes, 1)
        mean_length = finished_length.item() / max(episodes, 1)
        seconds = time.perf_counter() - start
        writer.writerow(
            [
                update,
                env_steps,
                f"{seconds:.2f}",
                episodes,
                f"{mean_return:.4f}",
                f"{win_rate:.4f}",
                f"{mean_length:.2f}",
                f"{policy_loss.item():.4f}",
                f"{value_loss.item():.4f}",
                f"{entropy.item():.4f}",
            ]
        )
        log.flush()
        if update % 10 == 1:
            print(
                f"update {update:5d}  steps {env_steps:>11,}  {seconds:6.1f} s  episodes {episodes:6d}  "
                f"return {mean_return:.3f}  win rate {win_rate:.3f}  length {mean_length:.1f}"
            )
        if episodes >= n and win_rate >= args.target_win_rate:  # judged on at least one episode per environment
            print(f"update {update}: win rate {win_rate:.3f} >= {args.target_win_rate}, stopping")
            break

    env.synchronize()  # raises if any device action was invalid
    log.close()
    print(f"{env_steps:,} environment steps in {time.perf_counter() - start:.1f} s; log in {args.csv}")


if __name__ == "__main__":
    main()
