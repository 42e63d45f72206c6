// The plugin's C ABI (psc_plugin.h): argument checks, CPU batches stepped by
// a pool of worker threads, state save/restore, keys and expansion; CUDA
// batches go to CudaBackend.cpp.  The game is psc_game_module.
#include <stdint.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "Batch.h"
#include "CudaBackend.h"
#include "ExpandDeadline.h"
#include "HostErrors.h"
#include "StateDump.h"

namespace psc_host {
namespace {

struct StateHeader {
    char magic[8];
    char sha1[40];
    int32_t undoCapacity;
    int32_t undoCount;
    uint64_t bodyHash;  // FNV-1a of what follows: a damaged state is refused, not loaded
};

// The last character counts the environment's layouts: a state saved by a plugin of another layout is refused.
constexpr char kStateMagic[8] = {'p', 's', 'c', 's', 't', 'a', 't', '3'};

uint64_t fnv1a(const char* bytes, size_t size) {
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < size; ++i) h = (h ^ static_cast<unsigned char>(bytes[i])) * 0x100000001b3ull;
    return h;
}

std::u16string utf16(const char* utf8) {
    std::u16string out;
    const unsigned char* s = reinterpret_cast<const unsigned char*>(utf8);
    while (*s) {
        unsigned cp = *s++;
        int extra = cp >= 0xF0 ? 3 : cp >= 0xE0 ? 2 : cp >= 0xC0 ? 1 : 0;
        if (extra) cp &= 0x3Fu >> extra;
        for (int i = 0; i < extra && (*s & 0xC0) == 0x80; ++i) cp = (cp << 6) | (*s++ & 0x3F);
        if (cp >= 0x10000) {
            cp -= 0x10000;
            out.push_back(static_cast<char16_t>(0xD800 + (cp >> 10)));
            out.push_back(static_cast<char16_t>(0xDC00 + (cp & 0x3FF)));
        } else {
            out.push_back(static_cast<char16_t>(cp));
        }
    }
    return out;
}

bool setSeed(void* env, const std::u16string& units) {
    return game().setSeed(env, reinterpret_cast<const uint16_t*>(units.data()), units.size()) != 0;
}

int levelCount() { return game().info->level_count; }
bool levelBuilt(int level) { return game().info->level_built[level] != 0; }
int firstBuiltLevel() {
    int level = 0;
    while (!levelBuilt(level)) ++level;
    return level;
}
int actionLimit() { return PSC_ACTION_COUNT; }

size_t observationBytes() {
    const psc_game_info& info = *game().info;
    return static_cast<size_t>(info.max_width) * static_cast<size_t>(info.max_height) * static_cast<size_t>(info.object_count);
}

int badAction(int32_t action, const std::string& where) {
    return fail(PSC_ERROR_BAD_ACTION, "action " + std::to_string(action) + where + " out of range [0, 8)");
}

int checkBatch(const psc_batch* b) { return b ? PSC_OK : fail(PSC_ERROR_NULL_POINTER, "batch is NULL"); }

int checkEnv(const psc_batch* b, int32_t env) {
    if (int s = checkBatch(b)) return s;
    if (env < 0 || env >= b->numEnvs) {
        return fail(PSC_ERROR_BAD_ENV, "environment " + std::to_string(env) + " out of range [0, " +
                                           std::to_string(b->numEnvs) + ")");
    }
    return PSC_OK;
}

// An environment's current state on either backend, copied.
int fetchEnv(const psc_batch* b, int env, EnvBuffer& out) {
    if (b->cuda) return cudaFetchEnv(b, env, out.data());
    std::memcpy(out.data(), b->env(env), game().envBytes);
    return PSC_OK;
}

// psc_state_size's, called here rather than through the exported symbol,
// which another plugin loaded with RTLD_GLOBAL would interpose.
size_t stateBytes(const psc_batch* b) {
    return sizeof(StateHeader) + game().envBytes + game().snapshotBytes * static_cast<size_t>(b->undoDepth);
}

int createCpuBatch(const psc_batch_options* options, psc_batch** batch) {
    const GameModule& g = game();
    psc_batch* b = new (std::nothrow) psc_batch;
    if (!b) return fail(PSC_ERROR_OUT_OF_MEMORY, "out of memory");
    try {
        b->numEnvs = options->num_envs;
        b->undoDepth = options->undo_depth;
        b->autoReset = options->auto_reset;
        b->maxEpisodeSteps = options->max_episode_steps;
        const size_t n = static_cast<size_t>(b->numEnvs);
        b->envWords.assign(n * g.envBytes / 8, 0);
        b->undoWords.assign(n * static_cast<size_t>(b->undoDepth) * g.snapshotBytes / 8, 0);
        b->undo.resize(n);
        b->episodeSteps.assign(n, 0);
        b->actions.assign(n, 0);
        b->observations.assign(n * observationBytes(), 0);
        b->rewards.assign(n, 0.0f);
        b->terminated.assign(n, 0);
        b->truncated.assign(n, 0);
        b->won.assign(n, 0);
        const int entry = g.info->level_entries[firstBuiltLevel()];
        char* undoBytes = reinterpret_cast<char*>(b->undoWords.data());
        for (int i = 0; i < b->numEnvs; ++i) {
            b->undo[static_cast<size_t>(i)] =
                UndoRing{b->undoDepth ? undoBytes + static_cast<size_t>(i) * static_cast<size_t>(b->undoDepth) * g.snapshotBytes : nullptr,
                         b->undoDepth, 0, 0, nullptr, 0, 0};
            g.initEnv(b->env(i), entry, b->autoReset, options->again_mode, b->maxEpisodeSteps);
            setSeed(b->env(i), utf16("0"));
            g.startEpisode(b->env(i), &b->undo[static_cast<size_t>(i)]);
        }
        int threads = options->threads > 0 ? options->threads : static_cast<int>(std::thread::hardware_concurrency());
        b->pool = new WorkerPool(std::max(1, threads));
    } catch (const std::system_error& e) {
        delete b;
        return fail(PSC_ERROR_BAD_ARGUMENT, std::string("cannot start the worker threads asked for: ") + e.what());
    } catch (const std::bad_alloc&) {
        delete b;
        return fail(PSC_ERROR_OUT_OF_MEMORY, "out of memory creating the batch");
    } catch (const std::length_error&) {
        delete b;
        return fail(PSC_ERROR_OUT_OF_MEMORY, "the batch is larger than memory");
    }
    *batch = b;
    return PSC_OK;
}

}  // namespace
}  // namespace psc_host

