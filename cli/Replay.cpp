#include "Replay.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace psc::cli {
namespace {

using nlohmann::json;

constexpr int kReplayUndoDepth = 4096;

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

int actionOf(const std::string& input) {
    static const char* const kNames[] = {"up", "left", "down", "right", "action", "undo", "restart", "tick"};
    for (int i = 0; i < 8; ++i) {
        if (input == kNames[i]) return i;
    }
    return -1;
}

// The recorded record without the fields psc does not reproduce (sound events).
json comparable(json record) {
    record.erase("sfx");
    return record;
}

std::string cellNames(const json& record, size_t x, size_t y) {
    const json& rows = record.at("rows");
    if (y >= rows.size() || x >= rows[y].size()) return "(outside)";
    return record.at("palette").at(rows[y][x].get<size_t>()).get<std::string>();
}

void printDifference(const json& expected, const json& actual) {
    for (const char* field : {"level", "screen", "message", "won", "width", "height"}) {
        if (expected.value(field, json()) != actual.value(field, json())) {
            fmt::print("  {}: expected {}, got {}\n", field, expected.value(field, json()).dump(), actual.value(field, json()).dump());
        }
    }
    const size_t height = std::max(expected.at("rows").size(), actual.at("rows").size());
    int shown = 0;
    for (size_t y = 0; y < height; ++y) {
        size_t width = 0;
        if (y < expected.at("rows").size()) width = expected.at("rows")[y].size();
        if (y < actual.at("rows").size()) width = std::max(width, actual.at("rows")[y].size());
        for (size_t x = 0; x < width; ++x) {
            const std::string e = cellNames(expected, x, y);
            const std::string a = cellNames(actual, x, y);
            if (e == a) continue;
            if (shown++ < 40) fmt::print("  cell ({}, {}): expected [{}], got [{}]\n", x, y, e, a);
        }
    }
    if (shown > 40) fmt::print("  ... {} cells differ\n", shown);
}

}  // namespace

