// ---- psc template: the plugin's C ABI on the CPU -------------------------
// Batches of environments stepped by a pool of worker threads, observations,
// state save/restore and the canonical state dump (runtime/psc_plugin.h).

namespace psc_game {
namespace {

// Runs fn(begin, end) over [0, n) split across persistent worker threads.
class WorkerPool {
public:
    // Throws std::system_error when the system gives fewer threads (the ones started are stopped first).
    explicit WorkerPool(int threads) {
        try {
            for (int i = 1; i < threads; ++i) workers_.emplace_back([this, i] { loop(i); });
        } catch (...) {
            stop();
            throw;
        }
        threads_ = threads;
    }
    ~WorkerPool() { stop(); }
    void run(int n, const std::function<void(int, int)>& fn) {
        if (threads_ == 1 || n < 2 * threads_) {
            fn(0, n);
            return;
        }
        {
            std::lock_guard<std::mutex> lock(mutex_);
            job_ = &fn;
            n_ = n;
            pending_ = threads_ - 1;
            ++generation_;
        }
        wake_.notify_all();
        fn(0, chunkEnd(0));
        std::unique_lock<std::mutex> lock(mutex_);
        done_.wait(lock, [this] { return pending_ == 0; });
        job_ = nullptr;
    }

private:
    void stop() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stopping_ = true;
            ++generation_;
        }
        wake_.notify_all();
        for (auto& w : workers_) w.join();
    }
    int chunkEnd(int i) const { return static_cast<int>(static_cast<long long>(n_) * (i + 1) / threads_); }
    void loop(int index) {
        unsigned long long seen = 0;
        for (;;) {
            const std::function<void(int, int)>* job;
            {
                std::unique_lock<std::mutex> lock(mutex_);
                wake_.wait(lock, [&] { return generation_ != seen; });
                seen = generation_;
                if (stopping_) return;
                job = job_;
            }
            (*job)(chunkEnd(index - 1), chunkEnd(index));
            {
                std::lock_guard<std::mutex> lock(mutex_);
                if (--pending_ == 0) done_.notify_one();
            }
        }
    }

    std::vector<std::thread> workers_;
    int threads_ = 1;
    std::mutex mutex_;
    std::condition_variable wake_;
    std::condition_variable done_;
    const std::function<void(int, int)>* job_ = nullptr;
    int n_ = 0;
    int pending_ = 0;
    unsigned long long generation_ = 0;
    bool stopping_ = false;
};

struct StateHeader {
    char magic[8];
    char sha1[40];
    int32_t undoCapacity;
    int32_t undoCount;
    uint64_t bodyHash;  // FNV-1a of what follows: a damaged state is refused, not loaded
};

constexpr char kStateMagic[8] = {'p', 's', 'c', 's', 't', 'a', 't', '2'};

uint64_t fnv1a(const char* bytes, size_t size) {
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < size; ++i) h = (h ^ static_cast<unsigned char>(bytes[i])) * 0x100000001b3ull;
    return h;
}

// Fields a saved environment indexes tables or loops with must be in range
// (a state whose hash matches can still be made by hand).
bool plausible(const Env& e) {
    return e.width >= 0 && e.width <= kMaxWidth && e.height >= 0 && e.height <= kMaxHeight &&
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
}

}  // namespace
}  // namespace psc_game

struct psc_batch {
    void* cuda = nullptr;  // the CUDA backend's batch, when this batch runs there
    int numEnvs = 0;
    int undoDepth = 0;
    int autoReset = PSC_AUTO_RESET_OFF;
    int maxEpisodeSteps = 0;
    std::vector<psc_game::Env> envs;
    std::vector<psc_game::Snapshot> undoEntries;
    std::vector<psc_game::UndoStack> undo;
    // psc_buffers
    std::vector<int32_t> actions;
    std::vector<uint8_t> observations;
    std::vector<float> rewards;
    std::vector<uint8_t> terminated;
    std::vector<uint8_t> truncated;
    std::vector<uint8_t> won;
    std::vector<int32_t> episodeSteps;
    unsigned long long rolloutSteps = 0;  // steps run by rollouts so far (the random actions' counter)
    psc_game::WorkerPool* pool = nullptr;
};

