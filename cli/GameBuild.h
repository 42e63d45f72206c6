// From a game's text to a loaded plugin: compile, generate, build (cached), load.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "Compiler.h"
#include "Plugin.h"
#include "CppSource.h"
#include "CudaCompiler.h"
#include "PluginBuilder.h"

namespace psc::cli {

struct GameBuildOptions {
    bool keepGoing = false;  // build games the reference plays despite errors
    bool quiet = false;      // no diagnostics on stderr
    BuildOptions build;
    std::vector<int> levels;      // playable levels to build; empty: all
    std::string target = "cpu";   // cpu | cuda | all (cuda plugins also run on the CPU)
    CudaCompileOptions cuda;
    std::string gpuState = "auto";  // auto | registers | memory | groups | shared (codegen::SourceOptions)
    int cudaUnits = 0;              // CUDA compile units; 0: chosen by codegen (codegen::SourceOptions)
    bool searchKernels = false;     // psc_expand on the GPU (codegen::SourceOptions)
    std::string ruleForm = "auto";  // auto | code | table (codegen::SourceOptions)
};

// The code generator's options for building `text` (read from `path`).
codegen::SourceOptions sourceOptions(const std::string& text, const std::string& path, const GameBuildOptions& options);

// The compiled game when it can be built; prints diagnostics as it goes.
std::optional<ir::Game> compileForBuild(const std::string& text, const std::string& path, const GameBuildOptions& options);
// Builds (or finds in the cache) the plugin of `game` for options.target;
// null on failure (reported on stderr).
std::unique_ptr<Plugin> loadPlugin(const ir::Game& game, const std::string& text, const std::string& path,
                                   const GameBuildOptions& options, std::string* pluginPath = nullptr);
// The cache key of a game's compiled device code (cudaSource and the CUDA options).
std::string deviceCodeKey(const std::string& cudaSource, const GameBuildOptions& options);
// The game's device code compiled for CUDA (cached); nothing on failure
// (reported on stderr).
std::optional<CudaCompileResult> compileDeviceCode(const ir::Game& game, const std::string& text,
                                                   const std::string& path, const GameBuildOptions& options);

}  // namespace psc::cli
