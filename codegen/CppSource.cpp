#include "CppSource.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <map>

#include "CodeWriter.h"
#include "KeyObjects.h"
#include "RuleParts.h"
#include "RuleCode.h"
#include "RuleTable.h"
#include "DormantGroups.h"
#include "Templates.h"
#include "base/JsString.h"
#include "base/JsonText.h"
#include "base/Palettes.h"

namespace psc::codegen {
namespace {

using ir::Game;
using ir::WinCondition;

constexpr const char* kGeneratorVersion = "psc 0.1.0";

// Boards of more words than this (levels over 512 cells) keep their word
// loops rolled on the GPU and their state in local memory: unrolled, code size
// and NVRTC time grow with the level's area (a 5,000-cell level took minutes).
constexpr int kMaxUnrolledBoardWords = 8;
// The GPU's loops over a board's words are written out by the preprocessor
// (templates/core.h's PSC_FOR_WORDS) in the registers layout over boards of
// at most this many words: their stepping units compiled 14-22 % faster and
// stepped as fast (one H100); over three- and four-word boards they stepped
// 0.97-0.99x, in the groups layout 0.92x (kettle), in the memory layout 0.96x
// (atlas), so those keep the loops that NVVM unrolls.
constexpr int kMaxWrittenOutGpuWords = 2;

// CUDA compile units: one per this many bytes of rule code, besides unit 0
// (docs/performance.md measures the choice), and at most this many in all.
constexpr size_t kRuleBytesPerUnit = 16000;
constexpr int kMaxCompileUnits = 8;

// The registers layout's budget.  Registers make NVVM and ptxas unroll
// every word of every board access into the rules, which they compile as one
// kernel, so compile time grows with rule code times board words (its
// weight).  Since the stepping kernel compiles alone (two units, one
// out-of-line call a step), on one H100 host (docs/performance.md) NVRTC
// took 1.7-1.9 s for slidings (31.0 k), 2.0-2.8 s for takeheart (64.4 k) and
// 2.1-3.0 s for kettle (69.3 k), against 0.8-0.9 s in groups; the hosts lent
// differ by a third, so the budget keeps the whole build near 2 s there and
// under the 3 s bar on a slower one.  Past it, units compile in parallel
// instead.  Registers ran those three 1.5-2.1x faster than groups; limerick
// (124 k) no faster than its memory layout now (0.98x, 5.8 s of NVRTC).
constexpr size_t kRegisterCodeBudget = 40000;

// The groups layout (templates/core.h) compiles each group with its rules
// inlined, on a copy of the state in registers, which costs NVRTC about
// twice the memory layout's time per byte of rule code, and more with the
// board's words.  A group's weight is its code bytes times the words; one
// compile unit per kGroupUnitWeight (about 1 s of NVRTC on the GPU machine's
// host: docs/performance.md), and `auto` picks the layout while the units it
// needs stay within kMaxCompileUnits.  A group over kGroupCopyBudget passes
// over parts of its rules, each within the budget, each on a copy; a random
// group stays apart instead, compiled as the memory layout.
constexpr size_t kGroupCopyBudget = 16000;
constexpr size_t kGroupUnitWeight = 16000;

// The memory layout inlines each group's rules into the group's function,
// which spares a call a rule: on one H200, limerick stepped 1.32x and atlas
// 1.48x as fast (docs/performance.md).  NVVM's time grows faster than the
// inlined code: a group of 35 kB of code over 5-word boards (weight 178 k)
// took it 6.8 s alone, one of 51 kB over 2 words (103 k) 1.3 s, limerick's
// largest (39 k) 0.6 s.  Past this weight a group calls its rules.
constexpr size_t kInlinedGroupWeight = 64000;

// The memory layout over boards too large to unroll (more than
// kMaxUnrolledBoardWords words) keeps its boards in local memory and its
// loops over their words rolled, so few values need registers at once, and
// its warps wait on local memory: more of them an SM hide more of that wait.
// A cap of 80 registers a thread (uncapped, ptxas takes up to 255), on one
// H200 against none, at the best of batches 16,384 and 1,048,576: 14 corpus
// games of 9-60 words 0.99-1.24x.  64 lost up to 18 % (hypermaze), 72 up to
// 10 %.  Over boards that unroll, 80 gave 0.70-1.41x (atlas the best), with
// no sign before ptxas runs of which (docs/performance.md).
constexpr int kRolledBoardRegisters = 80;

// How the GPU code is built (gpuCode, below): decided once per source, as it
// generates the rules to size them.
struct GpuCode {
    bool inRegisters = false;  // the state layout (templates/core.h)
    bool inShared = false;     // the memory layout, stepped in shared memory (templates/cuda_kernels.h)
    bool inGroups = false;     // the memory layout, each rule group on a copy in registers (templates/core.h)
    int units = 1;             // CUDA compile units (templates/core.h)
    int turnUnit = 0;          // the unit compiling the turn (the last, when there are several), or 0
    int runBlocks = 0;         // the stepping kernel's 128-thread blocks an SM (its launch bounds), or 0: none
    int unitRegisters = 0;     // a cap on every unit's registers a thread (0: none): see emitConstants
    RuleUnits rules;           // where the rules go (with the groups layout, which groups stay apart)
    std::string why;           // why `auto` took or left the registers layout (a comment in the source)
};

std::string cString(const std::string& utf8) { return json::quote(utf8); }

int positionOf(int x, int y, int height) { return x * (height + 1) + y; }

bool usesRandom(const Game& g) {
    for (const auto* groups : {&g.rules, &g.lateRules}) {
        for (const auto& group : *groups) {
            if (groupUsesRandom(group)) return true;
        }
    }
    return false;
}

bool hasCommand(const Game& g, std::string_view command) {
    for (const auto* groups : {&g.rules, &g.lateRules}) {
        for (const auto& group : *groups) {
            for (const auto& rule : group.rules) {
                for (const auto& c : rule.commands) {
                    if (c.name == command) return true;
                }
            }
        }
    }
    return false;
}

bool lateRandomDirections(const Game& g) {
    for (const auto& group : g.lateRules) {
        for (const auto& rule : group.rules) {
            for (const auto& row : rule.rows) {
                for (const auto& c : row) {
                    if (c.replacement && c.replacement->randomDirMask.any()) return true;
                }
            }
        }
    }
    return false;
}

template <typename T, typename F>
std::string list(const std::vector<T>& items, F f, const char* empty = "0") {
    if (items.empty()) return empty;
    std::string out;
    for (size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + f(items[i]);
    return out;
}

std::string join(const std::vector<std::string>& items, const char* separator) {
    std::string out;
    for (size_t i = 0; i < items.size(); ++i) out += (i ? separator : "") + items[i];
    return out;
}

// The psc options that shaped the source, as they are written on the command line.
std::string shapingOptions(const SourceOptions& o) {
    std::string out;
    std::vector<std::string> levels;
    for (int l : o.levels) levels.push_back(std::to_string(l));
    if (!levels.empty()) out += " --levels " + join(levels, " ");
    if (o.target != "cpu" && o.gpuState != "auto") out += " --gpu-state " + o.gpuState;
    if (o.target != "cpu" && o.cudaUnits > 0) out += fmt::format(" --cuda-units {}", o.cudaUnits);
    if (o.target != "cpu" && o.searchKernels) out += " --search-kernels";
    if (o.ruleForm != "auto") out += " --rules " + o.ruleForm;
    return out;
}

// `emit`: the --emit stage that prints this source, or empty for a plugin's
// source that includes the CUDA host code (written only with the plugin).
std::string header(const Game& g, const SourceOptions& o, const std::string& emit) {
    const std::string command = emit.empty() ? fmt::format("psc {} -o PLUGIN --target {}{}", o.sourceName, o.target, shapingOptions(o))
                                             : fmt::format("psc {} --emit {}{}", o.sourceName, emit, shapingOptions(o));
    return fmt::format(
        "// Generated by {} from {} (sha1 {}), target {}.\n"
        "// Game: \"{}\": {} objects, {} collision layers, {} + {} rule groups, {} level entries.\n"
        "// Do not edit: regenerate with `{}`.\n\n",
        kGeneratorVersion, o.sourceName, o.sourceSha1, o.target, g.title, g.objectCount, g.layerCount, g.rules.size(),
        g.lateRules.size(), g.levels.size(), command);
}

// The level size shared by every level built, or 0 when they differ.
std::pair<int, int> fixedSize(const Game& g, const SourceOptions& o) {
    int width = -1;
    int height = -1;
    for (size_t i = 0; i < g.levels.size(); ++i) {
        if (g.levels[i].isMessage || !entryBuilt(g, o, i)) continue;
        width = width < 0 || width == g.levels[i].width ? g.levels[i].width : 0;
        height = height < 0 || height == g.levels[i].height ? g.levels[i].height : 0;
    }
    return {std::max(width, 0), std::max(height, 0)};
}

int largestHeight(const Game& g, const SourceOptions& o) {
    int height = 0;
    for (size_t i = 0; i < g.levels.size(); ++i) {
        if (!g.levels[i].isMessage && entryBuilt(g, o, i)) height = std::max(height, g.levels[i].height);
    }
    return height;
}

void emitConstants(CodeWriter& out, const Game& g, const SourceOptions& o, const GpuCode& gpu) {
    out.line(fmt::format("#define PSC_USES_RANDOM {}", usesRandom(g) ? 1 : 0));
    out.line(fmt::format("#define PSC_HAS_RIGID {}", g.hasRigid ? 1 : 0));
    out.line(fmt::format("#define PSC_HAS_RULE_MESSAGES {}", ruleMessages(g).empty() ? 0 : 1));
    out.line(fmt::format("#define PSC_STATE_IN_REGISTERS {}  // the GPU's state layout (templates/core.h)",
                         gpu.inRegisters ? 1 : 0));
    if (o.target != "cpu" && !gpu.why.empty()) out.line("// --gpu-state auto takes registers for " + gpu.why + ".");
    out.line(fmt::format("#define PSC_STATE_IN_SHARED {}  // the stepping kernel's copy in shared memory",
                         gpu.inShared ? 1 : 0));
    out.line(fmt::format("#define PSC_STATE_IN_GROUPS {}  // each rule group on a copy in registers",
                         gpu.inGroups ? 1 : 0));
    if (o.target != "cpu") {
        out.line(fmt::format("#define PSC_GROUP_UNITS {}  // units 1..this compile the groups on a copy",
                             gpu.rules.groupUnits));
        out.line(fmt::format("#define PSC_GROUP_SPANS {}  // a unit's groups of a phase run on one copy (templates/core.h)",
                             gpu.rules.spans ? 1 : 0));
    }
    const int words = boardWords(g, o);
    const bool unrolledWords = gpu.inRegisters || words <= kMaxUnrolledBoardWords;
    out.line(fmt::format("#define PSC_UNROLL_BOARD_WORDS {}  // the GPU unrolls loops over objects, layers and words",
                         unrolledWords ? 1 : 0));
    if (unrolledWords) {
        std::string steps;
        for (int k = 0; k < words; ++k) steps += fmt::format(" PSC_WORD_STEP({}, n, i, __VA_ARGS__)", k);
        out.line("// A loop over a board's words written out, a step a word (PSC_FOR_WORDS, templates/core.h).");
        out.line("#define PSC_WORD_STEPS(n, i, ...)" + steps);
        out.line(fmt::format("#define PSC_GPU_WORDS_WRITTEN_OUT {}  // on the GPU too: the registers layout over one- or two-word boards",
                             gpu.inRegisters && words <= kMaxWrittenOutGpuWords ? 1 : 0));
    }
    if (o.target != "cpu") {
        out.line(fmt::format("#define PSC_COMPILE_UNITS {}  // programs NVRTC compiles at once (templates/core.h)",
                             gpu.units));
        out.line(fmt::format("#define PSC_TURN_UNIT {}  // the unit that compiles the turn (0: unit 0)", gpu.turnUnit));
        out.line(fmt::format("#define PSC_RUN_KERNEL_BLOCKS {}  // the stepping kernel's blocks an SM (0: no launch bounds)",
                             gpu.runBlocks));
        // A kernel's launch bounds cap its registers, and those of what it calls
        // in another unit must fit under the same cap, or the link fails; the
        // memory layout over large boards takes a cap for occupancy
        // (kRolledBoardRegisters).  NVRTC and nvcc (runtime/CudaCompiler.cpp)
        // and the driver's link of PTX (runtime/plugin_host/CudaBackend.cpp)
        // compile every unit so.
        out.line(fmt::format("#define PSC_UNIT_MAX_REGISTERS {}  // registers a thread in every compile unit (0: no cap)",
                             gpu.unitRegisters));
        out.line(fmt::format("#define PSC_SEARCH_KERNELS {}  // psc_expand on the GPU (--search-kernels)",
                             o.searchKernels ? 1 : 0));
    }
    out.line();
    out.open("namespace psc_game");
    out.line(fmt::format("constexpr int kObjects = {};  // object ids, ghost ids included", std::max(1, g.objectCount)));
    out.line(fmt::format("constexpr int kLayers = {};", std::max(1, g.layerCount)));
    out.line(fmt::format("constexpr int kWords = {};  // 64-bit words per bitboard (largest level built)", words));
    const auto [fixedWidth, fixedHeight] = fixedSize(g, o);
    out.line(fmt::format("constexpr int kFixedWidth = {};   // the width of every level built, or 0", fixedWidth));
    out.line(fmt::format("constexpr int kFixedHeight = {};  // the height of every level built, or 0", fixedHeight));
    out.line(fmt::format("constexpr int kMaxBuiltHeight = {};  // the height of the tallest level built", largestHeight(g, o)));
    out.line(fmt::format("constexpr int kEntries = {};  // LEVELS entries, messages included", g.levels.size()));
    out.line(fmt::format("constexpr int kRigidGroupCount = {};", g.rigidGroupIndexToGroupIndex.size()));
    out.line(fmt::format("constexpr int kWinConditionCount = {};", g.winConditions.size()));
    out.line("constexpr int kSeedUnits = 64;");
    out.line(fmt::format("constexpr bool kNoUndo = {};", g.hasMetadata("noundo")));
    out.line(fmt::format("constexpr bool kNoRestart = {};", g.hasMetadata("norestart")));
    out.line(fmt::format("constexpr bool kRunRulesOnLevelStart = {};", g.hasMetadata("run_rules_on_level_start")));
    out.line(fmt::format("constexpr bool kRequirePlayerMovement = {};", g.hasMetadata("require_player_movement")));
    out.line(fmt::format("constexpr bool kMovementsCanLinger = {};  // late rules set random directions",
                         lateRandomDirections(g)));
    out.line(fmt::format("constexpr unsigned long long kMovingLayerBits = 0x{:x}ull;  // layers that can move (movingLayerBits)",
                         movingLayerBits(g)));
    out.line(fmt::format("constexpr bool kSoundReadsCanReload = {};  // a cell's movement sounds can reload its movements",
                         soundReadsCanReload(g)));
    out.line(fmt::format("constexpr bool kHasCheckpoint = {};  // a rule can move the restart target",
                         hasCommand(g, "checkpoint")));
    out.line(fmt::format("constexpr bool kHasRestartCommand = {};  // a rule can queue `restart`", hasCommand(g, "restart")));
    out.line(fmt::format("constexpr bool kHasCancelCommand = {};  // a rule can queue `cancel`", hasCommand(g, "cancel")));
    out.line(fmt::format("constexpr bool kHasAgainCommand = {};  // a rule can queue `again`", hasCommand(g, "again")));
    out.close("  // namespace psc_game");
    out.line();
}

// What movement resolution needs of each collision layer, with the layer's
// object ids as constants: whether a cell holds any of its objects, how many
// movement-sound declarations name an object in the cell, and moving its
// objects from one cell to another.
void emitLayerMoves(CodeWriter& out, const Game& g) {
    auto layerSwitch = [&](const std::string& signature, const std::string& fallback, auto caseBody) {
        out.open(signature);
        out.open("switch (layer)");
        for (size_t L = 0; L < g.layerMasks.size(); ++L) {
            std::string body = caseBody(L);
            if (!body.empty()) out.line(fmt::format("case {}: {}", L, body));
        }
        out.line("default: break;");
        out.close();
        if (!fallback.empty()) out.line(fallback);
        out.close();
    };
    layerSwitch("PSC_DEVICE PSC_INLINE bool layerOccupied(const Env& e, int layer, int p)", "return false;", [&](size_t L) {
        std::vector<std::string> tests;
        for (int id : g.layerMasks[L].bits()) tests.push_back(fmt::format("e.obj[{}].test(p)", id));
        return tests.empty() ? std::string() : "return " + join(tests, " || ") + ";";
    });
    layerSwitch("PSC_DEVICE PSC_INLINE int soundReads(const Env& e, int layer, int p)", "return 0;", [&](size_t L) {
        std::vector<std::string> reads;
        if (L < g.sounds.move.size()) {
            for (const auto& sound : g.sounds.move[L]) reads.push_back(fmt::format("int(e.obj[{}].test(p))", sound.objectId));
        }
        return reads.empty() ? std::string() : "return " + join(reads, " + ") + ";";
    });
    layerSwitch("PSC_DEVICE PSC_INLINE void moveLayerObjects(Env& e, int layer, int from, int to)", "", [&](size_t L) {
        std::string body;
        for (int id : g.layerMasks[L].bits()) body += fmt::format("moveBit(e.obj[{}], from, to); ", id);
        return body.empty() ? std::string() : body + "break;";
    });
    // The memory layout moves a layer's objects in a loop over a table of
    // them (PSC_LAYER_MOVES_ROLLED, templates/core.h).
    const uint64_t moving = movingLayerBits(g);
    std::vector<int> layerStart = {0};
    std::vector<int> layerObjects;
    for (size_t L = 0; L < g.layerMasks.size(); ++L) {
        if (layerCanMove(moving, L)) {
            for (int id : g.layerMasks[L].bits()) layerObjects.push_back(id);
        }
        layerStart.push_back(static_cast<int>(layerObjects.size()));
    }
    if (layerObjects.empty()) layerObjects.push_back(0);  // no zero-length array; every range is empty
    out.line("#if PSC_LAYER_MOVES_ROLLED");
    out.line("// Each moving layer's objects: kMovingLayerObjects[kMovingLayerStart[L] .. kMovingLayerStart[L + 1]).");
    out.line(fmt::format("PSC_TABLE int kMovingLayerStart[] = {{{}}};", fmt::join(layerStart, ", ")));
    out.line(fmt::format("PSC_TABLE int kMovingLayerObjects[] = {{{}}};", fmt::join(layerObjects, ", ")));
    out.open("PSC_DEVICE PSC_INLINE Board layerCells(const Env& e, int layer)");
    out.line("Board cells = Board::zero();");
    out.line("PSC_UNROLL_STATE for (int i = kMovingLayerStart[layer]; i < kMovingLayerStart[layer + 1]; ++i) cells = cells | e.obj[kMovingLayerObjects[i]];");
    out.line("return cells;");
    out.close();
    out.open("PSC_DEVICE PSC_INLINE void moveLayerWhere(Env& e, int layer, const Board (&moved)[4], const Board& leaving, "
             "const int (&steps)[4])");
    out.line("PSC_UNROLL_STATE for (int i = kMovingLayerStart[layer]; i < kMovingLayerStart[layer + 1]; ++i) {");
    out.line("    moveObjectWhere(e.obj[kMovingLayerObjects[i]], moved, leaving, steps);");
    out.line("}");
    out.close();
    out.line("#else");
    // Only the moving layers' cases: the others are never asked for, and
    // NVRTC's optimizer takes time over each case before it drops it.
    layerSwitch("PSC_DEVICE PSC_INLINE Board layerCells(const Env& e, int layer)", "return Board::zero();", [&](size_t L) {
        if (!layerCanMove(moving, L)) return std::string();
        std::vector<std::string> boards;
        for (int id : g.layerMasks[L].bits()) boards.push_back(fmt::format("e.obj[{}]", id));
        return boards.empty() ? std::string() : "return " + join(boards, " | ") + ";";
    });
    layerSwitch("PSC_DEVICE PSC_INLINE void moveLayerWhere(Env& e, int layer, const Board (&moved)[4], const Board& leaving, "
                "const int (&steps)[4])",
                "", [&](size_t L) {
                    if (!layerCanMove(moving, L)) return std::string();
                    std::string body;
                    for (int id : g.layerMasks[L].bits()) {
                        body += fmt::format("moveObjectWhere(e.obj[{}], moved, leaving, steps); ", id);
                    }
                    return body.empty() ? std::string() : body + "break;";
                });
    out.line("#endif");
    out.line();
}

void emitTables(CodeWriter& out, const Game& g, const SourceOptions& o) {
    auto str = [](int v) { return std::to_string(v); };
    out.line("// ---- the game's tables");
    out.open("namespace psc_game");
    // Levels: each level's geometry masks (Env::rowStart, Env::inside), then
    // its object boards, at positions x * (height + 1) + y.  The masks are
    // tables, not computed at the level's start, because an episode's reset
    // runs on one GPU thread while the rest of its warp waits (constellationz
    // spent 5 % of its warp instructions building them).
    const int words = boardWords(g, o);
    std::vector<int> isMessage;
    std::vector<int> widths;
    std::vector<int> heights;
    std::vector<int> offsets;
    std::vector<std::string> boards;
    for (const auto& level : g.levels) {
        isMessage.push_back(level.isMessage ? 1 : 0);
        widths.push_back(level.width);
        heights.push_back(level.height);
        if (level.isMessage) {
            offsets.push_back(-1);
            continue;
        }
        if (!entryBuilt(g, o, offsets.size())) {
            offsets.push_back(-2);  // not built (SourceOptions::levels)
            continue;
        }
        offsets.push_back(static_cast<int>(boards.size()));
        std::vector<uint64_t> rowStart(static_cast<size_t>(words), 0);
        std::vector<uint64_t> inside(static_cast<size_t>(words), 0);
        std::vector<std::vector<uint64_t>> b(static_cast<size_t>(std::max(1, g.objectCount)),
                                             std::vector<uint64_t>(static_cast<size_t>(words), 0));
        for (int x = 0; x < level.width; ++x) {
            for (int y = 0; y < level.height; ++y) {
                const int p = positionOf(x, y, level.height);
                const size_t word = static_cast<size_t>(p / 64);
                const uint64_t bit = 1ull << (p % 64);
                if (y == 0) rowStart[word] |= bit;
                inside[word] |= bit;
                level.cells[static_cast<size_t>(x * level.height + y)].forEach([&](size_t id) {
                    if (id < b.size()) b[id][word] |= bit;
                });
            }
        }
        for (const auto& board : {rowStart, inside}) {
            for (uint64_t w : board) boards.push_back(fmt::format("0x{:x}ull", w));
        }
        for (const auto& object : b) {
            for (uint64_t w : object) boards.push_back(fmt::format("0x{:x}ull", w));
        }
    }
    out.line("PSC_TABLE bool kEntryIsMessage[] = {" + list(isMessage, [](int v) { return std::string(v ? "true" : "false"); }, "false") + "};");
    out.line("PSC_TABLE short kEntryWidth[] = {" + list(widths, str) + "};");
    out.line("PSC_TABLE short kEntryHeight[] = {" + list(heights, str) + "};");
    out.line("PSC_TABLE int kEntryBoards[] = {" + list(offsets, str) + "};");
    out.line("PSC_TABLE u64 kLevelBoards[] = {");
    for (size_t i = 0; i < boards.size(); i += 8) {
        std::string row = "    ";
        for (size_t j = i; j < std::min(boards.size(), i + 8); ++j) row += boards[j] + ", ";
        out.line(row);
    }
    if (boards.empty()) out.line("    0");
    out.line("};");
    out.line();
    // One helper per collision layer: clear the layer at p, except for `keep` (set).
    for (size_t L = 0; L < g.layerMasks.size(); ++L) {
        const std::vector<int> ids = g.layerMasks[L].bits();
        std::string names;
        for (int id : ids) names += (names.empty() ? "" : ", ") + g.objects[static_cast<size_t>(id)].name;
        out.line(fmt::format("// layer {}: {}", L, names));
        out.open(fmt::format("PSC_DEVICE {}bool putLayer{}(Env& e, int p, int keep)", ids.size() <= 2 ? "PSC_INLINE " : "PSC_LAYER ", L));
        out.line("PSC_ON_STACK(e);");
        out.line("bool ch = false;");
        for (int id : ids) out.line(fmt::format("ch |= e.obj[{0}].assign(p, keep == {0});", id));
        out.line("(void)keep;");
        out.line("return ch;");
        out.close();
        // The same at every position of `where`, for rules applied at once (RuleCode).
        out.open(fmt::format("PSC_DEVICE PSC_INLINE bool putLayer{}Where(Env& e, const Board& where, int keep)", L));
        out.line("bool ch = false;");
        for (int id : ids) out.line(fmt::format("ch |= e.obj[{0}].assignWhere(where, keep == {0});", id));
        out.line("(void)keep;");
        out.line("return ch;");
        out.close();
    }
    out.line();
    emitLayerMoves(out, g);
    out.open("PSC_DEVICE PSC_COLD void loadLevelCells(Env& e, int entry)");
    out.line("e.width = kEntryWidth[entry];");
    out.line("e.height = kEntryHeight[entry];");
    out.line("const u64* src = kLevelBoards + kEntryBoards[entry];");
    out.line("for (int w = 0; w < kWords; ++w) {");
    out.line("    e.rowStart.w[w] = src[w];");
    out.line("    e.inside.w[w] = src[kWords + w];");
    out.line("}");
    out.line("src += 2 * kWords;");
    out.line("for (int o = 0; o < kObjects; ++o) {");
    out.line("    for (int w = 0; w < kWords; ++w) e.obj[o].w[w] = src[o * kWords + w];");
    out.line("}");
    out.line("for (int m = 0; m < kLayers * 5; ++m) e.mov[m] = Board::zero();");
    out.close();
    out.line();
    out.close("  // namespace psc_game");
    out.line();
}

std::string objectsExpr(const BitSet& mask, bool all, const char* emptyAll, const char* emptyAny) {
    std::vector<std::string> terms;
    mask.forEach([&](size_t id) { terms.push_back(fmt::format("e.obj[{}]", id)); });
    if (terms.empty()) return all ? emptyAll : emptyAny;
    std::string out;
    for (size_t i = 0; i < terms.size(); ++i) out += (i ? (all ? " & " : " | ") : "") + terms[i];
    return terms.size() > 1 ? "(" + out + ")" : out;
}

// A function over the win conditions: `check` gives each condition's
// statement over its boards a (the objects) and b (what they must be on).
template <typename Check>
void winFunction(CodeWriter& out, const Game& g, const std::string& signature, const std::string& start, Check check,
                 const std::string& finish) {
    out.open(signature);
    if (!start.empty()) out.line(start);
    bool needNonEmpty = false;
    for (const auto& w : g.winConditions) needNonEmpty = needNonEmpty || w.onEverything;
    if (needNonEmpty) {
        std::string all;
        for (int id = 0; id < g.objectCount; ++id) all += fmt::format("{}e.obj[{}]", id ? " | " : "", id);
        out.line("const Board nonEmpty = " + (all.empty() ? std::string("Board::zero()") : "(" + all + ")") + ";");
    }
    for (const auto& w : g.winConditions) {
        const char* q = w.quantifier < 0 ? "no" : w.quantifier > 0 ? "all" : "some";
        out.line(fmt::format("// line {}: {}", w.line, q));
        out.open("");
        out.line("const Board a = " + objectsExpr(w.objects, w.aggregate1, "e.inside", "Board::zero()") + ";");
        out.line("const Board b = " + (w.onEverything ? std::string("nonEmpty")
                                                       : objectsExpr(w.on, w.aggregate2, "e.inside", "Board::zero()")) + ";");
        out.line(check(w));
        out.close();
    }
    out.line("(void)e;");
    out.line(finish);
    out.close();
    out.line();
}

// Search's estimate of the inputs still needed (psc_estimate_distance):
// templates/state_key.h defines the distances it adds up.
void emitWinDistance(CodeWriter& out, const Game& g) {
    out.open("namespace psc_game");
    winFunction(out, g, "PSC_DEVICE inline int winDistance(const Env& e)", "int distance = 0;", [](const WinCondition& w) {
        if (w.quantifier < 0) return std::string("distance += (a & b).count();");
        if (w.onEverything) return std::string(w.quantifier > 0 ? "distance += andNot(a, b).count();" : "distance += a.any() ? 0 : 1;");
        return std::string(w.quantifier > 0 ? "distance += distanceAllOn(e, a, b);" : "distance += distanceSomeOn(e, a, b);");
    }, "return distance;");
    out.close("  // namespace psc_game");
    out.line();
}

void emitPlayerAndWin(CodeWriter& out, const Game& g) {
    out.line("// ---- the player, and win conditions");
    out.open("namespace psc_game");
    out.line(std::string("// Cells holding the player (") + (g.playerIsAggregate ? "all of its parts" : "any player object") + ").");
    out.open("PSC_DEVICE PSC_INLINE Board playerCells(const Env& e)");
    out.line("return " + objectsExpr(g.playerMask, g.playerIsAggregate, "e.inside", "Board::zero()") + ";");
    out.close();
    out.open("PSC_DEVICE PSC_INLINE Board playerObjects(const Env& e)");
    out.line("return " + objectsExpr(g.playerMask, false, "Board::zero()", "Board::zero()") + ";");
    out.close();
    out.line("// The input's direction (field bit k) goes to the layer of every player object at `at`.");
    out.open("PSC_DEVICE PSC_INLINE void addPlayerMovement(Env& e, const Board& at, int k)");
    std::map<int, std::vector<size_t>> playersByLayer;
    g.playerMask.forEach([&](size_t id) {
        const ir::Object& o = g.objects[id];
        std::optional<int> layer = o.layer;
        if (!layer && o.liveId) layer = g.objects[static_cast<size_t>(*o.liveId)].layer;
        if (layer) playersByLayer[*layer].push_back(id);
    });
    for (const auto& [layer, ids] : playersByLayer) {
        std::string players;
        for (size_t id : ids) players += fmt::format("{}e.obj[{}]", players.empty() ? "" : " | ", id);
        if (ids.size() > 1) players = "(" + players + ")";
        out.open("");
        out.line(fmt::format("const Board moving = {} & at;", players));
        // Over the GPU's local memory only the direction's board is written
        // (limerick's four player objects had rewritten their layer's five
        // boards each).  Elsewhere selects over the five keep the boards in
        // registers (a board picked by a run-time index would leave them) or,
        // on the CPU, where the compiler knows them (kettle 0.95x, takeheart
        // 0.90x on one thread with the index).
        out.line("#if defined(__CUDA_ARCH__) && !PSC_STATE_IN_REGISTERS && !PSC_GROUP_COPIES_STATE");
        out.line(fmt::format("e.mov[{0} + k] = e.mov[{0} + k] | moving;", 5 * layer));
        out.line("#else");
        out.line(fmt::format("PSC_UNROLL for (int d = 0; d < 5; ++d) e.mov[{0} + d] = d == k ? e.mov[{0} + d] | moving : e.mov[{0} + d];",
                             5 * layer));
        out.line("#endif");
        out.close();
    }
    out.line("(void)e;");
    out.line("(void)at;");
    out.line("(void)k;");
    out.close();
    out.line();
    winFunction(out, g, "PSC_DEVICE PSC_INLINE bool winConditionsHold(const Env& e)", "", [](const WinCondition& w) {
        return w.quantifier < 0 ? "if ((a & b).any()) return false;"
               : w.quantifier > 0 ? "if (andNot(a, b).any()) return false;"
                                  : "if (!(a & b).any()) return false;";
    }, "return true;");
    out.close("  // namespace psc_game");
    out.line();
}

void emitHostInfo(CodeWriter& out, const Game& g, const SourceOptions& o) {
    out.line("// ---- game information for the host");
    out.open("namespace psc_game");
    std::vector<int> channels;
    for (const auto& obj : g.objects) {
        if (!obj.ghost) channels.push_back(obj.id);
    }
    auto str = [](int v) { return std::to_string(v); };
    out.line(fmt::format("constexpr int kChannelCount = {};", channels.size()));
    out.line("static const int kChannelObject[] = {" + list(channels, str) + "};");
    std::vector<std::string> names;
    for (const auto& obj : g.objects) names.push_back(cString(obj.name));
    if (names.empty()) names.push_back("\"\"");
    out.line("static const char* const kObjectNames[] = {" + list(names, [](const std::string& s) { return s; }) + "};");
    std::vector<std::string> channelNames;
    std::vector<int> channelLayers;
    for (int id : channels) {
        channelNames.push_back(cString(g.objects[static_cast<size_t>(id)].name));
        channelLayers.push_back(g.objects[static_cast<size_t>(id)].layer.value_or(-1));
    }
    out.line("static const char* const kChannelNames[] = {" + list(channelNames, [](const std::string& s) { return s; }, "\"\"") + "};");
    out.line("static const int32_t kChannelLayers[] = {" + list(channelLayers, str) + "};");
    // Rank of each object's name in JavaScript's default sort (the dump sorts cell contents so).
    std::vector<int> order;
    for (int id = 0; id < g.objectCount; ++id) order.push_back(id);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        return js::lessUtf16(g.objects[static_cast<size_t>(a)].name, g.objects[static_cast<size_t>(b)].name);
    });
    std::vector<int> rank(static_cast<size_t>(std::max(1, g.objectCount)), 0);
    for (size_t i = 0; i < order.size(); ++i) rank[static_cast<size_t>(order[i])] = static_cast<int>(i);
    out.line("static const int kObjectNameRank[] = {" + list(rank, str) + "};");

