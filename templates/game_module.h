// ---- psc template: the game module ------------------------------------------
// The engine's entry points and the game's tables, as the plugin host
// (runtime/plugin_host, compiled once with psc and linked into every plugin)
// calls them: psc_game_module.  Expects runtime/plugin_host/GameModule.h,
// the host information above, and PSC_PLUGIN_DEVICE_CODE (1: the CUDA
// backend's code is linked in, declared above).

namespace psc_game {
namespace {

static_assert(sizeof(UndoStack) == sizeof(psc_host::UndoRing) && offsetof(UndoStack, entries) == offsetof(psc_host::UndoRing, entries) &&
                  offsetof(UndoStack, capacity) == offsetof(psc_host::UndoRing, capacity) &&
                  offsetof(UndoStack, count) == offsetof(psc_host::UndoRing, count) &&
                  offsetof(UndoStack, head) == offsetof(psc_host::UndoRing, head) &&
                  offsetof(UndoStack, scratch) == offsetof(psc_host::UndoRing, turnScratch) &&
                  offsetof(UndoStack, scratchDepth) == offsetof(psc_host::UndoRing, turnScratchDepth) &&
                  offsetof(UndoStack, deadline) == offsetof(psc_host::UndoRing, deadline),
              "the host's undo ring is the engine's UndoStack");
static_assert(alignof(Env) <= 8 && alignof(Snapshot) <= 8, "the host keeps environments 8-byte aligned");
static_assert(sizeof(DeviceBatch) == sizeof(psc_host::DeviceBuffers) &&
                  offsetof(DeviceBatch, undoDepth) == offsetof(psc_host::DeviceBuffers, undoDepth) &&
                  offsetof(DeviceBatch, channelObjects) == offsetof(psc_host::DeviceBuffers, channelObjects) &&
                  offsetof(DeviceBatch, stats) == offsetof(psc_host::DeviceBuffers, stats) &&
                  offsetof(DeviceBatch, turnScratch) == offsetof(psc_host::DeviceBuffers, turnScratch),
              "the host's device buffers are the kernels' DeviceBatch");

Env& envOf(void* env) { return *static_cast<Env*>(env); }
const Env& envOf(const void* env) { return *static_cast<const Env*>(env); }
UndoStack& undoOf(psc_host::UndoRing* undo) { return *reinterpret_cast<UndoStack*>(undo); }

void moduleInitEnv(void* env, int levelEntry, int autoReset, int againMode, int maxEpisodeSteps) {
    Env& e = envOf(env);
    __builtin_memset(&e, 0, sizeof(Env));
    e.levelEntry = levelEntry;
    e.autoReset = static_cast<u8>(autoReset);
    e.againMode = static_cast<u8>(againMode);
    e.maxEpisodeSteps = maxEpisodeSteps;
}

void moduleSetLevelEntry(void* env, int entry) { envOf(env).levelEntry = entry; }

int moduleSetSeed(void* env, const uint16_t* units, size_t count) {
#if PSC_USES_RANDOM
    if (count > static_cast<size_t>(kSeedUnits)) return 0;
    Env& e = envOf(env);
    for (size_t i = 0; i < count; ++i) e.seed[i] = units[i];
    e.seedLength = static_cast<u8>(count);
#else
    (void)env;
    (void)units;
    (void)count;
#endif
    return 1;
}

// Whether board b holds positions of `cells` only.
bool within(const Board& b, const Board& cells) { return !andNot(b, cells).any(); }

// Whether a loaded environment's boards, and its undo snapshots', hold
// positions of its level's cells only: rules and movement look at the cells
// next to a match, which the guard positions keep within a board's words.
bool boardsInLevel(const Env& e, const char* snapshots, int count) {
    Board cells = Board::zero();
    for (int x = 0; x < e.width; ++x) {
        for (int y = 0; y < e.height; ++y) cells.set(positionOf(e, x, y));
    }
    bool in = within(e.inside, cells) && within(e.rowStart, cells);
    for (int o = 0; o < kObjects; ++o) in = in && within(e.obj[o], e.inside) && within(e.restartTarget.obj[o], e.inside);
    for (int m = 0; m < kLayers * 5; ++m) in = in && within(e.mov[m], e.inside);
    for (int k = 0; k < count; ++k) {
        Snapshot s;
        __builtin_memcpy(&s, snapshots + sizeof s * static_cast<size_t>(k), sizeof s);  // loaded bytes, maybe unaligned
        for (int o = 0; o < kObjects; ++o) in = in && within(s.obj[o], e.inside);
    }
    return in;
}

// Fields a saved environment indexes tables or loops with must be in range
// (a state whose hash matches can still be made by hand).
int modulePlausible(const void* env, const void* snapshots, int count) {
    const Env& e = envOf(env);
    const bool inRange = e.width >= 0 && e.width <= kMaxWidth && e.height >= 0 && e.height <= kMaxHeight &&
           e.width * (e.height + 1) <= kWords * 64 && e.entry >= 0 && e.levelEntry >= 0 && e.autoReset <= 2 &&
           e.againMode <= kAgainOneTurn && e.maxEpisodeSteps >= 0
#if PSC_HAS_RULE_MESSAGES
           && e.queuedMessage >= 0 && e.queuedMessage < kRuleMessageCount && e.shownMessage >= -1 &&
           e.shownMessage < kRuleMessageCount
#endif
#if PSC_USES_RANDOM
           && e.seedLength <= kSeedUnits
#endif
        ;
    return inRange && boardsInLevel(e, static_cast<const char*>(snapshots), count);
}

void moduleView(const void* env, psc_host::EnvView* out) {
    const Env& e = envOf(env);
    out->entry = e.entry;
    out->screen = screenOf(e);
    out->startExisted = e.startExisted;
    out->width = e.width;
    out->height = e.height;
    out->episodeSteps = e.episodeSteps;
    out->againing = e.againing;
    out->shownMessage = shownMessageOf(e);
    out->startCutOff = e.startCutOff;
    out->startWon = e.startWon;
}

int moduleCellObjects(const void* env, int x, int y, int* ids) {
    const Env& e = envOf(env);
    const int p = positionOf(e, x, y);
    int n = 0;
    for (int o = 0; o < kObjects; ++o) {
        if (e.obj[o].test(p)) ids[n++] = o;
    }
    return n;
}

void moduleStartEpisode(void* env, psc_host::UndoRing* undo) { startEpisode(envOf(env), undoOf(undo)); }

void moduleStep(void* env, psc_host::UndoRing* undo, int action, psc_step_result* r) {
    Env& e = envOf(env);
    const StepOutcome o = stepEnvironment(e, undoOf(undo), action);
    r->reward = o.reward;
    r->terminated = o.terminated;
    r->truncated = o.truncated;
    r->won = o.won;
    r->cut_off = o.cutOff;
    r->againing = o.againing;
    r->message = o.message;
    r->episode_steps = e.episodeSteps;
}

void moduleObserve(const void* env, uint8_t* out) {
    observeEnvironment(envOf(env), kChannelObject, kChannelCount, kMaxWidth, kMaxHeight, out);
}

// The stepping loops live here, not in the host, so that the turn inlines
// into them (sokoban: 20 % more steps/s on one CPU thread).
void moduleStepMany(void* env, psc_host::UndoRing* undo, int32_t steps, const int32_t* actions, size_t stride, float* rewards,
                    uint8_t* terminated, uint8_t* truncated, uint8_t* won) {
    Env& e = envOf(env);
    UndoStack& u = undoOf(undo);
    for (int32_t k = 0; k < steps; ++k) {
        const size_t at = static_cast<size_t>(k) * stride;
        const StepOutcome o = stepEnvironment(e, u, actions[at]);
        if (rewards) rewards[at] = o.reward;
        if (terminated) terminated[at] = o.terminated;
        if (truncated) truncated[at] = o.truncated;
        if (won) won[at] = o.won;
    }
}

void moduleRollout(void* env, psc_host::UndoRing* undo, int32_t steps, uint64_t seed, uint64_t index, uint64_t firstStep,
                   int actionCount, psc_rollout_stats* stats) {
    Env& e = envOf(env);
    UndoStack& u = undoOf(undo);
    for (int32_t k = 0; k < steps; ++k) {
        const StepOutcome o = stepEnvironment(e, u, randomAction(seed, index, firstStep + static_cast<uint64_t>(k), actionCount));
        ++stats->steps;
        stats->wins += o.won;
        stats->episodes += (o.terminated || o.truncated) ? 1 : 0;
    }
}
void moduleClearUndo(psc_host::UndoRing* undo) { clearUndo(undoOf(undo)); }

// Keys are u64 (unsigned long long) to the engine, uint64_t to the host.
const u64* words(const uint64_t* key) { return reinterpret_cast<const u64*>(key); }
u64* words(uint64_t* key) { return reinterpret_cast<u64*>(key); }
void moduleEncodeKey(const void* env, uint64_t* key) { encodeKey(envOf(env), words(key)); }
int moduleDecodeKey(void* env, const uint64_t* key) { return decodeKey(envOf(env), words(key)); }
int moduleKeyEntry(const uint64_t* key) { return keyEntry(words(key)); }
uint64_t moduleHashKey(const uint64_t* key) { return hashKey(words(key)); }
void moduleFoldKey(uint64_t* key) { foldKey(words(key)); }
uint8_t moduleExpandKey(void* env, const uint64_t* parent, int input, uint64_t* child, int64_t deadline) {
    return expandKey(envOf(env), words(parent), input, words(child), static_cast<unsigned long long>(deadline));
}
int moduleWinDistance(const void* env) { return winDistance(envOf(env)); }

#if PSC_PLUGIN_DEVICE_CODE
const psc_host::DeviceCode kDeviceCode = {
    PSC_STATE_IN_SHARED, kSharedEnvStride, PSC_SEARCH_KERNELS, kExpandTooLarge,
    kEnvInBatch ? kMaxTurnNesting * sizeof(TurnScratch) : 0, PSC_UNIT_MAX_REGISTERS,
};
#endif

}  // namespace
}  // namespace psc_game

