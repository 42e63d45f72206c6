// Loads a psc plugin the way training code does (dlopen through
// psc::plugin_loader), steps a batch of environments with pseudo-random
// actions on the CPU, and on CUDA when the plugin has CUDA code and a GPU is
// there, and reads the observations after every step.  The CUDA batch gets
// the same actions as the CPU one: its observations must be the same bytes.
//
//   rollout PLUGIN [ENVS [STEPS]]
#include <psc/Plugin.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

namespace {

struct Rollout {
    std::vector<uint8_t> observations;  // after the last step
    long long wins = 0;
    long long observedCells = 0;        // object cells seen over every step
};

// Actions among the four directions and `action`, from a fixed 64-bit LCG,
// so that two batches given the same stream play the same games.
std::vector<std::vector<int32_t>> actionStream(int envs, int steps) {
    std::vector<std::vector<int32_t>> actions(steps, std::vector<int32_t>(envs));
    uint64_t x = 0x9E3779B97F4A7C15ull;
    for (auto& step : actions) {
        for (int32_t& a : step) {
            x = x * 6364136223846793005ull + 1442695040888963407ull;
            a = static_cast<int32_t>((x >> 33) % 5);
        }
    }
    return actions;
}

Rollout run(const psc::Plugin& plugin, psc_backend backend, int envs, const std::vector<std::vector<int32_t>>& actions) {
    const psc_game_info& info = plugin.info();
    psc_batch_options options = psc::defaultBatchOptions();
    options.backend = backend;
    options.num_envs = envs;
    options.auto_reset = PSC_AUTO_RESET_SAME_STEP;
    options.max_episode_steps = 200;
    psc::Batch batch(plugin, options);

    std::vector<int32_t> levels(envs);
    std::vector<uint64_t> seeds(envs);
    for (int i = 0; i < envs; ++i) {
        levels[i] = i % info.level_count;
        seeds[i] = static_cast<uint64_t>(i);
    }
    batch.check(plugin.reset(batch.get(), nullptr, envs, levels.data(), seeds.data()), "reset");

    Rollout r;
    r.observations.resize(static_cast<size_t>(envs) * info.object_count * info.max_height * info.max_width);
    std::vector<psc_step_result> results(envs);
    for (const auto& step : actions) {
        batch.check(plugin.step(batch.get(), step.data(), results.data()), "step");
        batch.check(plugin.observe(batch.get(), r.observations.data(), r.observations.size()), "observe");
        for (const psc_step_result& result : results) r.wins += result.won;
        for (uint8_t cell : r.observations) r.observedCells += cell;
    }
    return r;
}

void report(const char* backend, const Rollout& r, int envs, int steps) {
    std::printf("%s: %d envs x %d steps, %lld wins, %lld object cells observed\n", backend, envs, steps, r.wins,
                r.observedCells);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2 || argc > 4) {
        std::fprintf(stderr, "usage: %s PLUGIN [ENVS [STEPS]]\n", argv[0]);
        return 2;
    }
    const int envs = argc > 2 ? std::atoi(argv[2]) : 16;
    const int steps = argc > 3 ? std::atoi(argv[3]) : 100;
    if (envs < 1 || steps < 1) {
        std::fprintf(stderr, "error: ENVS and STEPS must be positive\n");
        return 2;
    }
    std::string error;
    const auto plugin = psc::Plugin::open(argv[1], &error);
    if (!plugin) {
        std::fprintf(stderr, "error: %s\n", error.c_str());
        return 1;
    }
    const psc_game_info& info = plugin->info();
    std::printf("game: %s, %d levels, observations %d x %d x %d per env\n", info.title, info.level_count,
                info.object_count, info.max_height, info.max_width);
    try {
        const auto actions = actionStream(envs, steps);
        const Rollout cpu = run(*plugin, PSC_BACKEND_CPU, envs, actions);
        report("cpu", cpu, envs, steps);
        if (!(info.backends & (1u << PSC_BACKEND_CUDA))) {
            std::printf("cuda: not built into this plugin\n");
            return 0;
        }
        psc_batch_options probe = psc::defaultBatchOptions();
        probe.backend = PSC_BACKEND_CUDA;
        psc_batch* batch = nullptr;
        if (plugin->batchCreate(&probe, &batch) != PSC_OK) {
            std::printf("cuda: not available here (%s)\n", plugin->lastError());
            return 0;
        }
        plugin->batchDestroy(batch);
        const Rollout cuda = run(*plugin, PSC_BACKEND_CUDA, envs, actions);
        report("cuda", cuda, envs, steps);
        if (cuda.observations != cpu.observations || cuda.wins != cpu.wins) {
            std::fprintf(stderr, "error: the CUDA batch's observations differ from the CPU batch's\n");
            return 1;
        }
        std::printf("cuda: observations equal the CPU's\n");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 0;
}