    std::vector<int> levelEntries;
    std::vector<int> levelBuilt;
    std::vector<int> levelWidths;
    std::vector<int> levelHeights;
    int maxWidth = 0;
    int maxHeight = 0;
    std::vector<std::string> messages;
    std::vector<int> isMessage;
    for (size_t i = 0; i < g.levels.size(); ++i) {
        const auto& l = g.levels[i];
        isMessage.push_back(l.isMessage ? 1 : 0);
        messages.push_back(cString(l.isMessage ? js::trim(l.message) : std::string()));
        if (l.isMessage) continue;
        levelEntries.push_back(static_cast<int>(i));
        levelBuilt.push_back(entryBuilt(g, o, i) ? 1 : 0);
        levelWidths.push_back(l.width);
        levelHeights.push_back(l.height);
        maxWidth = std::max(maxWidth, l.width);
        maxHeight = std::max(maxHeight, l.height);
    }
    out.line(fmt::format("constexpr int kLevelCount = {};", levelEntries.size()));
    out.line(fmt::format("constexpr int kMaxWidth = {};", maxWidth));
    out.line(fmt::format("constexpr int kMaxHeight = {};", maxHeight));
    out.line("static const int32_t kLevelEntries[] = {" + list(levelEntries, str) + "};");
    out.line("static const uint8_t kLevelBuilt[] = {" + list(levelBuilt, str) + "};");
    out.line("static const int32_t kLevelWidths[] = {" + list(levelWidths, str) + "};");
    out.line("static const int32_t kLevelHeights[] = {" + list(levelHeights, str) + "};");
    out.line("static const uint8_t kHostEntryIsMessage[] = {" + list(isMessage, str) + "};");
    out.line("static const char* const kEntryMessages[] = {" + list(messages, [](const std::string& s) { return s; }, "\"\"") + "};");