int runReplay(const ReplayOptions& options) {
    json c;
    try {
        std::ifstream in(options.casePath);
        if (!in) {
            fmt::print(stderr, "{}: error: cannot open the case\n", options.casePath);
            return 2;
        }
        c = json::parse(in);
    } catch (const std::exception& e) {
        fmt::print(stderr, "{}: error: not a JSON case: {}\n", options.casePath, e.what());
        return 2;
    }
    if (c.value("kind", "") != "trace") {
        fmt::print(stderr, "{}: error: not a trace case\n", options.casePath);
        return 2;
    }
    const std::string game = c.at("game").get<std::string>();
    GameBuildOptions build = options.build;
    build.keepGoing = true;              // the reference plays games with up to five errors
    build.build.optimization = "-O0";    // short traces: compile fast rather than run fast
    build.target = options.backend == "cuda" ? "cuda" : "cpu";
    auto compiled = compileForBuild(game, options.casePath, build);
    if (!compiled) return 2;
    auto plugin = loadPlugin(*compiled, game, options.casePath, build);
    if (!plugin) return 2;

    std::ofstream dump;
    if (!options.dumpPath.empty()) {
        dump.open(options.dumpPath);
        if (!dump) {
            fmt::print(stderr, "{}: error: cannot write\n", options.dumpPath);
            return 2;
        }
    }
    try {
        psc_batch_options bo = defaultBatchOptions();
        // An undo history only where the trace undoes: without one, as by the
        // plugins' default, a turn skips what only the history needs (its
        // copy of the level, templates/engine.h), so the traces check both.
        const json& caseInputs = c.at("inputs");
        const bool undoes = std::any_of(caseInputs.begin(), caseInputs.end(), [](const json& input) { return input == "undo"; });
        bo.undo_depth = undoes ? kReplayUndoDepth : 0;
        bo.backend = options.backend == "cuda" ? PSC_BACKEND_CUDA : PSC_BACKEND_CPU;
        bo.device = options.device;
        // Under --verbose: where a replay's time goes (a GPU replay steps one
        // environment on one thread, so its stepping can outweigh the compile).
        const auto created = Clock::now();
        bo.num_envs = options.checkKeys ? 2 : 1;  // environment 1: the template keys are decoded over
        Batch batch(*plugin, bo);
        const std::string seed = c.at("level_seed").get<std::string>();
        batch.check(plugin->resetEntry(batch.get(), 0, c.at("start_level").get<int>(), seed.c_str()), "starting the level");
        if (options.build.build.verbose) fmt::print(stderr, "psc: batch created and level started in {:.2f} s\n", secondsSince(created));
        double stepSeconds = 0, readSeconds = 0;
        auto lastProgress = Clock::now();
        std::vector<uint64_t> key(plugin->info().state_key_bytes / 8);
        // The template of a key is the key's entry started afresh, as search's
        // is; but after a win the reference can show the won level's board on
        // the message entry that follows it, a board no fresh start of that
        // entry holds.  There the template is environment 1 as it stands: it
        // took the same inputs since it last gave back environment 0's state.
        auto keyGivesBack = [&](const json& actual) {
            const int32_t env = 0;
            const int entry = actual.at("level").get<int>();
            const psc_game_info& info = plugin->info();
            const bool boardOfEarlierLevel = entry >= 0 && entry < info.entry_count && info.entry_is_message[entry];
            batch.check(plugin->encodeStates(batch.get(), &env, 1, key.data(), nullptr), "encoding the state");
            if (!boardOfEarlierLevel) {
                batch.check(plugin->resetEntry(batch.get(), 1, entry, seed.c_str()), "starting the template");
            }
            const int decoded = plugin->decodeState(batch.get(), 1, key.data());
            // The decode refuses a template on another entry: there environment 1 did not follow.
            if (boardOfEarlierLevel && decoded != PSC_OK) return false;
            batch.check(decoded, "decoding the state");
            return json::parse(batch.dump(1)) == actual;
        };
        auto compare = [&](const json& expected, const std::string& label) {
            const auto start = Clock::now();
            const json actual = json::parse(batch.dump(0));
            readSeconds += secondsSince(start);
            if (dump) dump << actual.dump() << "\n";
            if (comparable(expected) != actual) {
                fmt::print("MISMATCH {} {}\n", c.value("id", options.casePath), label);
                printDifference(expected, actual);
                return false;
            }
            if (options.checkKeys && actual.at("screen") == "level" && !keyGivesBack(actual)) {
                fmt::print("MISMATCH {} {}: the state key does not give back the state\n", c.value("id", options.casePath), label);
                printDifference(actual, json::parse(batch.dump(1)));
                return false;
            }
            return true;
        };
        if (!compare(c.at("initial"), "at the start")) return 1;
        const json& inputs = c.at("inputs");
        const json& steps = c.at("steps");
        for (size_t i = 0; i < inputs.size(); ++i) {
            const int action = actionOf(inputs[i].get<std::string>());
            if (action < 0) {
                fmt::print(stderr, "{}: error: unknown input {}\n", options.casePath, inputs[i].dump());
                return 2;
            }
            // With --check-keys environment 1 is the keys' template (keyGivesBack): it steps along unseen.
            const int32_t a[2] = {action, action};
            const auto start = Clock::now();
            batch.check(plugin->step(batch.get(), a, nullptr), "stepping");
            stepSeconds += secondsSince(start);
            if (options.build.build.verbose && secondsSince(lastProgress) >= 10) {
                fmt::print(stderr, "psc: {} of {} inputs stepped ({:.2f} s)\n", i + 1, inputs.size(), stepSeconds);
                lastProgress = Clock::now();
            }
            if (!compare(steps.at(i), fmt::format("after input {} ({})", i, inputs[i].get<std::string>()))) return 1;
        }
        if (options.build.build.verbose) {
            fmt::print(stderr, "psc: {} inputs stepped in {:.2f} s, states read back in {:.2f} s\n", inputs.size(),
                       stepSeconds, readSeconds);
        }
    } catch (const std::exception& e) {
        fmt::print(stderr, "{}: error: {}\n", options.casePath, e.what());
        return 2;
    }
    fmt::print("PASS {}\n", c.value("id", options.casePath));
    return 0;
}

}  // namespace psc::cli
