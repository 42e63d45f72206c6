#include "Bench.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "SourceFile.h"

namespace psc::cli {
int runBench(const BenchOptions& o) {
    if (o.backend != "cpu") {
        fmt::print(stderr, "psc bench: backend {} is not available in this build\n", o.backend);
        return 2;
    }
    if (o.batch <= 0 || o.steps <= 0 || o.repeats <= 0 || o.threads <= 0 || o.warmup < 0) {
        fmt::print(stderr, "psc bench: batch, steps, repeats and threads must be positive\n");
        return 2;
    }
    auto text = readSource(o.gamePath);
    if (!text) return 2;
    auto game = compileForBuild(*text, o.gamePath, o.build);
    if (!game) return 2;
    GameBuildOptions build = o.build;
    if (!o.allLevels) build.levels = {o.level};  // bitboards sized for this level only
    auto plugin = loadCpuPlugin(*game, *text, o.gamePath, build);
    if (!plugin) return 2;
    const psc_game_info& info = plugin->info();
    if (o.level < 0 || o.level >= info.level_count) {
        fmt::print(stderr, "psc bench: level {} out of range [0, {})\n", o.level, info.level_count);
        return 2;
    }
    try {
        psc_batch_options bo = defaultBatchOptions();
        bo.num_envs = o.batch;
        bo.threads = o.threads;
        bo.auto_reset = PSC_AUTO_RESET_SAME_STEP;
        Batch batch(*plugin, bo);
        std::vector<int32_t> levels(static_cast<size_t>(o.batch), o.level);
        std::vector<uint64_t> seeds(static_cast<size_t>(o.batch));
        for (int i = 0; i < o.batch; ++i) seeds[static_cast<size_t>(i)] = static_cast<uint64_t>(i);
        batch.check(plugin->reset(batch.get(), nullptr, o.batch, levels.data(), seeds.data()), "reset");
        uint64_t seed = 12345;
        auto run = [&]() {
            const auto start = std::chrono::steady_clock::now();
            psc_rollout_stats stats{};
            batch.check(plugin->rollout(batch.get(), o.steps, seed++, &stats), "rollout");
            return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        };
        for (int w = 0; w < o.warmup; ++w) run();
        std::vector<double> rates;
        fmt::print("{:>8} {:>12} {:>14}\n", "repeat", "seconds", "steps/s");
        for (int r = 0; r < o.repeats; ++r) {
            const double seconds = run();
            const double rate = static_cast<double>(o.batch) * o.steps / seconds;
            rates.push_back(rate);
            fmt::print("{:>8} {:>12.4f} {:>14.0f}\n", r, seconds, rate);
        }
        std::vector<double> sorted = rates;
        std::sort(sorted.begin(), sorted.end());
        fmt::print("game {} level {} batch {} threads {} backend cpu{}; min {:.0f} median {:.0f} max {:.0f}\n", o.gamePath,
                   o.level, o.batch, o.threads, o.allLevels ? " (all levels built)" : "", sorted.front(),
                   sorted[sorted.size() / 2], sorted.back());
        fmt::print("steps/s: {:.0f}\n", sorted[sorted.size() / 2]);
    } catch (const std::exception& e) {
        fmt::print(stderr, "psc bench: {}\n", e.what());
        return 2;
    }
    return 0;
}

}  // namespace psc::cli