    auto meta = [&](const char* key) {
        const ir::MetadataValue* v = g.metadataValue(key);
        return cString(v ? v->text : std::string());
    };
    std::vector<std::string> flags;
    if (g.hasMetadata("noaction")) flags.push_back("PSC_FLAG_NOACTION");
    if (g.hasMetadata("noundo")) flags.push_back("PSC_FLAG_NOUNDO");
    if (g.hasMetadata("norestart")) flags.push_back("PSC_FLAG_NORESTART");
    if (g.hasMetadata("require_player_movement")) flags.push_back("PSC_FLAG_REQUIRE_PLAYER_MOVEMENT");
    if (g.hasMetadata("run_rules_on_level_start")) flags.push_back("PSC_FLAG_RUN_RULES_ON_LEVEL_START");
    if (g.hasMetadata("realtime_interval")) flags.push_back("PSC_FLAG_REALTIME");
    if (usesRandom(g)) flags.push_back("PSC_FLAG_USES_RANDOM");
    if (g.hasRigid) flags.push_back("PSC_FLAG_HAS_RIGID");
    std::string flagExpr = flags.empty() ? "0u" : list(flags, [](const std::string& f) { return f; });
    for (size_t at; (at = flagExpr.find(", ")) != std::string::npos;) flagExpr.replace(at, 2, " | ");
    double realtime = 0;
    if (const ir::MetadataValue* v = g.metadataValue("realtime_interval")) realtime = js::toNumber(v->text);
    if (!(realtime > 0)) realtime = 0;
    double again = 0.15;  // the reference player's default
    if (const ir::MetadataValue* v = g.metadataValue("again_interval")) again = js::toNumber(v->text);
    if (!(again >= 0) || !std::isfinite(again)) again = 0.15;
    const std::vector<std::string> ruleTexts = ruleMessages(g);
    out.line(fmt::format("constexpr int kRuleMessageCount = {};", ruleTexts.size()));
    out.line("static const char* const kRuleMessages[] = {" +
             list(ruleTexts, [](const std::string& t) { return cString(t); }, "\"\"") + "};");
    // Sprites (5x5, -1 transparent) and colours (0xRRGGBB) per channel.
    std::vector<int> sprites;
    std::vector<std::string> colors;
    auto rgb = [](const std::string& hex) -> std::string {
        if (hex.size() == 7 && hex[0] == '#') return "0x" + hex.substr(1) + "u";
        if (hex.size() == 4 && hex[0] == '#') return fmt::format("0x{0}{0}{1}{1}{2}{2}u", hex[1], hex[2], hex[3]);
        return "0u";
    };
    for (int id : channels) {
        const ir::Object& obj = g.objects[static_cast<size_t>(id)];
        for (int r = 0; r < 5; ++r) {
            for (int c = 0; c < 5; ++c) {
                int v = -1;
                if (static_cast<size_t>(r) < obj.sprite.size() && static_cast<size_t>(c) < obj.sprite[static_cast<size_t>(r)].size()) {
                    v = obj.sprite[static_cast<size_t>(r)][static_cast<size_t>(c)];
                    if (v >= static_cast<int>(obj.colors.size()) || (v >= 0 && obj.colors[static_cast<size_t>(v)] == "transparent")) v = -1;
                }
                sprites.push_back(v < 0 ? -1 : v);
            }
        }
        for (size_t k = 0; k < 10; ++k) colors.push_back(k < obj.colors.size() ? rgb(obj.colors[k]) : "0u");
    }
    out.line("static const int8_t kObjectSprites[] = {" + list(sprites, str) + "};");
    out.line("static const uint32_t kObjectColors[] = {" + list(colors, [](const std::string& c) { return c; }, "0u") + "};");
    auto themeColor = [&](const char* key, const char* fallback) {
        std::string palette = palette::kDefaultPalette;
        if (const ir::MetadataValue* p = g.metadataValue("color_palette")) {
            if (auto resolved = palette::resolve(p->text)) palette = *resolved;
        }
        const ir::MetadataValue* v = g.metadataValue(key);
        std::string hex = v ? palette::toHex(palette, v->text) : fallback;
        if (!palette::isColor(hex) || hex == "transparent") hex = fallback;
        return rgb(hex);
    };
    out.line("static const psc_game_info kGameInfo = {");
    out.line("    PSC_ABI_VERSION,");
    out.line(fmt::format("    {}, {}, {},", meta("title"), meta("author"), meta("homepage")));
    out.line(fmt::format("    {}, {},", cString(o.sourceName), cString(o.sourceSha1)));
    out.line(fmt::format("    {},", cString(std::string(kGeneratorVersion) + ", target " + o.target)));
    out.line(fmt::format("    {},", flagExpr));
    out.line(fmt::format("    {},", o.target == "cpu" ? "1u << PSC_BACKEND_CPU" : "(1u << PSC_BACKEND_CPU) | (1u << PSC_BACKEND_CUDA)"));
    out.line(fmt::format("    kChannelCount, kChannelNames, kChannelLayers, {},", g.layerCount));
    out.line("    kLevelCount, kLevelEntries, kLevelBuilt, kLevelWidths, kLevelHeights, kMaxWidth, kMaxHeight,");
    out.line(fmt::format("    {}, kHostEntryIsMessage, kEntryMessages,", g.levels.size()));
    out.line(fmt::format("    PSC_ACTION_COUNT, {},", realtime));
    out.line(fmt::format("    kObjectSprites, kObjectColors, {}, {},", themeColor("background_color", "#000000"),
                         themeColor("text_color", "#ffffff")));
    out.line("    static_cast<uint32_t>(sizeof(u64) * kKeyWords),");
    out.line(fmt::format("    {}, kRuleMessageCount, kRuleMessages,", again));
    out.line("};");
    out.close("  // namespace psc_game");
    out.line();
}

}  // namespace