namespace psc_game {
namespace {

bool setSeed(Env& e, const std::u16string& units) {
#if PSC_USES_RANDOM
    if (units.size() > static_cast<size_t>(kSeedUnits)) return false;
    for (size_t i = 0; i < units.size(); ++i) e.seed[i] = units[i];
    e.seedLength = static_cast<u8>(units.size());
#else
    (void)e;
    (void)units;
#endif
    return true;
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

void observeEnv(const Env& e, uint8_t* out) {
    observeEnvironment(e, kChannelObject, kChannelCount, kMaxWidth, kMaxHeight, out);
}

psc_step_result toResult(const StepOutcome& o, const Env& e) {
    psc_step_result r{};
    r.reward = o.reward;
    r.terminated = o.terminated;
    r.truncated = o.truncated;
    r.won = o.won;
    r.cut_off = o.cutOff;
    r.againing = o.againing;
    r.message = o.message;
    r.episode_steps = e.episodeSteps;
    return r;
}

size_t observationBytes() { return static_cast<size_t>(kMaxWidth) * kMaxHeight * kChannelCount; }

void appendJsonString(std::string& out, const char* s) {
    static const char* hex = "0123456789abcdef";
    out += '"';
    for (const unsigned char* p = reinterpret_cast<const unsigned char*>(s); *p; ++p) {
        switch (*p) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\r': out += "\\r"; break;
            case '\t': out += "\\t"; break;
            case '\b': out += "\\b"; break;
            case '\f': out += "\\f"; break;
            default:
                if (*p < 0x20) {
                    out += "\\u00";
                    out += hex[*p >> 4];
                    out += hex[*p & 15];
                } else {
                    out += static_cast<char>(*p);
                }
        }
    }
    out += '"';
}

std::string dumpState(const Env& e) {
    std::string out = "{\"level\":" + std::to_string(e.entry) + ",\"screen\":";
    const Screen screen = screenOf(e);
    out += screen == kScreenTitle ? "\"title\"" : screen == kScreenMessage ? "\"message\"" : "\"level\"";
    out += ",\"message\":";
    if (screen == kScreenTitle) {
        out += "\"#title\"";
    } else if (screen == kScreenMessage) {
        appendJsonString(out, e.entry >= 0 && e.entry < kEntries ? kEntryMessages[e.entry] : "");
    } else {
        out += "null";
    }
    out += ",\"won\":";
    out += (screen == kScreenTitle && e.startExisted) ? "true" : "false";
    out += ",\"width\":" + std::to_string(e.width) + ",\"height\":" + std::to_string(e.height);
    std::vector<std::string> palette;
    std::string rows = "[";
    int ids[kObjects];
    for (int y = 0; y < e.height; ++y) {
        rows += y ? ",[" : "[";
        for (int x = 0; x < e.width; ++x) {
            const int p = positionOf(e, x, y);
            int n = 0;
            for (int o = 0; o < kObjects; ++o) {
                if (e.obj[o].test(p)) ids[n++] = o;
            }
            std::sort(ids, ids + n, [](int a, int b) { return kObjectNameRank[a] < kObjectNameRank[b]; });
            std::string cell;
            for (int k = 0; k < n; ++k) {
                if (k) cell += ' ';
                cell += kObjectNames[ids[k]];
            }
            size_t index = std::find(palette.begin(), palette.end(), cell) - palette.begin();
            if (index == palette.size()) palette.push_back(cell);
            rows += (x ? "," : "") + std::to_string(index);
        }
        rows += "]";
    }
    rows += "]";
    out += ",\"palette\":[";
    for (size_t i = 0; i < palette.size(); ++i) {
        if (i) out += ",";
        appendJsonString(out, palette[i].c_str());
    }
    out += "],\"rows\":" + rows + "}";
    return out;
}

int checkBatch(const psc_batch* b) {
    return b ? PSC_OK : fail(PSC_ERROR_NULL_POINTER, "batch is NULL");
}

int checkEnv(const psc_batch* b, int32_t env) {
    if (int s = checkBatch(b)) return s;
    if (env < 0 || env >= b->numEnvs) {
        return fail(PSC_ERROR_BAD_ENV, "environment " + std::to_string(env) + " out of range [0, " +
                                           std::to_string(b->numEnvs) + ")");
    }
    return PSC_OK;
}

}  // namespace
}  // namespace psc_game

