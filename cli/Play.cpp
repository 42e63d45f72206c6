#include "Play.h"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "Diagnose.h"
#include "GameBuild.h"
#include "InputScript.h"
#include "LevelView.h"
#include "Player.h"
#include "SourceFile.h"

namespace psc::cli {

int runPlay(const PlayCommandOptions& o) {
    // Checked first: a full-screen game written into a pipe or a file helps no one.
    if (!o.scripted && !isatty(STDOUT_FILENO)) {
        fmt::print(stderr, "psc play: error: standard output is not a terminal; psc play draws the game full-screen "
                           "(for scripts: --scripted reads keys from standard input and prints what happens)\n");
        return 2;
    }
    if (!o.scripted && !isatty(STDIN_FILENO)) {
        fmt::print(stderr, "psc play: error: standard input is not a terminal (--scripted reads keys from a pipe)\n");
        return 2;
    }
    if (!o.replay.empty() && !o.replayFile.empty()) {
        fmt::print(stderr, "psc play: error: --replay and --replay-file exclude each other\n");
        return 2;
    }
    play::PlayOptions po;
    po.gamePath = o.gamePath;
    po.forceGlyphs = o.glyphs;
    po.scripted = o.scripted;
    po.replayInterval = o.replayInterval;
    po.recordPath = o.recordPath;
    po.hintTimeLimit = o.hintTimeLimit;
    if (!o.replay.empty() || !o.replayFile.empty()) {
        std::string script = o.replay;
        if (!o.replayFile.empty()) {
            std::ifstream in(o.replayFile);
            if (!in) {
                fmt::print(stderr, "{}: error: cannot open the replay file\n", o.replayFile);
                return 2;
            }
            std::stringstream text;
            text << in.rdbuf();
            script = text.str();
        }
        std::string problem;
        auto actions = play::parseInputScript(script, &problem);
        if (!actions) {
            fmt::print(stderr, "psc play: error: {}: {}\n", o.replayFile.empty() ? "--replay" : o.replayFile, problem);
            return 2;
        }
        po.replay = *actions;
        po.hasReplay = true;
    }

    auto text = readSource(o.gamePath);
    if (!text) return 2;
    CompileResult compiled = compileSource(*text);
    const bool playable = compiled.playable() && compiled.game && compiled.ast;
    if (!playable || compiled.status != CompileStatus::Ok) printDiagnostics(stderr, o.gamePath, compiled);
    if (!playable) {
        fmt::print(stderr, "{}: {}\n", o.gamePath, verdict(compiled));
        return 2;
    }
    const int levels = static_cast<int>(compiled.game->playableLevels().size());
    if (levels == 0) {
        fmt::print(stderr, "{}: error: the game has no level to play\n", o.gamePath);
        return 2;
    }
    if (o.level && (*o.level < 0 || *o.level >= levels)) {
        fmt::print(stderr, "psc play: error: level {} out of range [0, {})\n", *o.level, levels);
        return 2;
    }
    po.level = o.level;

    GameBuildOptions build;
    build.keepGoing = true;  // the reference plays games with up to five errors
    build.quiet = true;      // reported above
    build.target = "cpu";
    auto plugin = loadPlugin(*compiled.game, *text, o.gamePath, build);
    if (!plugin) return 2;

    po.seed = o.seed ? *o.seed
                     : static_cast<uint64_t>(std::chrono::system_clock::now().time_since_epoch().count()) ^
                           (static_cast<uint64_t>(getpid()) << 32);
    std::error_code ec;
    po.pscBinary = std::filesystem::read_symlink("/proc/self/exe", ec).string();

    const play::GameDisplay display = play::makeGameDisplay(*compiled.ast, *compiled.game, *text, plugin->info());
    try {
        return play::play(*plugin, display, po);
    } catch (const std::exception& e) {
        fmt::print(stderr, "psc play: error: {}\n", e.what());
        return 1;
    }
}

}  // namespace psc::cli
