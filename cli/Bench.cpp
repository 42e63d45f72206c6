#include "Bench.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <set>
#include <vector>

#include "BenchExpand.h"
#include "CudaTimer.h"
#include "SourceFile.h"

namespace psc::cli {
namespace {

struct Row {
    int batch;  // environments per device
    double median;
    double min;
    double max;
    double slowestDevice;  // median steps/s of the slowest device (several devices only)
};

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

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
    // --devices: one batch of each size on every device, stepped at once and timed by the host's clock.
    const bool several = !o.devices.empty();
    const std::vector<int> devices = several ? o.devices : std::vector<int>{o.device};
    if (several && !cuda) {
        fmt::print(stderr, "psc bench: --devices needs --backend cuda\n");
        return 2;
    }
    if (std::set<int>(devices.begin(), devices.end()).size() != devices.size() ||
        std::any_of(devices.begin(), devices.end(), [](int d) { return d < 0; })) {
        fmt::print(stderr, "psc bench: devices must be distinct CUDA ordinals (0, 1, ...)\n");
        return 2;
    }
    if (several && o.expand) {
        fmt::print(stderr, "psc bench: --expand measures one device (--device N)\n");
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
    std::vector<CudaTimer> timers;
    if (cuda) {
        for (int d : devices) {
            std::string error;
            auto timer = CudaTimer::create(d, &error);
            if (!timer) {
                fmt::print(stderr, "psc bench: {}\n", error);
                return 2;
            }
            timers.push_back(*timer);
        }
    }
    if (o.expand) {
        std::optional<CudaTimer> timer;
        if (cuda) timer = timers.front();
        return runExpandBench(o, *plugin, timer);
    }
    std::vector<Row> rows;
    bool failed = false;
    if (several) {
        fmt::print("devices {}: one batch each, stepped at once; steps/s of all of them together\n", fmt::join(devices, ","));
        fmt::print("{:>10} {:>8} {:>16} {:>16} {:>16} {:>16}\n", "batch/GPU", "steps", "median steps/s", "min steps/s",
                   "max steps/s", "slowest GPU");
    } else {
        fmt::print("{:>10} {:>8} {:>16} {:>16} {:>16}\n", "batch", "steps", "median steps/s", "min steps/s", "max steps/s");
    }
    try {
        for (int n : batches) {
            std::vector<std::unique_ptr<Batch>> batchPerDevice;
            for (int d : devices) {
                psc_batch_options bo = defaultBatchOptions();
                bo.backend = cuda ? PSC_BACKEND_CUDA : PSC_BACKEND_CPU;
                bo.num_envs = n;
                bo.threads = o.threads;
                bo.auto_reset = PSC_AUTO_RESET_SAME_STEP;
                bo.device = d;
                auto batch = std::make_unique<Batch>(*plugin, bo);
                std::vector<int32_t> levels(static_cast<size_t>(n), o.level);
                std::vector<uint64_t> seeds(static_cast<size_t>(n));
                for (int i = 0; i < n; ++i) seeds[static_cast<size_t>(i)] = static_cast<uint64_t>(i);
                batch->check(plugin->reset(batch->get(), nullptr, n, levels.data(), seeds.data()), "reset");
                batchPerDevice.push_back(std::move(batch));
            }
            uint64_t seed = 12345;
            std::vector<double> deviceSeconds(devices.size());
            // Seconds for `steps` steps of every batch; deviceSeconds gets each device's own time.
            auto run = [&](int steps) {
                if (!cuda) {
                    const auto start = std::chrono::steady_clock::now();
                    Batch& batch = *batchPerDevice.front();
                    batch.check(plugin->rollout(batch.get(), steps, seed++, nullptr), "rollout");
                    return deviceSeconds.front() = secondsSince(start);
                }
                for (auto& batch : batchPerDevice) batch->check(plugin->synchronize(batch->get()), "synchronize");
                const auto start = std::chrono::steady_clock::now();
                for (size_t k = 0; k < batchPerDevice.size(); ++k) {
                    timers[k].start();
                    Batch& batch = *batchPerDevice[k];
                    batch.check(plugin->rollout(batch.get(), steps, seed++, nullptr), "rollout");
                }
                for (size_t k = 0; k < batchPerDevice.size(); ++k) deviceSeconds[k] = timers[k].stop() / 1000.0;
                return several ? secondsSince(start) : deviceSeconds.front();
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
            const double stepsPerRun = static_cast<double>(n) * steps;
            std::vector<double> rates;
            std::vector<double> slowest;
            for (int r = 0; r < o.repeats; ++r) {
                rates.push_back(stepsPerRun * static_cast<double>(devices.size()) / run(steps));
                slowest.push_back(stepsPerRun / *std::max_element(deviceSeconds.begin(), deviceSeconds.end()));
            }
            std::sort(rates.begin(), rates.end());
            std::sort(slowest.begin(), slowest.end());
            rows.push_back({n, rates[rates.size() / 2], rates.front(), rates.back(), slowest[slowest.size() / 2]});
            const Row& row = rows.back();
            if (several) {
                fmt::print("{:>10} {:>8} {:>16.0f} {:>16.0f} {:>16.0f} {:>16.0f}\n", n, steps, row.median, row.min, row.max,
                           row.slowestDevice);
            } else {
                fmt::print("{:>10} {:>8} {:>16.0f} {:>16.0f} {:>16.0f}\n", n, steps, row.median, row.min, row.max);
            }
        }
    } catch (const std::exception& e) {
        // Batch sizes measured before the failure (often: out of device memory) are still reported.
        fmt::print(stderr, "psc bench: {}\n", e.what());
        if (rows.empty()) return 2;
        failed = true;
    }
    const Row best = *std::max_element(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.median < b.median; });
    std::string where = cuda ? "" : fmt::format(" threads {}", o.threads);
    if (several) where = fmt::format(" devices {}", fmt::join(devices, ","));
    else if (cuda && o.device != 0) where = fmt::format(" device {}", o.device);
    fmt::print("game {} level {} backend {}{}{}; best batch {}{}\n", o.gamePath, o.level, o.backend, where,
               o.allLevels ? " (all levels built)" : "", best.batch, several ? " per GPU" : "");
    fmt::print("steps/s: {:.0f}\n", best.median);
    return failed ? 2 : 0;
}

}  // namespace psc::cli