extern "C" {

uint32_t psc_abi_version(void) { return PSC_ABI_VERSION; }

const psc_game_info* psc_get_game_info(void) { return &psc_game::kGameInfo; }

const char* psc_last_error(void) { return psc_game::lastError.c_str(); }

int psc_batch_create(const psc_batch_options* options, psc_batch** batch) {
    using namespace psc_game;
    if (!options || !batch) return fail(PSC_ERROR_NULL_POINTER, "options and batch must not be NULL");
    *batch = nullptr;
    if (options->struct_size != sizeof(psc_batch_options)) {
        return fail(PSC_ERROR_ABI_VERSION, "psc_batch_options.struct_size does not match this plugin (ABI version " +
                                               std::to_string(PSC_ABI_VERSION) + ")");
    }
    if (options->backend != PSC_BACKEND_CPU) {
        return psc_cuda_batch_create(options, batch);
    }
    if (options->num_envs <= 0) return fail(PSC_ERROR_BAD_ARGUMENT, "num_envs must be positive");
    if (options->undo_depth < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "undo_depth must not be negative");
    if (options->max_episode_steps < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "max_episode_steps must not be negative");
    if (options->again_mode != PSC_AGAIN_SETTLE && options->again_mode != PSC_AGAIN_ONE_TURN) {
        return fail(PSC_ERROR_BAD_ARGUMENT, "again_mode must be 0 or 1 (psc_again_mode)");
    }
    if (kLevelCount == 0) return fail(PSC_ERROR_BAD_LEVEL, "the game has no playable level");
    psc_batch* b = new (std::nothrow) psc_batch;
    if (!b) return fail(PSC_ERROR_OUT_OF_MEMORY, "out of memory");
    try {
        b->numEnvs = options->num_envs;
        b->undoDepth = options->undo_depth;
        if (options->auto_reset < PSC_AUTO_RESET_OFF || options->auto_reset > PSC_AUTO_RESET_NEXT_STEP) {
            delete b;
            return fail(PSC_ERROR_BAD_ARGUMENT, "auto_reset must be 0, 1 or 2 (psc_auto_reset)");
        }
        b->autoReset = options->auto_reset;
        b->maxEpisodeSteps = options->max_episode_steps;
        b->envs.resize(static_cast<size_t>(b->numEnvs));
        b->undoEntries.resize(static_cast<size_t>(b->numEnvs) * static_cast<size_t>(b->undoDepth));
        b->undo.resize(static_cast<size_t>(b->numEnvs));
        int firstBuilt = 0;
        while (!kLevelBuilt[firstBuilt]) ++firstBuilt;
        b->episodeSteps.assign(static_cast<size_t>(b->numEnvs), 0);
        b->actions.assign(static_cast<size_t>(b->numEnvs), 0);
        b->observations.assign(static_cast<size_t>(b->numEnvs) * observationBytes(), 0);
        b->rewards.assign(static_cast<size_t>(b->numEnvs), 0.0f);
        b->terminated.assign(static_cast<size_t>(b->numEnvs), 0);
        b->truncated.assign(static_cast<size_t>(b->numEnvs), 0);
        b->won.assign(static_cast<size_t>(b->numEnvs), 0);
        for (int i = 0; i < b->numEnvs; ++i) {
            b->undo[i] = UndoStack{b->undoDepth ? &b->undoEntries[static_cast<size_t>(i) * b->undoDepth] : nullptr,
                                   b->undoDepth, 0, 0};
            Env& e = b->envs[i];
            std::memset(&e, 0, sizeof(Env));
            setSeed(e, utf16("0"));
            e.levelEntry = kLevelEntries[firstBuilt];
            e.autoReset = static_cast<u8>(b->autoReset);
            e.againMode = static_cast<u8>(options->again_mode);
            e.maxEpisodeSteps = b->maxEpisodeSteps;
            startEpisode(e, b->undo[i]);
        }
        int threads = options->threads > 0 ? options->threads : static_cast<int>(std::thread::hardware_concurrency());
        b->pool = new WorkerPool(std::max(1, threads));
    } catch (const std::system_error& e) {
        delete b;
        return fail(PSC_ERROR_BAD_ARGUMENT, std::string("cannot start the worker threads asked for: ") + e.what());
    } catch (const std::bad_alloc&) {
        delete b;
        return fail(PSC_ERROR_OUT_OF_MEMORY, "out of memory creating the batch");
    }
    *batch = b;
    return PSC_OK;
}

void psc_batch_destroy(psc_batch* batch) {
    if (!batch) return;
    if (psc_cuda_batch_destroy(batch)) return;
    delete batch->pool;
    delete batch;
}

int psc_batch_size(const psc_batch* batch, int32_t* num_envs) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (!num_envs) return fail(PSC_ERROR_NULL_POINTER, "num_envs is NULL");
    *num_envs = batch->numEnvs;
    return PSC_OK;
}

