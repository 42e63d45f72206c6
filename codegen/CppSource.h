// CppSource: the generated source of one game.
//
// The source is self-contained: the game's constants and tables, its rules
// as code (RuleCode), and the fixed engine from templates/ (the turn, the
// command queue, undo, levels), followed by the plugin's C ABI.  The same
// device part compiles as CUDA.  Output depends only on the IR and the
// options: the same input gives the same bytes.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "ir/Ir.h"

namespace psc::codegen {

// How a game's rules are written (SourceOptions::ruleForm), and why.
struct RuleFormChoice {
    bool table = false;
    size_t codeBytes = 0;  // the rules as straight-line code (0 when not measured)
    std::vector<size_t> groupCodeBytes;  // of that, each group's with its rules (early, then late)
    std::string reason;
};

struct SourceOptions {
    std::string sourceName;  // shown in the header comment and in game info
    std::string sourceSha1;
    std::string target = "cpu";  // cpu | cuda
    // Playable levels to build (numbered from 0); empty: all.  Bitboards are
    // sized for the largest level built, so building only small levels makes
    // every step cheaper.
    std::vector<int> levels;
    // Where the GPU keeps each environment's state: "registers", "memory"
    // (local memory), "groups" (local memory, each rule group run on a copy
    // in registers), "shared" (the memory layout, stepped in shared memory),
    // or "auto" (chosen from the game's rule code and board size; see
    // templates/core.h).
    std::string gpuState = "auto";
    // CUDA compile units (templates/core.h) for a memory-layout game; 0: as
    // many as its rule code calls for (one per 16 kB, at most 8 in all).
    int cudaUnits = 0;
    // Also compile search's expansion kernel (psc_expand on CUDA batches).
    // Off by default: in the registers layout it inlines every rule a second
    // time, which costs NVRTC up to 80% more time (docs/search.md).
    bool searchKernels = false;
    // How the rules are written: "code" (straight-line, RuleCode), "table"
    // (records an interpreter reads, RuleTable: compiles in seconds, steps
    // slower), or "auto": code unless it would be over kTableRuleCodeBytes.
    std::string ruleForm = "auto";
    // ruleForm(game, *this), when a build has decided it already: deciding
    // writes the rules out once, seconds for the largest games.
    std::optional<RuleFormChoice> decidedRuleForm;
};

// The rule form a source gets, and why (for --verbose).
RuleFormChoice ruleForm(const ir::Game& game, const SourceOptions& options);

// The part that runs per environment (host and device): tables, rules, engine.
std::string deviceSource(const ir::Game& game, const SourceOptions& options);
// The C++ translation unit of a CPU plugin: the game's code and its game
// module, which the plugin host (runtime/plugin_host) drives once linked.
std::string cpuPluginSource(const ir::Game& game, const SourceOptions& options);
// The CUDA translation unit: the device part and the kernels (for NVRTC or nvcc).
std::string cudaSource(const ir::Game& game, const SourceOptions& options);
// The host translation unit of a plugin with both backends, which compiles
// and links while NVRTC runs: cpuPluginSource's, with the CUDA backend's
// description of the device code, which is added to the linked plugin after
// (runtime/plugin_host/DeviceImage.h).
std::string cudaPluginSource(const ir::Game& game, const SourceOptions& options);

// Compile units of the plugin's host side (templates/core.h), which the
// system compiler compiles at once: the CUDA code's split for plugins with
// both backends, whose host compile follows NVRTC's on the build's critical
// path; 1 for CPU plugins, whose stepping loses up to 43 % (slidings) when
// its rules and groups are compiled apart from the turn.
int hostCompileUnits(const ir::Game& game, const SourceOptions& options);
// The GPU state layout the source gets: registers, groups, memory or shared
// (templates/core.h).
std::string gpuStateLayout(const ir::Game& game, const SourceOptions& options);

// Words of 64 bits per bitboard for the largest level built.
int boardWords(const ir::Game& game, const SourceOptions& options);
// Whether LEVELS entry `entry` is built (messages always are).
bool entryBuilt(const ir::Game& game, const SourceOptions& options, size_t entry);

}  // namespace psc::codegen
