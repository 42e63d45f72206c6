// ---- psc template: the plugin's C ABI on the CPU -------------------------
// Batches of environments stepped by a pool of worker threads, observations,
// state save/restore and the canonical state dump (runtime/psc_plugin.h).

namespace psc_game {
namespace {

// Runs fn(begin, end) over [0, n) split across persistent worker threads.
class WorkerPool {
public:
    explicit WorkerPool(int threads) {
        for (int i = 1; i < threads; ++i) workers_.emplace_back([this, i] { loop(i); });
        threads_ = threads;
    }
    ~WorkerPool() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stopping_ = true;
            ++generation_;
        }
        wake_.notify_all();
        for (auto& w : workers_) w.join();
    }
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
    int32_t levelEntry;
    int32_t episodeSteps;
};

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
    std::vector<int32_t> levelEntry;    // the entry each environment resets to
    std::vector<int32_t> episodeSteps;
    std::vector<uint8_t> needsReset;    // next-step auto-reset: the episode ended on the last step
    // psc_buffers
    std::vector<int32_t> actions;
    std::vector<uint8_t> observations;
    std::vector<float> rewards;
    std::vector<uint8_t> terminated;
    std::vector<uint8_t> truncated;
    std::vector<uint8_t> won;
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

void startEnv(psc_batch* b, int i) {
    b->envs[i].stopOnWin = b->autoReset != PSC_AUTO_RESET_OFF ? 1 : 0;
    startAtEntry(b->envs[i], b->undo[i], b->levelEntry[i]);
    b->episodeSteps[i] = 0;
    b->needsReset[i] = 0;
}

psc_step_result stepEnv(psc_batch* b, int i, int action) {
    psc_step_result out{};
    if (b->needsReset[i]) {
        startEnv(b, i);
        return out;
    }
    Env& e = b->envs[i];
    UndoStack& u = b->undo[i];
    e.wins = 0;
    const bool settled = applyInput(e, u, action);
    out.won = e.wins > 0;
    out.reward = static_cast<float>(e.wins);
    out.cut_off = !settled || e.unavailable;
    out.episode_steps = ++b->episodeSteps[i];
    if (b->autoReset == PSC_AUTO_RESET_OFF) {
        out.terminated = e.titleScreen && e.startExisted;
        return out;
    }
    out.terminated = out.won;
    out.truncated = !out.won && b->maxEpisodeSteps > 0 && out.episode_steps >= b->maxEpisodeSteps;
    if (out.terminated || out.truncated) {
        if (b->autoReset == PSC_AUTO_RESET_SAME_STEP) startEnv(b, i);
        else b->needsReset[i] = 1;
    }
    return out;
}

void observeEnv(const Env& e, uint8_t* out) {
    const size_t plane = static_cast<size_t>(kMaxWidth) * kMaxHeight;
    std::memset(out, 0, plane * kChannelCount);
    for (int c = 0; c < kChannelCount; ++c) {
        const Board& board = e.obj[kChannelObject[c]];
        for (int x = 0; x < e.width && x < kMaxWidth; ++x) {
            for (int y = 0; y < e.height && y < kMaxHeight; ++y) {
                out[plane * c + static_cast<size_t>(y) * kMaxWidth + x] = board.test(positionOf(e, x, y));
            }
        }
    }
}

size_t observationBytes() { return static_cast<size_t>(kMaxWidth) * kMaxHeight * kChannelCount; }

// A counter-based random action: the same (seed, env, step) gives the same action.
int randomAction(uint64_t seed, uint64_t env, uint64_t step, int count) {
    uint64_t z = seed ^ (env * 0x9E3779B97F4A7C15ull) ^ (step * 0xD1B54A32D192ED03ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<int>((z >> 32) % static_cast<uint64_t>(count));
}

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
        b->levelEntry.assign(static_cast<size_t>(b->numEnvs), kLevelEntries[firstBuilt]);
        b->episodeSteps.assign(static_cast<size_t>(b->numEnvs), 0);
        b->needsReset.assign(static_cast<size_t>(b->numEnvs), 0);
        b->actions.assign(static_cast<size_t>(b->numEnvs), 0);
        b->observations.assign(static_cast<size_t>(b->numEnvs) * observationBytes(), 0);
        b->rewards.assign(static_cast<size_t>(b->numEnvs), 0.0f);
        b->terminated.assign(static_cast<size_t>(b->numEnvs), 0);
        b->truncated.assign(static_cast<size_t>(b->numEnvs), 0);
        b->won.assign(static_cast<size_t>(b->numEnvs), 0);
        for (int i = 0; i < b->numEnvs; ++i) {
            b->undo[i] = UndoStack{b->undoDepth ? &b->undoEntries[static_cast<size_t>(i) * b->undoDepth] : nullptr,
                                   b->undoDepth, 0, 0};
            std::memset(&b->envs[i], 0, sizeof(Env));
            setSeed(b->envs[i], utf16("0"));
            startEnv(b, i);
        }
        int threads = options->threads > 0 ? options->threads : static_cast<int>(std::thread::hardware_concurrency());
        b->pool = new WorkerPool(std::max(1, threads));
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
        batch->levelEntry[env] = kLevelEntries[levels[i]];
        setSeed(batch->envs[env], utf16(std::to_string(seeds[i]).c_str()));
        startEnv(batch, env);
    }
    return PSC_OK;
}

