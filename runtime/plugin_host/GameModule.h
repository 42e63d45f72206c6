// What a game's generated code hands the plugin host: its sizes, its tables
// and the engine's entry points, as one constant (psc_game_module, defined
// by templates/game_module.h).  The host (the rest of this folder) is
// compiled once with psc and linked into every plugin, where it implements
// the C ABI of psc_plugin.h on top of this module: a plugin build compiles
// only the game.  An environment is opaque to the host, envBytes of plain
// data that it copies, saves and uploads as bytes.
//
// Include psc_plugin.h first: a generated source holds both, embedded, and
// includes neither (hence include guards, not #pragma once).
#ifndef PSC_GAME_MODULE_H
#define PSC_GAME_MODULE_H

#include <stddef.h>
#include <stdint.h>

namespace psc_host {

// Raised whenever the module's layout changes; the host refuses a module of
// another version (a plugin built from mismatched parts).
constexpr uint32_t kGameModuleVersion = 6;

// A ring of undo snapshots, laid out as the engine's UndoStack (whose turn
// scratch only the GPU's kernels use: null here).
struct UndoRing {
    void* entries;
    int capacity;
    int count;
    int head;  // index of the oldest entry
    void* turnScratch;
    int turnScratchDepth;
    unsigned long long deadline;  // the engine's UndoStack::deadline (psc_expand's own undo stack sets it)
};

// The fields of an environment the host reads.
struct EnvView {
    int entry;  // LEVELS entry shown
    int screen;  // 0 level, 1 message, 2 title
    int startExisted;
    int width;
    int height;
    int episodeSteps;
    int againing;
    int shownMessage;  // rule message index, or -1
    int startCutOff;   // the last reset's start chain was cut off
    int startWon;      // the last reset's start won the level
};

// A CUDA batch's device pointers, passed by value to every kernel: the
// engine's DeviceBatch, with the game's types left out.
struct DeviceBuffers {
    void* envs;
    void* undoEntries;  // [numEnvs][undoDepth]
    int* undoCount;
    int* undoHead;
    int undoDepth;
    int numEnvs;
    int* actions;
    uint8_t* observations;
    float* rewards;
    uint8_t* terminated;
    uint8_t* truncated;
    uint8_t* won;
    int* episodeSteps;
    const int* channelObjects;
    int channels;
    int maxWidth;
    int maxHeight;
    unsigned long long* stats;  // steps, wins, episodes, invalid actions (psc_run_kernel)
    void* turnScratch;          // turnScratchBytes an environment, where DeviceCode asks for it
};

// What the CUDA backend needs to know of the game's device code (a plugin
// built with the CUDA backend), besides the code itself, which the plugin's
// file holds (DeviceImage.h).
struct DeviceCode {
    int stateInShared;         // the stepping kernel keeps environments in shared memory
    unsigned sharedEnvStride;  // bytes between two of them there
    int searchKernels;         // psc_expand_kernel was compiled
    int expandTooLarge;        // environments too large to expand on the GPU
    // Device memory each environment's turns need besides the stack (0: none):
    // the scratch of environments too large for the stack.
    size_t turnScratchBytes;
    int unitMaxRegisters;  // registers a thread the driver's link of PTX units allows (0: no cap)
};

struct GameModule {
    uint32_t version;  // kGameModuleVersion
    const psc_game_info* info;
    size_t envBytes;
    size_t snapshotBytes;  // an undo entry
    int seedUnits;         // UTF-16 units of a level seed the environment holds
    int keyWords;          // 64-bit words of a state key
    const int* entryBoards;  // per LEVELS entry: -2 where the entry was left out of the plugin
    const int* channelObjects;
    const DeviceCode* device;  // NULL in a CPU-only plugin

    // An environment zeroed, with the batch's settings and the entry its episodes start at.
    void (*initEnv)(void* env, int levelEntry, int autoReset, int againMode, int maxEpisodeSteps);
    void (*setLevelEntry)(void* env, int entry);
    int (*setSeed)(void* env, const uint16_t* units, size_t count);  // 0: longer than seedUnits
    // The fields a loaded state indexes with are in range, and its boards and
    // its `count` undo snapshots hold positions of its level's cells only.
    int (*plausible)(const void* env, const void* snapshots, int count);
    void (*view)(const void* env, EnvView* out);
    // The object ids in cell (x, y), in id order; returns how many.
    int (*cellObjects)(const void* env, int x, int y, int* ids);
    int objectCount;                 // object ids, ghosts included
    const char* const* objectNames;  // by object id
    const int* objectNameRank;       // each object's rank in JavaScript's default sort of the names

    void (*startEpisode)(void* env, UndoRing* undo);
    void (*step)(void* env, UndoRing* undo, int action, psc_step_result* result);
    void (*observe)(const void* env, uint8_t* out);  // channels × max_height × max_width
    // One environment's part of psc_step_many: `steps` steps, its k-th action
    // actions[k * stride] and its results likewise (each output may be NULL).
    void (*stepMany)(void* env, UndoRing* undo, int32_t steps, const int32_t* actions, size_t stride, float* rewards,
                     uint8_t* terminated, uint8_t* truncated, uint8_t* won);
    // One environment's part of psc_rollout: environment `index`'s random
    // actions from `seed` for steps firstStep, firstStep + 1, ...; adds to `stats`.
    void (*rollout)(void* env, UndoRing* undo, int32_t steps, uint64_t seed, uint64_t index, uint64_t firstStep,
                    int actionCount, psc_rollout_stats* stats);
    void (*clearUndo)(UndoRing* undo);

    void (*encodeKey)(const void* env, uint64_t* key);
    int (*decodeKey)(void* env, const uint64_t* key);  // 0: the key is no state of env's level
    int (*keyEntry)(const uint64_t* key);
    uint64_t (*hashKey)(const uint64_t* key);
    void (*foldKey)(uint64_t* key);  // into search's form (psc_canonical_keys)
    // deadline: steadyNanoseconds (ExpandDeadline.h) when the expansion stops, 0: none.
    uint8_t (*expandKey)(void* env, const uint64_t* parent, int input, uint64_t* child, int64_t deadline);
    int (*winDistance)(const void* env);
};

}  // namespace psc_host

// Defined by the game's code in every plugin (hidden: each plugin has its own).
extern "C" const psc_host::GameModule psc_game_module;

#endif  // PSC_GAME_MODULE_H