using namespace psc_host;

extern "C" {

PSC_API uint32_t psc_abi_version(void) { return PSC_ABI_VERSION; }

PSC_API const psc_game_info* psc_get_game_info(void) { return game().info; }

PSC_API const char* psc_last_error(void) { return lastError().c_str(); }

PSC_API int psc_batch_create(const psc_batch_options* options, psc_batch** batch) {
    if (!options || !batch) return fail(PSC_ERROR_NULL_POINTER, "options and batch must not be NULL");
    *batch = nullptr;
    if (options->struct_size != sizeof(psc_batch_options)) {
        return fail(PSC_ERROR_ABI_VERSION, "psc_batch_options.struct_size does not match this plugin (ABI version " +
                                               std::to_string(PSC_ABI_VERSION) + ")");
    }
    if (game().version != kGameModuleVersion) {
        return fail(PSC_ERROR_ABI_VERSION, "this plugin's game code and host were built by different versions of psc");
    }
    if (options->backend != PSC_BACKEND_CPU) {
        if (!game().device) {
            return fail(PSC_ERROR_BACKEND_UNAVAILABLE, "this plugin was built without the CUDA backend (psc --target cuda)");
        }
        if (options->backend != PSC_BACKEND_CUDA) return fail(PSC_ERROR_BAD_ARGUMENT, "unknown backend");
    }
    if (options->num_envs <= 0) return fail(PSC_ERROR_BAD_ARGUMENT, "num_envs must be positive");
    if (options->undo_depth < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "undo_depth must not be negative");
    if (options->max_episode_steps < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "max_episode_steps must not be negative");
    if (options->auto_reset < PSC_AUTO_RESET_OFF || options->auto_reset > PSC_AUTO_RESET_NEXT_STEP) {
        return fail(PSC_ERROR_BAD_ARGUMENT, "auto_reset must be 0, 1 or 2 (psc_auto_reset)");
    }
    if (options->again_mode != PSC_AGAIN_SETTLE && options->again_mode != PSC_AGAIN_ONE_TURN) {
        return fail(PSC_ERROR_BAD_ARGUMENT, "again_mode must be 0 or 1 (psc_again_mode)");
    }
    if (levelCount() == 0) return fail(PSC_ERROR_BAD_LEVEL, "the game has no playable level");
    // The sizes below are products of the caller's numbers: one that does
    // not fit in size_t would wrap to a small allocation.
    const size_t envs = static_cast<size_t>(options->num_envs);
    const size_t depth = static_cast<size_t>(options->undo_depth);
    if (envs > SIZE_MAX / game().envBytes || (depth && envs > SIZE_MAX / depth / game().snapshotBytes)) {
        return fail(PSC_ERROR_OUT_OF_MEMORY, "num_envs × undo_depth environments and snapshots are more bytes than memory has");
    }
    if (options->backend == PSC_BACKEND_CUDA) return cudaBatchCreate(options, batch);
    return createCpuBatch(options, batch);
}

PSC_API void psc_batch_destroy(psc_batch* batch) {
    if (!batch) return;
    if (batch->cuda) cudaBatchDestroy(batch);
    delete batch->pool;
    delete batch;
}

PSC_API int psc_batch_size(const psc_batch* batch, int32_t* num_envs) {
    if (int s = checkBatch(batch)) return s;
    if (!num_envs) return fail(PSC_ERROR_NULL_POINTER, "num_envs is NULL");
    *num_envs = batch->numEnvs;
    return PSC_OK;
}

PSC_API int psc_reset(psc_batch* batch, const int32_t* env_ids, int32_t count, const int32_t* levels, const uint64_t* seeds) {
    if (int s = checkBatch(batch)) return s;
    if (count < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "count must not be negative");
    if (!levels || !seeds) return fail(PSC_ERROR_NULL_POINTER, "levels and seeds must not be NULL");
    if (!env_ids && count != batch->numEnvs) return fail(PSC_ERROR_BAD_ARGUMENT, "without env_ids, count must be num_envs");
    for (int32_t i = 0; i < count; ++i) {
        const int32_t env = env_ids ? env_ids[i] : i;
        if (int s = checkEnv(batch, env)) return s;
        if (levels[i] < 0 || levels[i] >= levelCount()) {
            return fail(PSC_ERROR_BAD_LEVEL, "level " + std::to_string(levels[i]) + " out of range [0, " +
                                                 std::to_string(levelCount()) + ")");
        }
        if (!levelBuilt(levels[i])) {
            return fail(PSC_ERROR_BAD_LEVEL, "level " + std::to_string(levels[i]) +
                                                 " was left out of this plugin (psc --levels)");
        }
    }
    const GameModule& g = game();
    if (batch->cuda) {
        std::vector<int32_t> entries(static_cast<size_t>(count));
        std::vector<std::u16string> seedUnits(static_cast<size_t>(count));
        for (int32_t i = 0; i < count; ++i) {
            entries[static_cast<size_t>(i)] = g.info->level_entries[levels[i]];
            seedUnits[static_cast<size_t>(i)] = utf16(std::to_string(seeds[i]).c_str());
        }
        return cudaResetEntries(batch, env_ids, count, entries.data(), seedUnits);
    }
    for (int32_t i = 0; i < count; ++i) {
        const int32_t env = env_ids ? env_ids[i] : i;
        g.setLevelEntry(batch->env(env), g.info->level_entries[levels[i]]);
        setSeed(batch->env(env), utf16(std::to_string(seeds[i]).c_str()));
        g.startEpisode(batch->env(env), &batch->undo[static_cast<size_t>(env)]);
    }
    return PSC_OK;
}

PSC_API int psc_reset_entry(psc_batch* batch, int32_t env, int32_t entry, const char* seed) {
    const GameModule& g = game();
    if (int s = checkEnv(batch, env)) return s;
    if (!seed) return fail(PSC_ERROR_NULL_POINTER, "seed is NULL");
    if (entry < 0) return fail(PSC_ERROR_BAD_LEVEL, "entry must not be negative");
    if (entry < g.info->entry_count && g.entryBoards[entry] == -2) {
        return fail(PSC_ERROR_BAD_LEVEL, "entry " + std::to_string(entry) + " was left out of this plugin (psc --levels)");
    }
    if (batch->cuda) return cudaResetEntries(batch, &env, 1, &entry, {utf16(seed)});
    if (!setSeed(batch->env(env), utf16(seed))) {
        return fail(PSC_ERROR_BAD_ARGUMENT, "the seed is longer than " + std::to_string(g.seedUnits) + " UTF-16 units");
    }
    g.setLevelEntry(batch->env(env), entry);
    g.startEpisode(batch->env(env), &batch->undo[static_cast<size_t>(env)]);
    return PSC_OK;
}

namespace {
// One flag of environment env's view (psc_start_cut_off, psc_start_won).
int readViewFlag(const psc_batch* batch, int32_t env, uint8_t* flag, const char* flagName, int EnvView::*field) {
    const GameModule& g = game();
    if (int s = checkEnv(batch, env)) return s;
    if (!flag) return fail(PSC_ERROR_NULL_POINTER, std::string(flagName) + " is NULL");
    EnvBuffer e(g.envBytes);
    if (int s = fetchEnv(batch, env, e)) return s;
    EnvView v;
    g.view(e.data(), &v);
    *flag = v.*field ? 1 : 0;
    return PSC_OK;
}
}  // namespace

PSC_API int psc_start_cut_off(const psc_batch* batch, int32_t env, uint8_t* cut_off) {
    return readViewFlag(batch, env, cut_off, "cut_off", &EnvView::startCutOff);
}

PSC_API int psc_start_won(const psc_batch* batch, int32_t env, uint8_t* won) {
    return readViewFlag(batch, env, won, "won", &EnvView::startWon);
}

PSC_API int psc_step(psc_batch* batch, const int32_t* actions, psc_step_result* results) {
    if (int s = checkBatch(batch)) return s;
    if (!actions) return fail(PSC_ERROR_NULL_POINTER, "actions is NULL");
    for (int i = 0; i < batch->numEnvs; ++i) {
        if (actions[i] < 0 || actions[i] >= actionLimit()) return badAction(actions[i], " of environment " + std::to_string(i));
    }
    if (batch->cuda) return cudaStep(batch, actions, results);
    const GameModule& g = game();
    batch->pool->run(batch->numEnvs, [&](int begin, int end) {
        psc_step_result r{};
        for (int i = begin; i < end; ++i) {
            g.step(batch->env(i), &batch->undo[static_cast<size_t>(i)], actions[i], &r);
            if (results) results[i] = r;
        }
    });
    return PSC_OK;
}

PSC_API int psc_get_buffers(psc_batch* batch, psc_buffers* buffers) {
    if (int s = checkBatch(batch)) return s;
    if (!buffers) return fail(PSC_ERROR_NULL_POINTER, "buffers is NULL");
    if (batch->cuda) return cudaGetBuffers(batch, buffers);
    buffers->device = -1;
    buffers->num_envs = batch->numEnvs;
    buffers->actions = batch->actions.data();
    buffers->observations = batch->observations.data();
    buffers->rewards = batch->rewards.data();
    buffers->terminated = batch->terminated.data();
    buffers->truncated = batch->truncated.data();
    buffers->won = batch->won.data();
    buffers->episode_steps = batch->episodeSteps.data();
    return PSC_OK;
}

PSC_API int psc_step_buffers(psc_batch* batch) {
    if (int s = checkBatch(batch)) return s;
    if (batch->cuda) return cudaStepBuffers(batch);
    for (int i = 0; i < batch->numEnvs; ++i) {
        if (batch->actions[i] < 0 || batch->actions[i] >= actionLimit()) {
            return badAction(batch->actions[i], " of environment " + std::to_string(i));
        }
    }
    const GameModule& g = game();
    const size_t perEnv = observationBytes();
    batch->pool->run(batch->numEnvs, [&](int begin, int end) {
        psc_step_result r{};
        for (int i = begin; i < end; ++i) {
            g.step(batch->env(i), &batch->undo[static_cast<size_t>(i)], batch->actions[i], &r);
            batch->rewards[i] = r.reward;
            batch->terminated[i] = r.terminated;
            batch->truncated[i] = r.truncated;
            batch->won[i] = r.won;
            batch->episodeSteps[i] = r.episode_steps;
            g.observe(batch->env(i), batch->observations.data() + perEnv * static_cast<size_t>(i));
        }
    });
    return PSC_OK;
}

PSC_API int psc_step_many(psc_batch* batch, int32_t steps, const int32_t* actions, float* rewards, uint8_t* terminated,
                          uint8_t* truncated, uint8_t* won) {
    if (int s = checkBatch(batch)) return s;
    if (steps < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "steps must not be negative");
    if (!actions) return fail(PSC_ERROR_NULL_POINTER, "actions is NULL");
    if (batch->cuda) return cudaStepMany(batch, steps, actions, rewards, terminated, truncated, won);
    const size_t n = static_cast<size_t>(batch->numEnvs);
    for (size_t at = 0; at < n * static_cast<size_t>(steps); ++at) {
        if (actions[at] < 0 || actions[at] >= actionLimit()) {
            return badAction(actions[at], " of step " + std::to_string(at / n) + ", environment " + std::to_string(at % n));
        }
    }
    const GameModule& g = game();
    const size_t perEnv = observationBytes();
    batch->pool->run(batch->numEnvs, [&](int begin, int end) {
        for (int i = begin; i < end; ++i) {
            const size_t at = static_cast<size_t>(i);
            g.stepMany(batch->env(i), &batch->undo[at], steps, actions + at, n, rewards ? rewards + at : nullptr,
                       terminated ? terminated + at : nullptr, truncated ? truncated + at : nullptr, won ? won + at : nullptr);
            EnvView v;
            g.view(batch->env(i), &v);
            batch->episodeSteps[i] = v.episodeSteps;
            g.observe(batch->env(i), batch->observations.data() + perEnv * static_cast<size_t>(i));
        }
    });
    return PSC_OK;
}

PSC_API int psc_set_stream(psc_batch* batch, void* stream) {
    if (int s = checkBatch(batch)) return s;
    if (batch->cuda) return cudaSetStream(batch, stream);
    return PSC_OK;
}

PSC_API int psc_synchronize(psc_batch* batch) {
    if (int s = checkBatch(batch)) return s;
    if (batch->cuda) return cudaSynchronize(batch);
    return PSC_OK;
}

PSC_API int psc_rollout(psc_batch* batch, int32_t steps, uint64_t seed, psc_rollout_stats* stats) {
    if (int s = checkBatch(batch)) return s;
    if (steps < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "steps must not be negative");
    if (batch->cuda) return cudaRollout(batch, steps, seed, stats);
    const GameModule& g = game();
    const int actionCount = (g.info->flags & PSC_FLAG_NOACTION) ? 4 : 5;
    std::vector<psc_rollout_stats> partial(static_cast<size_t>(batch->numEnvs));
    batch->pool->run(batch->numEnvs, [&](int begin, int end) {
        for (int i = begin; i < end; ++i) {
            psc_rollout_stats& st = partial[static_cast<size_t>(i)];
            st = psc_rollout_stats{0, 0, 0};
            g.rollout(batch->env(i), &batch->undo[static_cast<size_t>(i)], steps, seed, static_cast<uint64_t>(i), batch->rolloutSteps,
                      actionCount, &st);
        }
    });
    batch->rolloutSteps += static_cast<unsigned long long>(steps);
    if (stats) {
        *stats = psc_rollout_stats{0, 0, 0};
        for (const auto& p : partial) {
            stats->steps += p.steps;
            stats->wins += p.wins;
            stats->episodes += p.episodes;
        }
    }
    return PSC_OK;
}

PSC_API int psc_observe(psc_batch* batch, uint8_t* observations, size_t size) {
    if (int s = checkBatch(batch)) return s;
    if (!observations) return fail(PSC_ERROR_NULL_POINTER, "observations is NULL");
    const size_t perEnv = observationBytes();
    if (size < perEnv * static_cast<size_t>(batch->numEnvs)) {
        return fail(PSC_ERROR_BUFFER_TOO_SMALL,
                    "observations need " + std::to_string(perEnv * static_cast<size_t>(batch->numEnvs)) + " bytes");
    }
    if (batch->cuda) return cudaObserve(batch, observations, size);
    const GameModule& g = game();
    batch->pool->run(batch->numEnvs, [&](int begin, int end) {
        for (int i = begin; i < end; ++i) g.observe(batch->env(i), observations + perEnv * static_cast<size_t>(i));
    });
    return PSC_OK;
}

PSC_API size_t psc_state_size(const psc_batch* batch) {
    return batch ? stateBytes(batch) : 0;
}

PSC_API int psc_save_state(const psc_batch* batch, int32_t env, void* buffer, size_t size) {
    const GameModule& g = game();
    if (int s = checkEnv(batch, env)) return s;
    if (!buffer) return fail(PSC_ERROR_NULL_POINTER, "buffer is NULL");
    if (size < stateBytes(batch)) return fail(PSC_ERROR_BUFFER_TOO_SMALL, "the buffer is smaller than psc_state_size()");
    char* out = static_cast<char*>(buffer);
    char* body = out + sizeof(StateHeader);
    char* undoOut = body + g.envBytes;
    int undoCount = 0;
    if (batch->cuda) {
        EnvBuffer e(g.envBytes);
        EnvBuffer undo(g.snapshotBytes * static_cast<size_t>(batch->undoDepth));
        if (int s = cudaReadState(batch, env, e.data(), undo.data(), &undoCount)) return s;
        std::memcpy(body, e.data(), g.envBytes);
        if (undoCount) std::memcpy(undoOut, undo.data(), g.snapshotBytes * static_cast<size_t>(undoCount));
    } else {
        std::memcpy(body, batch->env(env), g.envBytes);
        const UndoRing& u = batch->undo[static_cast<size_t>(env)];
        undoCount = u.count;
        for (int k = 0; k < u.count; ++k) {
            std::memcpy(undoOut + g.snapshotBytes * static_cast<size_t>(k),
                        static_cast<const char*>(u.entries) + g.snapshotBytes * static_cast<size_t>((u.head + k) % u.capacity),
                        g.snapshotBytes);
        }
    }
    StateHeader h{};
    std::memcpy(h.magic, kStateMagic, 8);
    std::memcpy(h.sha1, g.info->source_sha1, 40);
    h.undoCapacity = batch->undoDepth;
    h.undoCount = undoCount;
    h.bodyHash = fnv1a(body, g.envBytes + g.snapshotBytes * static_cast<size_t>(undoCount));
    std::memcpy(out, &h, sizeof h);
    return PSC_OK;
}

PSC_API int psc_load_state(psc_batch* batch, int32_t env, const void* buffer, size_t size) {
    const GameModule& g = game();
    if (int s = checkEnv(batch, env)) return s;
    if (!buffer) return fail(PSC_ERROR_NULL_POINTER, "buffer is NULL");
    if (size < stateBytes(batch)) return fail(PSC_ERROR_BUFFER_TOO_SMALL, "the buffer is smaller than psc_state_size()");
    StateHeader h;
    const char* in = static_cast<const char*>(buffer);
    std::memcpy(&h, in, sizeof h);
    if (std::memcmp(h.magic, kStateMagic, 8) != 0 || std::memcmp(h.sha1, g.info->source_sha1, 40) != 0) {
        return fail(PSC_ERROR_BAD_STATE, "the buffer is not a saved state of this game");
    }
    if (h.undoCapacity != batch->undoDepth || h.undoCount < 0 || h.undoCount > h.undoCapacity) {
        return fail(PSC_ERROR_BAD_STATE, "the saved state's undo depth differs from this batch's");
    }
    const char* body = in + sizeof h;
    const size_t undoBytes = g.snapshotBytes * static_cast<size_t>(h.undoCount);
    if (fnv1a(body, g.envBytes + undoBytes) != h.bodyHash) {
        return fail(PSC_ERROR_BAD_STATE, "the saved state is damaged (its checksum does not match)");
    }
    EnvBuffer e(g.envBytes);
    std::memcpy(e.data(), body, g.envBytes);
    if (!g.plausible(e.data(), body + g.envBytes, h.undoCount)) {
        return fail(PSC_ERROR_BAD_STATE, "the saved state holds values out of range, or objects outside its level");
    }
    if (batch->cuda) return cudaWriteState(batch, env, e.data(), body + g.envBytes, h.undoCount);
    std::memcpy(batch->env(env), e.data(), g.envBytes);
    UndoRing& u = batch->undo[static_cast<size_t>(env)];
    u.head = 0;
    u.count = h.undoCount;
    if (undoBytes) std::memcpy(u.entries, body + g.envBytes, undoBytes);
    return PSC_OK;
}

PSC_API int psc_dump_state(const psc_batch* batch, int32_t env, char* buffer, size_t size, size_t* needed) {
    if (int s = checkEnv(batch, env)) return s;
    EnvBuffer e(game().envBytes);
    if (int s = fetchEnv(batch, env, e)) return s;
    const std::string json = dumpState(e.data());
    if (needed) *needed = json.size() + 1;
    if (!buffer || size < json.size() + 1) return fail(PSC_ERROR_BUFFER_TOO_SMALL, "the buffer is too small for the dump");
    std::memcpy(buffer, json.c_str(), json.size() + 1);
    return PSC_OK;
}

PSC_API int psc_encode_states(const psc_batch* batch, const int32_t* env_ids, int32_t count, void* keys, uint64_t* hashes) {
    const GameModule& g = game();
    if (int s = checkBatch(batch)) return s;
    if (!env_ids || !keys) return fail(PSC_ERROR_NULL_POINTER, "env_ids and keys must not be NULL");
    if (count < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "count must not be negative");
    uint64_t* out = static_cast<uint64_t*>(keys);
    EnvBuffer e(g.envBytes);
    for (int32_t i = 0; i < count; ++i) {
        if (int s = checkEnv(batch, env_ids[i])) return s;
        if (int s = fetchEnv(batch, env_ids[i], e)) return s;
        uint64_t* key = out + static_cast<size_t>(i) * static_cast<size_t>(g.keyWords);
        g.encodeKey(e.data(), key);
        if (hashes) hashes[i] = g.hashKey(key);
    }
    return PSC_OK;
}

PSC_API int psc_canonical_keys(const psc_batch* batch, void* keys, int32_t count, uint64_t* hashes) {
    const GameModule& g = game();
    if (int s = checkBatch(batch)) return s;
    if (!keys) return fail(PSC_ERROR_NULL_POINTER, "keys must not be NULL");
    if (count < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "count must not be negative");
    uint64_t* k = static_cast<uint64_t*>(keys);
    for (int32_t i = 0; i < count; ++i) {
        uint64_t* key = k + static_cast<size_t>(i) * static_cast<size_t>(g.keyWords);
        g.foldKey(key);
        if (hashes) hashes[i] = g.hashKey(key);
    }
    return PSC_OK;
}

PSC_API int psc_decode_state(psc_batch* batch, int32_t env, const void* key) {
    const GameModule& g = game();
    if (int s = checkEnv(batch, env)) return s;
    if (!key) return fail(PSC_ERROR_NULL_POINTER, "key is NULL");
    const uint64_t* k = static_cast<const uint64_t*>(key);
    EnvBuffer e(g.envBytes);
    if (int s = fetchEnv(batch, env, e)) return s;
    EnvView v;
    g.view(e.data(), &v);
    if (g.keyEntry(k) != v.entry) {
        return fail(PSC_ERROR_BAD_STATE, "the key shows entry " + std::to_string(g.keyEntry(k)) + ", the environment entry " +
                                             std::to_string(v.entry));
    }
    if (!g.decodeKey(e.data(), k)) return fail(PSC_ERROR_BAD_STATE, "the key is no state of the environment's level");
    if (batch->cuda) return cudaWriteState(batch, env, e.data(), nullptr, 0);
    std::memcpy(batch->env(env), e.data(), g.envBytes);
    g.clearUndo(&batch->undo[static_cast<size_t>(env)]);
    return PSC_OK;
}

PSC_API int psc_expand(psc_batch* batch, int32_t template_env, const void* keys, int32_t count, const int32_t* actions,
                       int32_t action_count, void* children, uint8_t* flags, uint64_t* hashes, int32_t* estimates) {
    const GameModule& g = game();
    if (int s = checkEnv(batch, template_env)) return s;
    if (!keys || !actions || !children || !flags) return fail(PSC_ERROR_NULL_POINTER, "keys, actions, children and flags must not be NULL");
    if (count < 0 || action_count <= 0) return fail(PSC_ERROR_BAD_ARGUMENT, "count must not be negative and action_count must be positive");
    if (batch->cuda) return cudaExpand(batch, template_env, keys, count, actions, action_count, children, flags, hashes, estimates);
    for (int32_t a = 0; a < action_count; ++a) {
        if (actions[a] < 0 || actions[a] >= actionLimit()) return badAction(actions[a], "");
    }
    const void* base = batch->env(template_env);
    EnvView baseView;
    g.view(base, &baseView);
    const size_t words = static_cast<size_t>(g.keyWords);
    const uint64_t* parents = static_cast<const uint64_t*>(keys);
    for (int32_t i = 0; i < count; ++i) {
        if (g.keyEntry(parents + static_cast<size_t>(i) * words) != baseView.entry) {
            return fail(PSC_ERROR_BAD_STATE, "key " + std::to_string(i) + " is not of the template environment's entry " +
                                                 std::to_string(baseView.entry));
        }
    }
    uint64_t* out = static_cast<uint64_t*>(children);
    const int64_t pairs = static_cast<int64_t>(count) * action_count;
    if (pairs > INT32_MAX) return fail(PSC_ERROR_BAD_ARGUMENT, "count * action_count must be below 2^31");
    const int64_t deadline = batch->expandDeadline;
    batch->pool->run(static_cast<int>(pairs), [&](int begin, int end) {
        EnvBuffer e(g.envBytes);
        DeadlineWatch watch(deadline);
        for (int at = begin; at < end; ++at) {
            uint64_t* child = out + static_cast<size_t>(at) * words;
            if (watch.passed()) {
                flags[at] = PSC_EXPAND_TIMED_OUT;  // a child not started by the deadline is none (expandKey)
            } else {
                std::memcpy(e.data(), base, g.envBytes);
                flags[at] = g.expandKey(e.data(), parents + static_cast<size_t>(at / action_count) * words,
                                        actions[at % action_count], child, deadline);
            }
            const bool noChild = flags[at] == PSC_EXPAND_TIMED_OUT || flags[at] == PSC_EXPAND_INVALID;
            if (hashes) hashes[at] = noChild ? 0 : g.hashKey(child);
            if (estimates) estimates[at] = noChild ? 0 : g.winDistance(e.data());
        }
    });
    return PSC_OK;
}

PSC_API int psc_set_deadline(psc_batch* batch, double seconds) {
    if (int s = checkBatch(batch)) return s;
    if (!(seconds >= 0) || seconds > 1e9) return fail(PSC_ERROR_BAD_ARGUMENT, "seconds must be between 0 and 1e9");
    batch->expandDeadline = seconds > 0 ? steadyNanoseconds() + static_cast<int64_t>(seconds * 1e9) : 0;
    return PSC_OK;
}

PSC_API int psc_estimate_distance(const psc_batch* batch, int32_t template_env, const void* keys, int32_t count,
                                  int32_t* estimates) {
    const GameModule& g = game();
    if (int s = checkEnv(batch, template_env)) return s;
    if (!keys || !estimates) return fail(PSC_ERROR_NULL_POINTER, "keys and estimates must not be NULL");
    if (count < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "count must not be negative");
    EnvBuffer base(g.envBytes);
    if (int s = fetchEnv(batch, template_env, base)) return s;
    EnvView baseView;
    g.view(base.data(), &baseView);
    const size_t words = static_cast<size_t>(g.keyWords);
    const uint64_t* k = static_cast<const uint64_t*>(keys);
    for (int32_t i = 0; i < count; ++i) {
        if (g.keyEntry(k + static_cast<size_t>(i) * words) != baseView.entry) {
            return fail(PSC_ERROR_BAD_STATE, "key " + std::to_string(i) + " is not of the template environment's entry");
        }
    }
    std::vector<uint8_t> unfit(static_cast<size_t>(count));
    const auto estimate = [&](int begin, int end) {
        EnvBuffer e(g.envBytes);
        for (int i = begin; i < end; ++i) {
            std::memcpy(e.data(), base.data(), g.envBytes);
            unfit[static_cast<size_t>(i)] = !g.decodeKey(e.data(), k + static_cast<size_t>(i) * words);
            estimates[i] = unfit[static_cast<size_t>(i)] ? 0 : g.winDistance(e.data());
        }
    };
    if (batch->pool) batch->pool->run(count, estimate);
    else estimate(0, count);  // a CUDA batch: no worker threads
    const auto bad = std::find(unfit.begin(), unfit.end(), 1);
    if (bad != unfit.end()) {
        return fail(PSC_ERROR_BAD_STATE,
                    "key " + std::to_string(bad - unfit.begin()) + " is no state of the template environment's level");
    }
    return PSC_OK;
}

PSC_API int psc_device_alloc(psc_batch* batch, size_t bytes, void** pointer) {
    if (int s = checkBatch(batch)) return s;
    if (!pointer) return fail(PSC_ERROR_NULL_POINTER, "pointer is NULL");
    *pointer = nullptr;
    if (batch->cuda) return cudaAlloc(batch, bytes, pointer);
    *pointer = std::malloc(std::max<size_t>(bytes, 1));
    return *pointer ? PSC_OK : fail(PSC_ERROR_OUT_OF_MEMORY, "cannot allocate " + std::to_string(bytes) + " bytes");
}

PSC_API int psc_device_free(psc_batch* batch, void* pointer) {
    if (int s = checkBatch(batch)) return s;
    if (!pointer) return PSC_OK;
    if (batch->cuda) return cudaFree(batch, pointer);
    std::free(pointer);
    return PSC_OK;
}

PSC_API int psc_copy(psc_batch* batch, void* destination, const void* source, size_t bytes) {
    if (int s = checkBatch(batch)) return s;
    if ((!destination || !source) && bytes) return fail(PSC_ERROR_NULL_POINTER, "destination and source must not be NULL");
    if (!bytes) return PSC_OK;
    if (batch->cuda) return cudaCopy(batch, destination, source, bytes);
    std::memmove(destination, source, bytes);
    return PSC_OK;
}

}  // extern "C"
