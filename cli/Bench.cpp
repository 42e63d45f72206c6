#include "Bench.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "BenchExpand.h"
#include "CudaTimer.h"
#include "SourceFile.h"

namespace psc::cli {
namespace {

struct Row {
    int batch;
    double median;
    double min;
    double max;
};

}  // namespace

int runBench(const BenchOptions& o) {
    const bool cuda = o.backend == "cuda";
    std::vector<int> batches = o.batches;
    if (batches.empty()) batches = cuda ? std::vector<int>{1, 256, 4096, 65536, 262144, 1048576, 4194304} : std::vector<int>{1};
    for (int b : batches) {
        if (b <= 0) {
            fmt::print(stderr, "psc bench: batch sizes must be positive\n");
            return 2;
        }
    }
    if (o.steps < 0 || o.repeats <= 0 || o.threads <= 0 || o.warmup < 0) {
        fmt::print(stderr, "psc bench: steps, repeats and threads must be positive\n");
        return 2;
    }
    auto text = readSource(o.gamePath);
    if (!text) return 2;
    auto game = compileForBuild(*text, o.gamePath, o.build);
    if (!game) return 2;
    GameBuildOptions build = o.build;
    build.target = cuda ? "cuda" : "cpu";
    if (!o.allLevels) build.levels = {o.level};  // bitboards sized for this level only
    build.searchKernels = o.expand;
    auto plugin = loadPlugin(*game, *text, o.gamePath, build);
    if (!plugin) return 2;
    const psc_game_info& info = plugin->info();
    if (o.level < 0 || o.level >= info.level_count) {
        fmt::print(stderr, "psc bench: level {} out of range [0, {})\n", o.level, info.level_count);
        return 2;
    }
    std::optional<CudaTimer> timer;
    if (cuda) {
        std::string error;
        timer = CudaTimer::create(0, &error);
        if (!timer) {
            fmt::print(stderr, "psc bench: {}\n", error);
            return 2;
        }
    }
    if (o.expand) return runExpandBench(o, *plugin, timer);
    std::vector<Row> rows;
    bool failed = false;
    fmt::print("{:>10} {:>8} {:>16} {:>16} {:>16}\n", "batch", "steps", "median steps/s", "min steps/s", "max steps/s");
    try {
        for (int n : batches) {
            psc_batch_options bo = defaultBatchOptions();
            bo.backend = cuda ? PSC_BACKEND_CUDA : PSC_BACKEND_CPU;
            bo.num_envs = n;
            bo.threads = o.threads;
            bo.auto_reset = PSC_AUTO_RESET_SAME_STEP;
            Batch batch(*plugin, bo);
            std::vector<int32_t> levels(static_cast<size_t>(n), o.level);
            std::vector<uint64_t> seeds(static_cast<size_t>(n));
            for (int i = 0; i < n; ++i) seeds[static_cast<size_t>(i)] = static_cast<uint64_t>(i);
            batch.check(plugin->reset(batch.get(), nullptr, n, levels.data(), seeds.data()), "reset");
            uint64_t seed = 12345;
            auto run = [&](int steps) {
                if (cuda) {
                    batch.check(plugin->synchronize(batch.get()), "synchronize");
                    timer->start();
                    batch.check(plugin->rollout(batch.get(), steps, seed++, nullptr), "rollout");
                    return timer->stop() / 1000.0;
                }
                const auto start = std::chrono::steady_clock::now();
                batch.check(plugin->rollout(batch.get(), steps, seed++, nullptr), "rollout");
                return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            };
            int steps = o.steps;
            if (steps == 0) {
                // Calibrate: grow the run until it takes long enough to time, then aim at 0.25 s.
                int probe = 4;
                double seconds = run(probe);
                while (seconds < 0.02 && probe < (1 << 20)) seconds = run(probe *= 4);
                steps = std::clamp(static_cast<int>(0.25 / std::max(seconds, 1e-9) * probe), 1, 1 << 22);
            }
            for (int w = 0; w < o.warmup; ++w) run(steps);
            std::vector<double> rates;
            for (int r = 0; r < o.repeats; ++r) rates.push_back(static_cast<double>(n) * steps / run(steps));
            std::sort(rates.begin(), rates.end());
            rows.push_back({n, rates[rates.size() / 2], rates.front(), rates.back()});
            fmt::print("{:>10} {:>8} {:>16.0f} {:>16.0f} {:>16.0f}\n", n, steps, rows.back().median, rows.back().min,
                       rows.back().max);
        }
    } catch (const std::exception& e) {
        // Batch sizes measured before the failure (often: out of device memory) are still reported.
        fmt::print(stderr, "psc bench: {}\n", e.what());
        if (rows.empty()) return 2;
        failed = true;
    }
    const Row best = *std::max_element(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.median < b.median; });
    fmt::print("game {} level {} backend {}{}{}; best batch {}\n", o.gamePath, o.level, o.backend,
               cuda ? "" : fmt::format(" threads {}", o.threads), o.allLevels ? " (all levels built)" : "", best.batch);
    fmt::print("steps/s: {:.0f}\n", best.median);
    return failed ? 2 : 0;
}

}  // namespace psc::cli