bool entryBuilt(const ir::Game& game, const SourceOptions& options, size_t entry) {
    if (options.levels.empty() || game.levels[entry].isMessage) return true;
    int level = 0;
    for (size_t i = 0; i < entry; ++i) level += game.levels[i].isMessage ? 0 : 1;
    return std::find(options.levels.begin(), options.levels.end(), level) != options.levels.end();
}

int boardWords(const ir::Game& game, const SourceOptions& options) {
    int words = 1;
    for (size_t i = 0; i < game.levels.size(); ++i) {
        const auto& l = game.levels[i];
        if (!l.isMessage && entryBuilt(game, options, i)) words = std::max(words, (l.width * (l.height + 1) + 63) / 64);
    }
    return words;
}

namespace {

// The turn's state in 64-bit words: the boards of every object and moving
// layer, the inside and row-start masks, and the turn's backup of the objects.
int turnStateWords(const ir::Game& game, int words) {
    const int movingLayers = std::popcount(movingLayerBits(game));
    return (2 * std::max(1, game.objectCount) + 5 * movingLayers + 2) * words;
}

// With the state in registers ptxas would take up to 255 registers a thread
// and leave two 128-thread blocks an SM; more warps hide more latency than
// the spills of a register cap cost.  Four blocks (at most 128 registers)
// where the turn's state (turnStateWords) is at most 48 64-bit words,
// leaving a quarter of the registers to the rules, and the rules' code
// times board words is at most 20 k, below the layout's
// budget, where ptxas's extra spilling does not slow the build; else three
// (at most 168).  On one H100 (docs/performance.md), against three: match3
// (34 words, 16.5 k of code) +14 % and blocks (45, 1.4 k) +13 % at their
// best batches; traveling (25, 21.8 k) +16 %, but its build 0.4-0.7 s
// slower (2.7 -> 3.1 s); zenpuzzle (57) +1 % but 3-4 % slower at batches
// up to 16,384; constellationz (76) spills 7.3 kB at 128 and loses 35 %.
int registerLayoutBlocks(const ir::Game& game, int words, size_t ruleBytes) {
    constexpr int kFourBlockStateWords = 48;
    constexpr size_t kFourBlockCodeWeight = 20000;
    const bool small =
        turnStateWords(game, words) <= kFourBlockStateWords && ruleBytes * static_cast<size_t>(words) <= kFourBlockCodeWeight;
    return small ? 4 : 3;
}

GpuCode gpuCode(const ir::Game& game, const SourceOptions& options, const RuleFormChoice& form) {
    const size_t ruleBytes = form.codeBytes;
    const int words = boardWords(game, options);
    GpuCode gpu;
    if (form.table) {
        // The interpreter reads boards by run-time index, which would leave
        // registers anyway.  Its code is small, but as one program every
        // kernel that runs a turn (stepping, and a reset's level-start turn)
        // inlined it and ptxas compiled it once for each: 10-70 s of NVRTC
        // on the development machine for six corpus games drawn from the 105
        // whose rules are a table.  So the turn has a unit of its own, unless
        // --cuda-units 1 asks for one program (docs/performance.md).
        gpu.inRegisters = options.gpuState == "registers";
        gpu.inShared = options.gpuState == "shared";
        if (!gpu.inRegisters && options.cudaUnits != 1) {
            gpu.turnUnit = 1;
            gpu.units = 2;
        }
        return gpu;
    }
    if (options.gpuState != "auto") {
        gpu.inRegisters = options.gpuState == "registers";
        gpu.inShared = options.gpuState == "shared";
        gpu.inGroups = options.gpuState == "groups";
    } else {
        // A turn's state of more than 127 words, two registers each, cannot
        // be held in a thread's 255 registers: ptxas spills it, slowly (on
        // one H100, corpus games of 136-497 words built in 2.2-11.5 s in
        // registers, 0.9-1.7 s in groups, and stepped 0.77-1.27x as fast;
        // games of 82-101 words 1.6-4.1x; docs/performance.md).
        constexpr int kRegisterStateWords = 127;
        const size_t weight = ruleBytes * static_cast<size_t>(words);
        const int stateWords = turnStateWords(game, words);
        gpu.inRegisters = words <= kMaxUnrolledBoardWords && weight <= kRegisterCodeBudget && stateWords <= kRegisterStateWords;
        gpu.why = fmt::format("boards of at most {} words (here {}), rule code x board words of at most {} (here {}) and a turn's "
                              "state of at most {} words (here {})",
                              kMaxUnrolledBoardWords, words, kRegisterCodeBudget, weight, kRegisterStateWords, stateWords);
    }
    if (gpu.inRegisters) {
        gpu.runBlocks = registerLayoutBlocks(game, words, ruleBytes);
        // The stepping kernel in one unit, the rest in another (templates/core.h),
        // unless --cuda-units 1 asks for one program.
        gpu.units = options.cudaUnits == 1 ? 1 : 2;
        // An SM's 64 K registers shared by runBlocks blocks of 128 threads, in ptxas's steps of 8.
        if (gpu.units > 1 && gpu.runBlocks > 0) gpu.unitRegisters = std::min(255, 65536 / (128 * gpu.runBlocks) / 8 * 8);
        return gpu;
    }
    const int groups = static_cast<int>(game.rules.size() + game.lateRules.size());
    if (groups == 0) return gpu;

    // The groups layout: units 1..groupUnits for the groups on a copy, then
    // units for those apart, by code size as the memory layout's.  Only a
    // random group cannot be split into parts, and stays apart when large.
    size_t copiedWeight = 0;
    size_t apartBytes = 0;
    for (size_t i = 0; i < form.groupCodeBytes.size(); ++i) {
        const size_t bytes = form.groupCodeBytes[i];
        const bool random = i < game.rules.size() ? game.rules[i].random : game.lateRules[i - game.rules.size()].random;
        const bool apart = random && bytes * static_cast<size_t>(words) > kGroupCopyBudget;
        gpu.rules.apart.push_back(apart);
        if (apart) {
            apartBytes += bytes;
        } else {
            copiedWeight += bytes * static_cast<size_t>(words);
        }
    }
    gpu.rules.partBytes = kGroupCopyBudget / static_cast<size_t>(words);
    gpu.rules.copyWeight = static_cast<size_t>(words);
    const int copyUnits = static_cast<int>((copiedWeight + kGroupUnitWeight - 1) / kGroupUnitWeight);
    const int apartUnits = static_cast<int>((apartBytes + kRuleBytesPerUnit - 1) / kRuleBytesPerUnit);
    if (options.gpuState == "auto") {
        // A random group's copy would hold the random stream, which rules
        // index at run time: it would stay in memory, copied in and out whole.
        gpu.inGroups = !usesRandom(game) && words <= kMaxUnrolledBoardWords && copyUnits >= 1 &&
                       copyUnits + apartUnits <= kMaxCompileUnits - 1;
    }
    gpu.rules.groups = gpu.inGroups;
    gpu.rules.rolledPasses = !gpu.inGroups;
    if (gpu.inGroups) {
        // Within kMaxCompileUnits, at least one unit of each kind needed.
        gpu.rules.groupUnits = std::clamp(copyUnits, copyUnits > 0 ? 1 : 0, kMaxCompileUnits - 1 - std::min(apartUnits, 1));
        const int rest = std::clamp(apartUnits, std::min(apartUnits, 1), kMaxCompileUnits - 1 - gpu.rules.groupUnits);
        gpu.units = 1 + gpu.rules.groupUnits + rest;
        // Spans where the turn runs each group once, in order (no loops, no
        // rigid bans, no random stream, which a copy would hold in local
        // memory, no group apart), and no group alone is more code than
        // the registers layout compiles as one kernel: a span is not split.
        const bool large = std::any_of(form.groupCodeBytes.begin(), form.groupCodeBytes.end(),
                                       [&](size_t bytes) { return bytes * static_cast<size_t>(words) > kRegisterCodeBudget; });
        gpu.rules.spans = apartUnits == 0 && !large && !usesRandom(game) && !game.hasRigid && game.loopPoints.empty() &&
                          game.lateLoopPoints.empty();
        if (gpu.rules.spans && gpu.rules.groupUnits > groups) {
            // A span's unit holds whole groups: no more units than groups.
            gpu.rules.groupUnits = groups;
            gpu.units = 1 + gpu.rules.groupUnits + rest;
        }
    } else {
        // The memory layout inlines a group's rules into it (templates/core.h)
        // up to kInlinedGroupWeight; a larger group, or one over boards too
        // large to unroll, calls its rules, each a function (apart).
        gpu.rules.apart.clear();
        for (const size_t bytes : form.groupCodeBytes) {
            gpu.rules.apart.push_back(words > kMaxUnrolledBoardWords || bytes * static_cast<size_t>(words) > kInlinedGroupWeight);
        }
        if (options.cudaUnits > 0) {
            // --cuda-units counts the turn's unit, which 3 units or more have.
            gpu.units = std::min(options.cudaUnits >= 3 ? options.cudaUnits - 1 : options.cudaUnits, groups + 1);
        } else {
            const int ruleUnits = static_cast<int>((ruleBytes + kRuleBytesPerUnit - 1) / kRuleBytesPerUnit);
            gpu.units = 1 + std::min({std::max(ruleUnits, 1), groups, kMaxCompileUnits - 1});
        }
    }
    gpu.rules.units = gpu.units;
    if (!gpu.inGroups && !gpu.inShared && words > kMaxUnrolledBoardWords) gpu.unitRegisters = kRolledBoardRegisters;
    if (gpu.units > 1 && options.cudaUnits != 2) {
        // The turn's own unit: in unit 0, with the kernels, it made that
        // unit the slowest to compile (docs/performance.md).
        gpu.turnUnit = gpu.units;
        ++gpu.units;
    }
    return gpu;
}

}  // namespace