int psc_reset(psc_batch* batch, const int32_t* env_ids, int32_t count, const int32_t* levels, const uint64_t* seeds) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (count < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "count must not be negative");
    if (psc_cuda_owns(batch)) return psc_cuda_reset(batch, env_ids, count, levels, seeds);
    if (!levels || !seeds) return fail(PSC_ERROR_NULL_POINTER, "levels and seeds must not be NULL");
    if (!env_ids && count != batch->numEnvs) return fail(PSC_ERROR_BAD_ARGUMENT, "without env_ids, count must be num_envs");
    for (int32_t i = 0; i < count; ++i) {
        const int32_t env = env_ids ? env_ids[i] : i;
        if (int s = checkEnv(batch, env)) return s;
        if (levels[i] < 0 || levels[i] >= kLevelCount) {
            return fail(PSC_ERROR_BAD_LEVEL, "level " + std::to_string(levels[i]) + " out of range [0, " +
                                                 std::to_string(kLevelCount) + ")");
        }
        if (!kLevelBuilt[levels[i]]) {
            return fail(PSC_ERROR_BAD_LEVEL, "level " + std::to_string(levels[i]) +
                                                 " was left out of this plugin (psc --levels)");
        }
    }
    for (int32_t i = 0; i < count; ++i) {
        const int32_t env = env_ids ? env_ids[i] : i;
        batch->envs[env].levelEntry = kLevelEntries[levels[i]];
        setSeed(batch->envs[env], utf16(std::to_string(seeds[i]).c_str()));
        startEpisode(batch->envs[env], batch->undo[env]);
    }
    return PSC_OK;
}

int psc_reset_entry(psc_batch* batch, int32_t env, int32_t entry, const char* seed) {
    using namespace psc_game;
    if (int s = checkEnv(batch, env)) return s;
    if (!seed) return fail(PSC_ERROR_NULL_POINTER, "seed is NULL");
    if (entry < 0) return fail(PSC_ERROR_BAD_LEVEL, "entry must not be negative");
    if (entry < kEntries && kEntryBoards[entry] == -2) {
        return fail(PSC_ERROR_BAD_LEVEL, "entry " + std::to_string(entry) + " was left out of this plugin (psc --levels)");
    }
    if (psc_cuda_owns(batch)) return psc_cuda_reset_entries(batch, &env, 1, &entry, {utf16(seed)});
    if (!setSeed(batch->envs[env], utf16(seed))) {
        return fail(PSC_ERROR_BAD_ARGUMENT, "the seed is longer than " + std::to_string(kSeedUnits) + " UTF-16 units");
    }
    batch->envs[env].levelEntry = entry;
    startEpisode(batch->envs[env], batch->undo[env]);
    return PSC_OK;
}

int psc_step(psc_batch* batch, const int32_t* actions, psc_step_result* results) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (psc_cuda_owns(batch)) return psc_cuda_step(batch, actions, results);
    if (!actions) return fail(PSC_ERROR_NULL_POINTER, "actions is NULL");
    for (int i = 0; i < batch->numEnvs; ++i) {
        if (actions[i] < 0 || actions[i] >= kInputCount) {
            return fail(PSC_ERROR_BAD_ACTION, "action " + std::to_string(actions[i]) + " of environment " +
                                                  std::to_string(i) + " out of range [0, 8)");
        }
    }
    batch->pool->run(batch->numEnvs, [&](int begin, int end) {
        for (int i = begin; i < end; ++i) {
            const StepOutcome o = stepEnvironment(batch->envs[i], batch->undo[i], actions[i]);
            if (results) results[i] = toResult(o, batch->envs[i]);
        }
    });
    return PSC_OK;
}

