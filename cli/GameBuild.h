// From a game's text to a loaded plugin: compile, generate, build (cached), load.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "Compiler.h"
#include "Plugin.h"
#include "PluginBuilder.h"

namespace psc::cli {

struct GameBuildOptions {
    bool keepGoing = false;  // build games the reference plays despite errors
    bool quiet = false;      // no diagnostics on stderr
    BuildOptions build;
    std::vector<int> levels;  // playable levels to build; empty: all
};

// The compiled game when it can be built; prints diagnostics as it goes.
std::optional<ir::Game> compileForBuild(const std::string& text, const std::string& path, const GameBuildOptions& options);
// Builds (or finds in the cache) the CPU plugin of `game`; null on failure (reported on stderr).
std::unique_ptr<Plugin> loadCpuPlugin(const ir::Game& game, const std::string& text, const std::string& path,
                                      const GameBuildOptions& options, std::string* pluginPath = nullptr);

}  // namespace psc::cli