RuleFormChoice ruleForm(const ir::Game& game, const SourceOptions& options) {
    if (options.decidedRuleForm) return *options.decidedRuleForm;
    RuleFormChoice choice;
    if (options.ruleForm == "table") {
        choice.table = true;
        choice.reason = "rules as a table (--rules table)";
        return choice;
    }
    CodeWriter rules;
    RuleUnits weighed;
    weighed.directionSets = false;
    weighed.oneMatchPaths = false;
    emitRules(rules, game, weighed, &choice.groupCodeBytes);
    choice.codeBytes = rules.text().size();
    const double megabytes = static_cast<double>(choice.codeBytes) / 1e6;
    if (options.ruleForm == "code") {
        choice.reason = fmt::format("rules as code (--rules code): {:.2f} MB", megabytes);
    } else if (choice.codeBytes > kTableRuleCodeBytes) {
        choice.table = true;
        choice.reason = fmt::format("rules as a table: their code would be {:.2f} MB, over the {:.1f} MB that compiles in time",
                                    megabytes, static_cast<double>(kTableRuleCodeBytes) / 1e6);
    } else {
        choice.reason = fmt::format("rules as code: {:.2f} MB ({} bytes)", megabytes, choice.codeBytes);
    }
    return choice;
}

int hostCompileUnits(const ir::Game& game, const SourceOptions& options) {
    if (options.target == "cpu") return 1;
    // The registers layout's two CUDA units split its kernels, not its rules.
    const GpuCode gpu = gpuCode(game, options, ruleForm(game, options));
    return gpu.inRegisters ? 1 : gpu.units;
}