int psc_reset_entry(psc_batch* batch, int32_t env, int32_t entry, const char* seed) {
    using namespace psc_game;
    if (int s = checkEnv(batch, env)) return s;
    if (psc_cuda_owns(batch)) return fail(PSC_ERROR_BACKEND_UNAVAILABLE, "psc_reset_entry runs on CPU batches");
    if (!seed) return fail(PSC_ERROR_NULL_POINTER, "seed is NULL");
    if (entry < 0) return fail(PSC_ERROR_BAD_LEVEL, "entry must not be negative");
    if (entry < kEntries && kEntryBoards[entry] == -2) {
        return fail(PSC_ERROR_BAD_LEVEL, "entry " + std::to_string(entry) + " was left out of this plugin (psc --levels)");
    }
    if (!setSeed(batch->envs[env], utf16(seed))) {
        return fail(PSC_ERROR_BAD_ARGUMENT, "the seed is longer than " + std::to_string(kSeedUnits) + " UTF-16 units");
    }
    batch->levelEntry[env] = entry;
    startEnv(batch, env);
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
            const psc_step_result r = stepEnv(batch, i, actions[i]);
            if (results) results[i] = r;
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
            const psc_step_result r = stepEnv(batch, i, batch->actions[i]);
            batch->rewards[i] = r.reward;
            batch->terminated[i] = r.terminated;
            batch->truncated[i] = r.truncated;
            batch->won[i] = r.won;
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
                const psc_step_result r = stepEnv(batch, i, randomAction(seed, static_cast<uint64_t>(i), static_cast<uint64_t>(k), actionCount));
                ++st.steps;
                st.wins += r.won;
                st.episodes += (r.terminated || r.truncated) ? 1 : 0;
            }
        }
    });
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
    if (psc_cuda_owns(batch)) return fail(PSC_ERROR_BACKEND_UNAVAILABLE, "state save/restore runs on CPU batches");
    if (!buffer) return fail(PSC_ERROR_NULL_POINTER, "buffer is NULL");
    if (size < psc_state_size(batch)) return fail(PSC_ERROR_BUFFER_TOO_SMALL, "the buffer is smaller than psc_state_size()");
    StateHeader h{};
    std::memcpy(h.magic, "pscstat1", 8);
    std::memcpy(h.sha1, kGameInfo.source_sha1, 40);
    const UndoStack& u = batch->undo[env];
    h.undoCapacity = u.capacity;
    h.undoCount = u.count;
    h.levelEntry = batch->levelEntry[env];
    h.episodeSteps = batch->episodeSteps[env];
    char* out = static_cast<char*>(buffer);
    std::memcpy(out, &h, sizeof h);
    std::memcpy(out + sizeof h, &batch->envs[env], sizeof(Env));
    Snapshot* entries = reinterpret_cast<Snapshot*>(out + sizeof h + sizeof(Env));
    for (int k = 0; k < u.count; ++k) std::memcpy(&entries[k], &u.entries[(u.head + k) % u.capacity], sizeof(Snapshot));
    return PSC_OK;
}

int psc_load_state(psc_batch* batch, int32_t env, const void* buffer, size_t size) {
    using namespace psc_game;
    if (int s = checkEnv(batch, env)) return s;
    if (psc_cuda_owns(batch)) return fail(PSC_ERROR_BACKEND_UNAVAILABLE, "state save/restore runs on CPU batches");
    if (!buffer) return fail(PSC_ERROR_NULL_POINTER, "buffer is NULL");
    if (size < psc_state_size(batch)) return fail(PSC_ERROR_BUFFER_TOO_SMALL, "the buffer is smaller than psc_state_size()");
    StateHeader h;
    const char* in = static_cast<const char*>(buffer);
    std::memcpy(&h, in, sizeof h);
    if (std::memcmp(h.magic, "pscstat1", 8) != 0 || std::memcmp(h.sha1, kGameInfo.source_sha1, 40) != 0) {
        return fail(PSC_ERROR_BAD_STATE, "the buffer is not a saved state of this game");
    }
    if (h.undoCapacity != batch->undoDepth || h.undoCount < 0 || h.undoCount > h.undoCapacity) {
        return fail(PSC_ERROR_BAD_STATE, "the saved state's undo depth differs from this batch's");
    }
    std::memcpy(&batch->envs[env], in + sizeof h, sizeof(Env));
    UndoStack& u = batch->undo[env];
    const Snapshot* entries = reinterpret_cast<const Snapshot*>(in + sizeof h + sizeof(Env));
    u.head = 0;
    u.count = h.undoCount;
    for (int k = 0; k < u.count; ++k) std::memcpy(&u.entries[k], &entries[k], sizeof(Snapshot));
    batch->levelEntry[env] = h.levelEntry;
    batch->episodeSteps[env] = h.episodeSteps;
    return PSC_OK;
}

int psc_dump_state(const psc_batch* batch, int32_t env, char* buffer, size_t size, size_t* needed) {
    using namespace psc_game;
    if (int s = checkEnv(batch, env)) return s;
    if (psc_cuda_owns(batch)) return fail(PSC_ERROR_BACKEND_UNAVAILABLE, "state dumps run on CPU batches");
    const std::string json = dumpState(batch->envs[env]);
    if (needed) *needed = json.size() + 1;
    if (!buffer || size < json.size() + 1) return fail(PSC_ERROR_BUFFER_TOO_SMALL, "the buffer is too small for the dump");
    std::memcpy(buffer, json.c_str(), json.size() + 1);
    return PSC_OK;
}

}  // extern "C"