extern "C" const psc_host::GameModule psc_game_module = {
    psc_host::kGameModuleVersion,
    &psc_game::kGameInfo,
    sizeof(psc_game::Env),
    sizeof(psc_game::Snapshot),
    psc_game::kSeedUnits,
    psc_game::kKeyWords,
    psc_game::kEntryBoards,
    psc_game::kChannelObject,
#if PSC_PLUGIN_DEVICE_CODE
    &psc_game::kDeviceCode,
#else
    nullptr,
#endif
    psc_game::moduleInitEnv,
    psc_game::moduleSetLevelEntry,
    psc_game::moduleSetSeed,
    psc_game::modulePlausible,
    psc_game::moduleView,
    psc_game::moduleCellObjects,
    psc_game::kObjects,
    psc_game::kObjectNames,
    psc_game::kObjectNameRank,
    psc_game::moduleStartEpisode,
    psc_game::moduleStep,
    psc_game::moduleObserve,
    psc_game::moduleStepMany,
    psc_game::moduleRollout,
    psc_game::moduleClearUndo,
    psc_game::moduleEncodeKey,
    psc_game::moduleDecodeKey,
    psc_game::moduleKeyEntry,
    psc_game::moduleHashKey,
    psc_game::moduleFoldKey,
    psc_game::moduleExpandKey,
    psc_game::moduleWinDistance,
};