std::string gpuStateLayout(const ir::Game& game, const SourceOptions& options) {
    const GpuCode gpu = gpuCode(game, options, ruleForm(game, options));
    return gpu.inRegisters ? "registers" : gpu.inGroups ? "groups" : gpu.inShared ? "shared" : "memory";
}

std::string deviceSource(const ir::Game& game, const SourceOptions& options) {
    CodeWriter out;
    const RuleFormChoice form = ruleForm(game, options);
    const GpuCode gpu = gpuCode(game, options, form);
    emitConstants(out, game, options, gpu);
    out.raw(templates::core());
    out.line();
    emitTables(out, game, options);
    emitPlayerAndWin(out, game);
    out.line("// ---- the rules");
    out.open("namespace psc_game");
    out.line("PSC_DEVICE PSC_INLINE u32 queueCommands(u32 queue, u32 commands);");
    if (!ruleMessages(game).empty()) out.line("PSC_DEVICE PSC_INLINE void queueMessageRule(Env& e, u32 commands, int message);");
    out.line();
    if (form.table) {
        emitRuleTableData(out, game);
        out.close("  // namespace psc_game");
        out.line();
        out.raw(templates::ruleTable());
        out.line();
        out.open("namespace psc_game");
        emitRuleTableGroups(out);
    } else {
        emitRules(out, game, options.target == "cpu" ? RuleUnits{} : gpu.rules);
    }
    out.line(fmt::format("constexpr bool kHasDormantGroups = {};  // groups the turn skips once they go dormant (codegen/DormantGroups.h)",
                         !form.table && dormantGroups(game).any()));
    out.close("  // namespace psc_game");
    out.line();
    out.raw(templates::movement());
    out.line();
    out.raw(templates::engine());
    out.line();
    const std::vector<int> keyIds = keyObjects(game);
    out.open("namespace psc_game");
    out.line(fmt::format("constexpr int kKeyObjectCount = {};  // objects an input can create, destroy or move", keyIds.size()));
    out.line("PSC_TABLE int kKeyObjects[] = {" + list(keyIds, [](int id) { return std::to_string(id); }, "-1") + "};");
    const std::vector<int> folds = keyFolds(game, keyIds);
    bool folding = false;
    for (size_t k = 0; k < folds.size(); ++k) {
        if (folds[k] == static_cast<int>(k)) continue;
        folding = true;
        out.line(fmt::format("// search takes {} for {}: nothing but their creation tells them apart (codegen/KeyObjects.h)",
                             game.objects[static_cast<size_t>(keyIds[k])].name,
                             game.objects[static_cast<size_t>(keyIds[static_cast<size_t>(folds[k])])].name));
    }
    out.line(fmt::format("constexpr bool kKeyFolds = {};", folding));
    out.line("PSC_TABLE int kKeyFoldInto[] = {" + list(folds, [](int k) { return std::to_string(k); }, "0") + "};");
    out.close("  // namespace psc_game");
    out.line();
    out.raw(templates::stateKey());
    out.line();
    emitWinDistance(out, game);
    return out.text();
}

