#include "Solve.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "CppSource.h"
#include "SourceFile.h"

namespace psc::cli {
namespace {

std::string humanCount(double n) {
    if (n >= 1e9) return fmt::format("{:.2f}G", n / 1e9);
    if (n >= 1e6) return fmt::format("{:.2f}M", n / 1e6);
    if (n >= 1e3) return fmt::format("{:.1f}k", n / 1e3);
    return fmt::format("{:.0f}", n);
}

// One line on stderr, rewritten in place on a terminal.
class ProgressLine {
public:
    explicit ProgressLine(bool enabled) : enabled_(enabled), tty_(isatty(STDERR_FILENO)) {}
    ~ProgressLine() { clear(); }
    void show(int level, const search::Progress& p) {
        if (!enabled_) return;
        const std::string line =
            fmt::format("psc solve: level {}: {}: depth {}, {} states, {} expanded/s, {} MB, {:.0f} s", level, p.stage, p.depth,
                        humanCount(static_cast<double>(p.unique)), humanCount(p.expanded / std::max(p.seconds, 1e-9)),
                        p.bytes >> 20, p.seconds);
        if (tty_) fmt::print(stderr, "\r{}\x1b[K", line);
        else fmt::print(stderr, "{}\n", line);
        shown_ = true;
    }
    void clear() {
        if (shown_ && tty_) fmt::print(stderr, "\r\x1b[K");
        shown_ = false;
    }

private:
    bool enabled_;
    bool tty_;
    bool shown_ = false;
};

nlohmann::ordered_json record(const search::SolveResult& r, int level, int entry, const std::string& algorithm,
                      const std::string& backend) {
    nlohmann::ordered_json j;
    j["level"] = level;
    j["entry"] = entry;
    j["status"] = std::string(search::statusName(r.status));
    const bool solved = r.status == search::Status::Solved;
    j["solution"] = solved ? nlohmann::ordered_json(r.solution) : nlohmann::ordered_json(nullptr);
    j["length"] = solved ? nlohmann::ordered_json(r.solution.size()) : nlohmann::ordered_json(nullptr);
    j["expanded"] = r.expanded;
    j["generated"] = r.generated;
    j["unique_states"] = r.unique;
    j["seconds"] = std::round(r.seconds * 1e4) / 1e4;
    j["memory_bytes"] = r.bytes;
    j["algorithm"] = algorithm;
    j["backend"] = backend;
    if (r.status == search::Status::Limit) j["limit"] = r.limit;
    if (r.startCutOff) j["start_cut_off"] = true;
    if (r.startWon) j["start_won"] = true;
    return j;
}

}  // namespace

int runSolve(const SolveCommandOptions& o) {
    const auto algorithm = search::parseAlgorithm(o.algorithm);
    if (!algorithm) {
        fmt::print(stderr, "psc solve: unknown algorithm '{}' (bfs, astar, wastar, greedy, beam, portfolio)\n", o.algorithm);
        return 2;
    }
    if (!o.levels.empty() && o.allLevels) {
        fmt::print(stderr, "psc solve: --level and --all-levels exclude each other\n");
        return 2;
    }
    if (!(o.timeLimit > 0) || !(o.weight >= 1) || o.threads <= 0 || o.maxMemoryMb < 0) {
        fmt::print(stderr, "psc solve: --time-limit must be positive, --weight at least 1, --threads positive\n");
        return 2;
    }
    for (char c : o.fromInputs) {
        if (search::actionOfLetter(c) < 0) {
            fmt::print(stderr, "psc solve: --from-inputs: '{}' is not an input (u d l r x)\n", c);
            return 2;
        }
    }
    auto text = readSource(o.gamePath);
    if (!text) return 2;
    auto game = compileForBuild(*text, o.gamePath, o.build);
    if (!game) return 2;
    int playable = 0;
    for (const auto& l : game->levels) playable += l.isMessage ? 0 : 1;
    std::vector<int> levels = o.levels;
    if (levels.empty() && o.allLevels) {
        for (int l = 0; l < playable; ++l) levels.push_back(l);
    }
    if (levels.empty()) levels.push_back(0);
    for (int l : levels) {
        if (l < 0 || l >= playable) {
            fmt::print(stderr, "psc solve: level {} out of range [0, {})\n", l, playable);
            return 2;
        }
    }
    // Bitboards, keys and (on the GPU) the state layout are sized for the
    // largest level a plugin holds, so levels of one board size share a
    // plugin, built when its first level comes up.  Under a few seconds a
    // level, one plugin for all: a build (1-4 s) would cost more than the
    // searches it speeds up.
    constexpr double kPluginPerSizeFromSeconds = 5.0;
    const bool perSize = o.timeLimit >= kPluginPerSizeFromSeconds;
    std::map<int, std::vector<int>> levelsOfWords;
    std::map<int, int> wordsOfLevel;
    for (int level : levels) {
        codegen::SourceOptions one;
        one.levels = {level};
        const int words = perSize ? codegen::boardWords(*game, one) : 0;
        wordsOfLevel[level] = words;
        levelsOfWords[words].push_back(level);
    }
    std::map<int, std::unique_ptr<Plugin>> plugins;
    auto pluginFor = [&](int level) -> Plugin* {
        const int words = wordsOfLevel[level];
        auto& plugin = plugins[words];
        if (!plugin) {
            GameBuildOptions build = o.build;
            build.target = o.backend == "cuda" ? "cuda" : "cpu";
            build.levels = levelsOfWords[words];
            build.searchKernels = true;
            plugin = loadPlugin(*game, *text, o.gamePath, build);
        }
        return plugin.get();
    };

    search::SolveOptions so;
    so.algorithm = *algorithm;
    so.timeLimit = o.timeLimit;
    so.maxStates = o.maxStates;
    so.maxMemory = static_cast<size_t>(o.maxMemoryMb * 1024 * 1024);
    so.weight = o.weight;
    so.beamWidth = o.beamWidth;
    so.space.backend = o.backend == "cuda" ? search::Backend::Cuda : search::Backend::Cpu;
    so.space.threads = o.threads;
    so.space.device = o.device;
    so.space.seed = o.seed;
    so.fromInputs = o.fromInputs;
    std::vector<int> unsolved;
    const auto started = std::chrono::steady_clock::now();
    for (int level : levels) {
        Plugin* plugin = pluginFor(level);
        if (!plugin) return 2;
        ProgressLine progress(!o.quiet);
        so.progress = [&](const search::Progress& p) { progress.show(level, p); };
        search::SolveResult r;
        try {
            r = search::solve(*plugin, level, so);
        } catch (const std::exception& e) {
            progress.clear();
            fmt::print(stderr, "psc solve: level {}: error: {}\n", level, e.what());
            return 2;
        }
        progress.clear();
        if (r.status != search::Status::Solved) unsolved.push_back(level);
        const int entry = plugin->info().level_entries[level];
        if (o.format == "json") {
            fmt::print("{}\n", record(r, level, entry, o.algorithm, o.backend).dump());
        } else {
            const std::string what = r.startWon ? std::string("solved by its start: its again chain wins the level before any input")
                                     : r.status == search::Status::Solved
                                         ? fmt::format("solved in {} inputs: {}", r.solution.size(), r.solution)
                                     : r.startCutOff ? std::string("exhausted: its start runs an again chain that never settles "
                                                                   "(cut off after 10,000 turns), so no input can be played")
                                     : r.status == search::Status::Exhausted ? std::string("exhausted: no reachable state wins")
                                                                             : fmt::format("stopped by the {} limit", r.limit);
            fmt::print("level {} (entry {}): {} ({} expanded, {} states, {:.3f} s)\n", level, entry, what, r.expanded,
                       r.unique, r.seconds);
        }
        std::fflush(stdout);
    }
    if (o.format != "json" && levels.size() > 1) {
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
        fmt::print("{} of {} levels solved in {:.1f} s{}\n", levels.size() - unsolved.size(), levels.size(), seconds,
                   unsolved.empty() ? "" : fmt::format(" (not solved: {})", fmt::join(unsolved, ", ")));
    }
    return unsolved.empty() ? 0 : 1;
}

}  // namespace psc::cli