int psc_get_buffers(psc_batch* batch, psc_buffers* buffers) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (psc_cuda_owns(batch)) return psc_cuda_get_buffers(batch, buffers);
    if (!buffers) return fail(PSC_ERROR_NULL_POINTER, "buffers is NULL");
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

int psc_step_buffers(psc_batch* batch) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (psc_cuda_owns(batch)) return psc_cuda_step_buffers(batch);
    for (int i = 0; i < batch->numEnvs; ++i) {
        if (batch->actions[i] < 0 || batch->actions[i] >= kInputCount) {
            return fail(PSC_ERROR_BAD_ACTION, "action " + std::to_string(batch->actions[i]) + " of environment " +
                                                  std::to_string(i) + " out of range [0, 8)");
        }
    }
    batch->pool->run(batch->numEnvs, [&](int begin, int end) {
        for (int i = begin; i < end; ++i) {
            const StepOutcome o = stepEnvironment(batch->envs[i], batch->undo[i], batch->actions[i]);
            batch->rewards[i] = o.reward;
            batch->terminated[i] = o.terminated;
            batch->truncated[i] = o.truncated;
            batch->won[i] = o.won;
            batch->episodeSteps[i] = batch->envs[i].episodeSteps;
            observeEnv(batch->envs[i], batch->observations.data() + observationBytes() * i);
        }
    });
    return PSC_OK;
}

int psc_step_many(psc_batch* batch, int32_t steps, const int32_t* actions, float* rewards, uint8_t* terminated,
                  uint8_t* truncated, uint8_t* won) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (steps < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "steps must not be negative");
    if (!actions) return fail(PSC_ERROR_NULL_POINTER, "actions is NULL");
    if (psc_cuda_owns(batch)) return psc_cuda_step_many(batch, steps, actions, rewards, terminated, truncated, won);
    const size_t n = static_cast<size_t>(batch->numEnvs);
    for (size_t at = 0; at < n * static_cast<size_t>(steps); ++at) {
        if (actions[at] < 0 || actions[at] >= kInputCount) {
            return fail(PSC_ERROR_BAD_ACTION, "action " + std::to_string(actions[at]) + " of step " + std::to_string(at / n) +
                                                  ", environment " + std::to_string(at % n) + " out of range [0, 8)");
        }
    }
    batch->pool->run(batch->numEnvs, [&](int begin, int end) {
        for (int i = begin; i < end; ++i) {
            for (int32_t k = 0; k < steps; ++k) {
                const size_t at = static_cast<size_t>(k) * n + static_cast<size_t>(i);
                const StepOutcome o = stepEnvironment(batch->envs[i], batch->undo[i], actions[at]);
                if (rewards) rewards[at] = o.reward;
                if (terminated) terminated[at] = o.terminated;
                if (truncated) truncated[at] = o.truncated;
                if (won) won[at] = o.won;
            }
            batch->episodeSteps[i] = batch->envs[i].episodeSteps;
            observeEnv(batch->envs[i], batch->observations.data() + observationBytes() * i);
        }
    });
    return PSC_OK;
}

int psc_set_stream(psc_batch* batch, void* stream) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (psc_cuda_owns(batch)) return psc_cuda_set_stream(batch, stream);
    return PSC_OK;
}

int psc_synchronize(psc_batch* batch) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (psc_cuda_owns(batch)) return psc_cuda_synchronize(batch);
    return PSC_OK;
}