std::string cudaSource(const ir::Game& game, const SourceOptions& options) {
    CodeWriter out;
    out.raw(header(game, options, "cuda"));
    out.raw(deviceSource(game, options));
    out.line();
    out.raw(templates::cudaKernels());
    return out.text();
}

namespace {
// A plugin's source: the ABI header, the game's engine code, its static
// description and the game module that the plugin host (runtime/plugin_host,
// linked in) drives; with the CUDA backend, the device code's declarations.
std::string pluginSource(const ir::Game& game, const SourceOptions& options) {
    const bool cuda = options.target != "cpu";
    CodeWriter out;
    out.raw(header(game, options, cuda ? "" : "cpp"));
    out.raw(templates::pluginHeader());
    out.line();
    out.raw(templates::gameModuleHeader());
    out.line();
    out.raw(deviceSource(game, options));
    out.line();
    out.line(fmt::format("// The game module: compile unit 0 of {} (templates/core.h).", hostCompileUnits(game, options)));
    out.raw("#if PSC_COMPILES_UNIT(0)\n");
    emitHostInfo(out, game, options);
    if (cuda) {
        out.line("// ---- the game's device code, compiled for CUDA, is added to the linked plugin");
        out.line("// (runtime/plugin_host/DeviceImage.h): this source compiles while NVRTC runs.");
    }
    out.line(fmt::format("#define PSC_PLUGIN_DEVICE_CODE {}", cuda ? 1 : 0));
    out.line();
    out.raw(templates::gameModule());
    out.raw("#endif  // compile unit 0\n");
    return out.text();
}
}  // namespace

std::string cudaPluginSource(const ir::Game& game, const SourceOptions& options) { return pluginSource(game, options); }

std::string cpuPluginSource(const ir::Game& game, const SourceOptions& options) { return pluginSource(game, options); }

}  // namespace psc::codegen