int psc_rollout(psc_batch* batch, int32_t steps, uint64_t seed, psc_rollout_stats* stats) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (steps < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "steps must not be negative");
    if (psc_cuda_owns(batch)) return psc_cuda_rollout(batch, steps, seed, stats);
    const int actionCount = (kGameInfo.flags & PSC_FLAG_NOACTION) ? 4 : 5;
    std::vector<psc_rollout_stats> partial(static_cast<size_t>(batch->numEnvs));
    batch->pool->run(batch->numEnvs, [&](int begin, int end) {
        for (int i = begin; i < end; ++i) {
            psc_rollout_stats& st = partial[static_cast<size_t>(i)];
            st = psc_rollout_stats{0, 0, 0};
            for (int32_t k = 0; k < steps; ++k) {
                const int action = randomAction(seed, static_cast<uint64_t>(i), batch->rolloutSteps + static_cast<uint64_t>(k), actionCount);
                const StepOutcome o = stepEnvironment(batch->envs[i], batch->undo[i], action);
                ++st.steps;
                st.wins += o.won;
                st.episodes += (o.terminated || o.truncated) ? 1 : 0;
            }
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

int psc_observe(psc_batch* batch, uint8_t* observations, size_t size) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (psc_cuda_owns(batch)) return psc_cuda_observe(batch, observations, size);
    if (!observations) return fail(PSC_ERROR_NULL_POINTER, "observations is NULL");
    const size_t perEnv = observationBytes();
    if (size < perEnv * batch->numEnvs) {
        return fail(PSC_ERROR_BUFFER_TOO_SMALL, "observations need " + std::to_string(perEnv * batch->numEnvs) + " bytes");
    }
    batch->pool->run(batch->numEnvs, [&](int begin, int end) {
        for (int i = begin; i < end; ++i) observeEnv(batch->envs[i], observations + perEnv * i);
    });
    return PSC_OK;
}

size_t psc_state_size(const psc_batch* batch) {
    using namespace psc_game;
    if (!batch) return 0;
    return sizeof(StateHeader) + sizeof(Env) + sizeof(Snapshot) * static_cast<size_t>(batch->undoDepth);
}

int psc_save_state(const psc_batch* batch, int32_t env, void* buffer, size_t size) {
    using namespace psc_game;
    if (int s = checkEnv(batch, env)) return s;
    if (!buffer) return fail(PSC_ERROR_NULL_POINTER, "buffer is NULL");
    if (size < psc_state_size(batch)) return fail(PSC_ERROR_BUFFER_TOO_SMALL, "the buffer is smaller than psc_state_size()");
    Env e;
    std::vector<Snapshot> undo;  // oldest first
    if (psc_cuda_owns(batch)) {
        if (int s = psc_cuda_read_state(batch, env, &e, undo)) return s;
    } else {
        e = batch->envs[env];
        const UndoStack& u = batch->undo[env];
        for (int k = 0; k < u.count; ++k) undo.push_back(u.entries[(u.head + k) % u.capacity]);
    }
    StateHeader h{};
    std::memcpy(h.magic, kStateMagic, 8);
    std::memcpy(h.sha1, kGameInfo.source_sha1, 40);
    h.undoCapacity = batch->undoDepth;
    h.undoCount = static_cast<int32_t>(undo.size());
    char* out = static_cast<char*>(buffer);
    std::memcpy(out + sizeof h, &e, sizeof(Env));
    if (!undo.empty()) std::memcpy(out + sizeof h + sizeof(Env), undo.data(), sizeof(Snapshot) * undo.size());
    h.bodyHash = fnv1a(out + sizeof h, sizeof(Env) + sizeof(Snapshot) * undo.size());
    std::memcpy(out, &h, sizeof h);
    return PSC_OK;
}

int psc_load_state(psc_batch* batch, int32_t env, const void* buffer, size_t size) {
    using namespace psc_game;
    if (int s = checkEnv(batch, env)) return s;
    if (!buffer) return fail(PSC_ERROR_NULL_POINTER, "buffer is NULL");
    if (size < psc_state_size(batch)) return fail(PSC_ERROR_BUFFER_TOO_SMALL, "the buffer is smaller than psc_state_size()");
    StateHeader h;
    const char* in = static_cast<const char*>(buffer);
    std::memcpy(&h, in, sizeof h);
    if (std::memcmp(h.magic, kStateMagic, 8) != 0 || std::memcmp(h.sha1, kGameInfo.source_sha1, 40) != 0) {
        return fail(PSC_ERROR_BAD_STATE, "the buffer is not a saved state of this game");
    }
    if (h.undoCapacity != batch->undoDepth || h.undoCount < 0 || h.undoCount > h.undoCapacity) {
        return fail(PSC_ERROR_BAD_STATE, "the saved state's undo depth differs from this batch's");
    }
    if (fnv1a(in + sizeof h, sizeof(Env) + sizeof(Snapshot) * static_cast<size_t>(h.undoCount)) != h.bodyHash) {
        return fail(PSC_ERROR_BAD_STATE, "the saved state is damaged (its checksum does not match)");
    }
    Env e;
    std::memcpy(&e, in + sizeof h, sizeof(Env));
    if (!plausible(e)) return fail(PSC_ERROR_BAD_STATE, "the saved state holds values out of range");
    std::vector<Snapshot> undo(static_cast<size_t>(h.undoCount));
    if (!undo.empty()) std::memcpy(undo.data(), in + sizeof h + sizeof(Env), sizeof(Snapshot) * undo.size());
    if (psc_cuda_owns(batch)) return psc_cuda_write_state(batch, env, e, undo);
    batch->envs[env] = e;
    UndoStack& u = batch->undo[env];
    u.head = 0;
    u.count = h.undoCount;
    for (int k = 0; k < u.count; ++k) u.entries[k] = undo[static_cast<size_t>(k)];
    return PSC_OK;
}

int psc_dump_state(const psc_batch* batch, int32_t env, char* buffer, size_t size, size_t* needed) {
    using namespace psc_game;
    if (int s = checkEnv(batch, env)) return s;
    Env fetched;
    if (psc_cuda_owns(batch)) {
        if (int s = psc_cuda_fetch_env(batch, env, &fetched)) return s;
    }
    const std::string json = dumpState(psc_cuda_owns(batch) ? fetched : batch->envs[env]);
    if (needed) *needed = json.size() + 1;
    if (!buffer || size < json.size() + 1) return fail(PSC_ERROR_BUFFER_TOO_SMALL, "the buffer is too small for the dump");
    std::memcpy(buffer, json.c_str(), json.size() + 1);
    return PSC_OK;
}

int psc_encode_states(const psc_batch* batch, const int32_t* env_ids, int32_t count, void* keys, uint64_t* hashes) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (!env_ids || !keys) return fail(PSC_ERROR_NULL_POINTER, "env_ids and keys must not be NULL");
    if (count < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "count must not be negative");
    u64* out = static_cast<u64*>(keys);
    for (int32_t i = 0; i < count; ++i) {
        if (int s = checkEnv(batch, env_ids[i])) return s;
        Env fetched;
        if (psc_cuda_owns(batch)) {
            if (int s = psc_cuda_fetch_env(batch, env_ids[i], &fetched)) return s;
        }
        const Env& e = psc_cuda_owns(batch) ? fetched : batch->envs[env_ids[i]];
        u64* key = out + static_cast<size_t>(i) * kKeyWords;
        encodeKey(e, key);
        if (hashes) hashes[i] = hashKey(key);
    }
    return PSC_OK;
}

int psc_decode_state(psc_batch* batch, int32_t env, const void* key) {
    using namespace psc_game;
    if (int s = checkEnv(batch, env)) return s;
    if (!key) return fail(PSC_ERROR_NULL_POINTER, "key is NULL");
    const u64* k = static_cast<const u64*>(key);
    Env e;
    if (psc_cuda_owns(batch)) {
        if (int s = psc_cuda_fetch_env(batch, env, &e)) return s;
    } else {
        e = batch->envs[env];
    }
    if (keyEntry(k) != e.entry) {
        return fail(PSC_ERROR_BAD_STATE, "the key shows entry " + std::to_string(keyEntry(k)) + ", the environment entry " +
                                             std::to_string(e.entry));
    }
    decodeKey(e, k);
    if (psc_cuda_owns(batch)) return psc_cuda_write_state(batch, env, e, {});
    batch->envs[env] = e;
    clearUndo(batch->undo[env]);
    return PSC_OK;
}

int psc_expand(psc_batch* batch, int32_t template_env, const void* keys, int32_t count, const int32_t* actions,
               int32_t action_count, void* children, uint8_t* flags, uint64_t* hashes, int32_t* estimates) {
    using namespace psc_game;
    if (int s = checkEnv(batch, template_env)) return s;
    if (!keys || !actions || !children || !flags) return fail(PSC_ERROR_NULL_POINTER, "keys, actions, children and flags must not be NULL");
    if (count < 0 || action_count <= 0) return fail(PSC_ERROR_BAD_ARGUMENT, "count must not be negative and action_count must be positive");
    if (psc_cuda_owns(batch)) {
        return psc_cuda_expand(batch, template_env, keys, count, actions, action_count, children, flags, hashes, estimates);
    }
    for (int32_t a = 0; a < action_count; ++a) {
        if (actions[a] < 0 || actions[a] >= kInputCount) {
            return fail(PSC_ERROR_BAD_ACTION, "action " + std::to_string(actions[a]) + " out of range [0, 8)");
        }
    }
    const Env& base = batch->envs[template_env];
    const u64* parents = static_cast<const u64*>(keys);
    for (int32_t i = 0; i < count; ++i) {
        if (keyEntry(parents + static_cast<size_t>(i) * kKeyWords) != base.entry) {
            return fail(PSC_ERROR_BAD_STATE, "key " + std::to_string(i) + " is not of the template environment's entry " +
                                                 std::to_string(base.entry));
        }
    }
    u64* out = static_cast<u64*>(children);
    const int64_t pairs = static_cast<int64_t>(count) * action_count;
    if (pairs > INT32_MAX) return fail(PSC_ERROR_BAD_ARGUMENT, "count * action_count must be below 2^31");
    batch->pool->run(static_cast<int>(pairs), [&](int begin, int end) {
        std::unique_ptr<Env> e(new Env);
        for (int at = begin; at < end; ++at) {
            *e = base;
            u64* child = out + static_cast<size_t>(at) * kKeyWords;
            flags[at] = expandKey(*e, parents + static_cast<size_t>(at / action_count) * kKeyWords, actions[at % action_count], child);
            if (hashes) hashes[at] = hashKey(child);
            if (estimates) estimates[at] = winDistance(*e);
        }
    });
    return PSC_OK;
}

int psc_estimate_distance(const psc_batch* batch, int32_t template_env, const void* keys, int32_t count,
                          int32_t* estimates) {
    using namespace psc_game;
    if (int s = checkEnv(batch, template_env)) return s;
    if (!keys || !estimates) return fail(PSC_ERROR_NULL_POINTER, "keys and estimates must not be NULL");
    if (count < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "count must not be negative");
    std::unique_ptr<Env> base(new Env);
    if (psc_cuda_owns(batch)) {
        if (int s = psc_cuda_fetch_env(batch, template_env, base.get())) return s;
    } else {
        *base = batch->envs[template_env];
    }
    const u64* k = static_cast<const u64*>(keys);
    for (int32_t i = 0; i < count; ++i) {
        if (keyEntry(k + static_cast<size_t>(i) * kKeyWords) != base->entry) {
            return fail(PSC_ERROR_BAD_STATE, "key " + std::to_string(i) + " is not of the template environment's entry");
        }
    }
    const auto estimate = [&](int begin, int end) {
        std::unique_ptr<Env> e(new Env);
        for (int i = begin; i < end; ++i) {
            *e = *base;
            decodeKey(*e, k + static_cast<size_t>(i) * kKeyWords);
            estimates[i] = winDistance(*e);
        }
    };
    if (batch->pool) batch->pool->run(count, estimate);
    else estimate(0, count);  // a CUDA batch: no worker threads
    return PSC_OK;
}

int psc_device_alloc(psc_batch* batch, size_t bytes, void** pointer) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (!pointer) return fail(PSC_ERROR_NULL_POINTER, "pointer is NULL");
    *pointer = nullptr;
    if (psc_cuda_owns(batch)) return psc_cuda_alloc(batch, bytes, pointer);
    *pointer = std::malloc(std::max<size_t>(bytes, 1));
    return *pointer ? PSC_OK : fail(PSC_ERROR_OUT_OF_MEMORY, "cannot allocate " + std::to_string(bytes) + " bytes");
}

int psc_device_free(psc_batch* batch, void* pointer) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if (!pointer) return PSC_OK;
    if (psc_cuda_owns(batch)) return psc_cuda_free(batch, pointer);
    std::free(pointer);
    return PSC_OK;
}

int psc_copy(psc_batch* batch, void* destination, const void* source, size_t bytes) {
    using namespace psc_game;
    if (int s = checkBatch(batch)) return s;
    if ((!destination || !source) && bytes) return fail(PSC_ERROR_NULL_POINTER, "destination and source must not be NULL");
    if (!bytes) return PSC_OK;
    if (psc_cuda_owns(batch)) return psc_cuda_copy(batch, destination, source, bytes);
    std::memmove(destination, source, bytes);
    return PSC_OK;
}

}  // extern "C"
