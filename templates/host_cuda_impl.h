// ---- psc template: the CUDA backend's host side (batches) -----------------

namespace psc_game {
namespace cuda {

Batch* of(const psc_batch* b) { return static_cast<Batch*>(b->cuda); }

}  // namespace cuda
}  // namespace psc_game

static bool psc_cuda_owns(const psc_batch* b) { return b && b->cuda; }

static int psc_cuda_batch_create(const psc_batch_options* options, psc_batch** out) {
    using namespace psc_game;
    using namespace psc_game::cuda;
    if (options->backend != PSC_BACKEND_CUDA) return fail(PSC_ERROR_BAD_ARGUMENT, "unknown backend");
    if (options->num_envs <= 0) return fail(PSC_ERROR_BAD_ARGUMENT, "num_envs must be positive");
    if (options->undo_depth < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "undo_depth must not be negative");
    if (options->max_episode_steps < 0) return fail(PSC_ERROR_BAD_ARGUMENT, "max_episode_steps must not be negative");
    if (options->auto_reset < PSC_AUTO_RESET_OFF || options->auto_reset > PSC_AUTO_RESET_NEXT_STEP) {
        return fail(PSC_ERROR_BAD_ARGUMENT, "auto_reset must be 0, 1 or 2 (psc_auto_reset)");
    }
    if (options->again_mode != PSC_AGAIN_SETTLE && options->again_mode != PSC_AGAIN_ONE_TURN) {
        return fail(PSC_ERROR_BAD_ARGUMENT, "again_mode must be 0 or 1 (psc_again_mode)");
    }
    if (kLevelCount == 0) return fail(PSC_ERROR_BAD_LEVEL, "the game has no playable level");
    Driver& d = driver();
    if (!d.loaded) return fail(PSC_ERROR_BACKEND_UNAVAILABLE, d.error);
    auto* cb = new (std::nothrow) Batch;
    if (!cb) return fail(PSC_ERROR_OUT_OF_MEMORY, "out of memory");
    auto cleanup = [&](int status) {
        delete cb;
        return status;
    };
    if (int s = check(d.cuDeviceGet(&cb->device, options->device), "selecting the CUDA device")) return cleanup(s);
    if (int s = check(d.cuDevicePrimaryCtxRetain(&cb->context, cb->device), "creating the CUDA context")) {
        cb->context = nullptr;
        return cleanup(s);
    }
    ContextScope scope(cb->context);
    constexpr int kStackLimit = 0;  // CU_LIMIT_STACK_SIZE
    size_t stack = 0;
    if (int s = check(d.cuCtxGetLimit(&stack, kStackLimit), "reading the stack limit")) return cleanup(s);
    if (stack < psc_device_stack_bytes) {
        const std::string what = "raising the stack limit to " + std::to_string(psc_device_stack_bytes) + " bytes a thread";
        if (int s = check(d.cuCtxSetLimit(kStackLimit, psc_device_stack_bytes), what.c_str())) return cleanup(s);
    }
    const CUresult loaded = loadModule(&cb->module);
    if (int s = check(loaded, "loading the game's kernels")) {
        cb->module = nullptr;
        return cleanup(s);
    }
    struct Named {
        CUfunction* f;
        const char* name;
    } kernels[] = {{&cb->reset, "psc_reset_kernel"}, {&cb->run, "psc_run_kernel"}, {&cb->observe, "psc_observe_kernel"},
                   {&cb->expand, PSC_SEARCH_KERNELS ? "psc_expand_kernel" : nullptr}};
    for (const Named& k : kernels) {
        if (!k.name) continue;
        if (int s = check(d.cuModuleGetFunction(k.f, cb->module, k.name), k.name)) return cleanup(s);
    }
    if (PSC_STATE_IN_SHARED) {
        if (int s = cb->fitSharedEnvs()) return cleanup(s);
    }
    const int n = options->num_envs;
    DeviceBatch& b = cb->dev;
    b.numEnvs = n;
    b.undoDepth = options->undo_depth;
    b.channels = kChannelCount;
    b.maxWidth = kMaxWidth;
    b.maxHeight = kMaxHeight;
    const size_t obsBytes = static_cast<size_t>(kChannelCount) * kMaxWidth * kMaxHeight;
    int* channelObjects = nullptr;
    int s = PSC_OK;
    if (!s) s = cb->allocate(&b.envs, static_cast<size_t>(n));
    if (!s) s = cb->allocate(&b.undoEntries, static_cast<size_t>(n) * static_cast<size_t>(b.undoDepth));
    if (!s) s = cb->allocate(&b.undoCount, static_cast<size_t>(n));
    if (!s) s = cb->allocate(&b.undoHead, static_cast<size_t>(n));
    if (!s) s = cb->allocate(&b.actions, static_cast<size_t>(n));
    if (!s) s = cb->allocate(&b.observations, static_cast<size_t>(n) * obsBytes);
    if (!s) s = cb->allocate(&b.rewards, static_cast<size_t>(n));
    if (!s) s = cb->allocate(&b.terminated, static_cast<size_t>(n));
    if (!s) s = cb->allocate(&b.truncated, static_cast<size_t>(n));
    if (!s) s = cb->allocate(&b.won, static_cast<size_t>(n));
    if (!s) s = cb->allocate(&b.episodeSteps, static_cast<size_t>(n));
    if (!s) s = cb->allocate(&channelObjects, static_cast<size_t>(kChannelCount));
    if (!s) s = cb->allocate(&b.stats, 4);
    if (s) return cleanup(s);
    b.channelObjects = channelObjects;
    if (int e = check(d.cuMemcpyHtoD(reinterpret_cast<CUdeviceptr>(channelObjects), kChannelObject, sizeof(int) * kChannelCount),
                      "uploading tables")) {
        return cleanup(e);
    }
    cb->autoReset = options->auto_reset;
    cb->againMode = options->again_mode;
    cb->maxEpisodeSteps = options->max_episode_steps;
    // The environments' fixed settings, then every environment started at the first level built.
    {
        std::vector<Env> envs(static_cast<size_t>(n));
        int firstBuilt = 0;
        while (!kLevelBuilt[firstBuilt]) ++firstBuilt;
        for (Env& e : envs) {
            std::memset(&e, 0, sizeof(Env));
            e.autoReset = static_cast<u8>(options->auto_reset);
            e.againMode = static_cast<u8>(options->again_mode);
            e.maxEpisodeSteps = options->max_episode_steps;
            e.levelEntry = kLevelEntries[firstBuilt];
        }
        if (int e = check(d.cuMemcpyHtoD(reinterpret_cast<CUdeviceptr>(b.envs), envs.data(), sizeof(Env) * envs.size()),
                          "uploading the environments")) {
            return cleanup(e);
        }
    }
    cb->buffers.device = options->device;
    cb->buffers.num_envs = n;
    cb->buffers.actions = b.actions;
    cb->buffers.observations = b.observations;
    cb->buffers.rewards = b.rewards;
    cb->buffers.terminated = b.terminated;
    cb->buffers.truncated = b.truncated;
    cb->buffers.won = b.won;
    cb->buffers.episode_steps = b.episodeSteps;

    psc_batch* batch = new (std::nothrow) psc_batch;
    if (!batch) return cleanup(fail(PSC_ERROR_OUT_OF_MEMORY, "out of memory"));
    batch->cuda = cb;
    batch->numEnvs = n;
    batch->undoDepth = options->undo_depth;
    batch->autoReset = options->auto_reset;
    batch->maxEpisodeSteps = options->max_episode_steps;
    std::vector<int32_t> levels(static_cast<size_t>(n));
    std::vector<uint64_t> seeds(static_cast<size_t>(n), 0);
    int firstBuilt = 0;
    while (!kLevelBuilt[firstBuilt]) ++firstBuilt;
    for (auto& l : levels) l = firstBuilt;
    if (int e = psc_cuda_reset(batch, nullptr, n, levels.data(), seeds.data())) {
        delete batch;
        return cleanup(e);
    }
    *out = batch;
    return PSC_OK;
}

static bool psc_cuda_batch_destroy(psc_batch* b) {
    if (!psc_cuda_owns(b)) return false;
    delete psc_game::cuda::of(b);
    delete b;
    return true;
}

static int psc_cuda_reset_entries(psc_batch* b, const int32_t* envIds, int32_t count, const int32_t* entries,
                                  const std::vector<std::u16string>& seeds) {
    using namespace psc_game;
    using namespace psc_game::cuda;
    Batch* cb = of(b);
    Driver& d = driver();
    ContextScope scope(cb->context);
    std::vector<int32_t> ids(static_cast<size_t>(count));
    std::vector<uint16_t> units(static_cast<size_t>(count) * kSeedUnits, 0);
    std::vector<uint8_t> lengths(static_cast<size_t>(count), 0);
    for (int32_t k = 0; k < count; ++k) {
        ids[static_cast<size_t>(k)] = envIds ? envIds[k] : k;
        const std::u16string& seed = seeds[static_cast<size_t>(k)];
        if (seed.size() > static_cast<size_t>(kSeedUnits)) {
            return fail(PSC_ERROR_BAD_ARGUMENT, "the seed is longer than " + std::to_string(kSeedUnits) + " UTF-16 units");
        }
        for (size_t c = 0; c < seed.size(); ++c) units[static_cast<size_t>(k) * kSeedUnits + c] = seed[c];
        lengths[static_cast<size_t>(k)] = static_cast<uint8_t>(seed.size());
    }
    int* dIds = nullptr;
    int* dEntries = nullptr;
    unsigned short* dUnits = nullptr;
    unsigned char* dLengths = nullptr;
    CUdeviceptr raw[4] = {0, 0, 0, 0};
    auto release = [&](int status) {
        for (CUdeviceptr p : raw) {
            if (p) d.cuMemFree(p);
        }
        return status;
    };
    if (int s = check(d.cuMemAlloc(&raw[0], sizeof(int) * ids.size() + 1), "allocating")) return release(s);
    if (int s = check(d.cuMemAlloc(&raw[1], sizeof(int) * ids.size() + 1), "allocating")) return release(s);
    if (int s = check(d.cuMemAlloc(&raw[2], sizeof(uint16_t) * units.size() + 1), "allocating")) return release(s);
    if (int s = check(d.cuMemAlloc(&raw[3], lengths.size() + 1), "allocating")) return release(s);
    dIds = reinterpret_cast<int*>(raw[0]);
    dEntries = reinterpret_cast<int*>(raw[1]);
    dUnits = reinterpret_cast<unsigned short*>(raw[2]);
    dLengths = reinterpret_cast<unsigned char*>(raw[3]);
    if (int s = check(d.cuMemcpyHtoD(raw[0], ids.data(), sizeof(int) * ids.size()), "uploading")) return release(s);
    if (int s = check(d.cuMemcpyHtoD(raw[1], entries, sizeof(int) * ids.size()), "uploading")) return release(s);
    if (int s = check(d.cuMemcpyHtoD(raw[2], units.data(), sizeof(uint16_t) * units.size()), "uploading")) return release(s);
    if (int s = check(d.cuMemcpyHtoD(raw[3], lengths.data(), lengths.size()), "uploading")) return release(s);
    void* args[] = {&cb->dev, &dIds, &dEntries, &dUnits, &dLengths, &count};
    if (int s = cb->launch(cb->reset, count, args)) return release(s);
    return release(cb->sync());
}

static int psc_cuda_reset(psc_batch* b, const int32_t* envIds, int32_t count, const int32_t* levels, const uint64_t* seeds) {
    using namespace psc_game;
    if (!levels || !seeds) return fail(PSC_ERROR_NULL_POINTER, "levels and seeds must not be NULL");
    if (!envIds && count != b->numEnvs) return fail(PSC_ERROR_BAD_ARGUMENT, "without env_ids, count must be num_envs");
    std::vector<int32_t> entries(static_cast<size_t>(count));
    std::vector<std::u16string> seedUnits(static_cast<size_t>(count));
    for (int32_t i = 0; i < count; ++i) {
        const int32_t env = envIds ? envIds[i] : i;
        if (env < 0 || env >= b->numEnvs) return fail(PSC_ERROR_BAD_ENV, "environment " + std::to_string(env) + " out of range");
        if (levels[i] < 0 || levels[i] >= kLevelCount || !kLevelBuilt[levels[i]]) {
            return fail(PSC_ERROR_BAD_LEVEL, "level " + std::to_string(levels[i]) + " is not available in this plugin");
        }
        entries[static_cast<size_t>(i)] = kLevelEntries[levels[i]];
        seedUnits[static_cast<size_t>(i)] = utf16(std::to_string(seeds[i]).c_str());
    }
    return psc_cuda_reset_entries(b, envIds, count, entries.data(), seedUnits);
}

namespace psc_game {
namespace cuda {

// Queues psc_run_kernel: `steps` steps with device actions [steps][num_envs]
// (NULL: random actions from `seed`), per-step results where not NULL.
int run(psc_batch* b, int32_t steps, const int32_t* actions, uint64_t seed, float* rewards, uint8_t* terminated,
        uint8_t* truncated, uint8_t* won, int observe) {
    Batch* cb = of(b);
    ContextScope scope(cb->context);
    int actionCount = (kGameInfo.flags & PSC_FLAG_NOACTION) ? 4 : 5;
    unsigned long long first = cb->rolloutSteps;
    void* args[] = {&cb->dev, &steps, &actions, &seed, &actionCount, &first, &rewards, &terminated, &truncated, &won, &observe};
    if (int s = cb->launch(cb->run, b->numEnvs, args, cb->runBlock, cb->runShared)) return s;
    if (!actions) cb->rolloutSteps += static_cast<unsigned long long>(steps);
    return PSC_OK;
}

// Reads and clears the kernels' counters; reports invalid actions they skipped.
int readCounters(psc_batch* b, unsigned long long counts[4]) {
    Batch* cb = of(b);
    Driver& d = driver();
    ContextScope scope(cb->context);
    if (int s = cb->sync()) return s;
    const CUdeviceptr stats = reinterpret_cast<CUdeviceptr>(cb->dev.stats);
    if (int s = check(d.cuMemcpyDtoH(counts, stats, 4 * sizeof(unsigned long long)), "reading counters")) return s;
    if (int s = check(d.cuMemsetD8(stats, 0, 4 * sizeof(unsigned long long)), "clearing counters")) return s;
    if (counts[3]) {
        return fail(PSC_ERROR_BAD_ACTION, std::to_string(counts[3]) +
                                              " steps had an action outside [0, 8) and were skipped");
    }
    return PSC_OK;
}

}  // namespace cuda
}  // namespace psc_game

static int psc_cuda_step_buffers(psc_batch* b) {
    using namespace psc_game;
    using namespace psc_game::cuda;
    const DeviceBatch& dev = of(b)->dev;
    return run(b, 1, dev.actions, 0, dev.rewards, dev.terminated, dev.truncated, dev.won, 1);
}

static int psc_cuda_step_many(psc_batch* b, int32_t steps, const int32_t* actions, float* rewards, uint8_t* terminated,
                              uint8_t* truncated, uint8_t* won) {
    using namespace psc_game::cuda;
    return run(b, steps, actions, 0, rewards, terminated, truncated, won, 1);
}

static int psc_cuda_step(psc_batch* b, const int32_t* actions, psc_step_result* results) {
    using namespace psc_game;
    using namespace psc_game::cuda;
    if (!actions) return fail(PSC_ERROR_NULL_POINTER, "actions is NULL");
    for (int i = 0; i < b->numEnvs; ++i) {
        if (actions[i] < 0 || actions[i] >= kInputCount) return fail(PSC_ERROR_BAD_ACTION, "action out of range [0, 8)");
    }
    Batch* cb = of(b);
    Driver& d = driver();
    ContextScope scope(cb->context);
    const size_t n = static_cast<size_t>(b->numEnvs);
    if (int s = check(d.cuMemcpyHtoD(reinterpret_cast<CUdeviceptr>(cb->dev.actions), actions, sizeof(int32_t) * n), "uploading actions")) return s;
    if (int s = psc_cuda_step_buffers(b)) return s;
    unsigned long long counts[4];
    if (int s = readCounters(b, counts)) return s;
    if (!results) return PSC_OK;
    std::vector<float> rewards(n);
    std::vector<uint8_t> terminated(n), truncated(n), won(n);
    std::vector<int32_t> steps(n);
    int s = PSC_OK;
    if (!s) s = check(d.cuMemcpyDtoH(rewards.data(), reinterpret_cast<CUdeviceptr>(cb->dev.rewards), sizeof(float) * n), "reading results");
    if (!s) s = check(d.cuMemcpyDtoH(terminated.data(), reinterpret_cast<CUdeviceptr>(cb->dev.terminated), n), "reading results");
    if (!s) s = check(d.cuMemcpyDtoH(truncated.data(), reinterpret_cast<CUdeviceptr>(cb->dev.truncated), n), "reading results");
    if (!s) s = check(d.cuMemcpyDtoH(won.data(), reinterpret_cast<CUdeviceptr>(cb->dev.won), n), "reading results");
    if (!s) s = check(d.cuMemcpyDtoH(steps.data(), reinterpret_cast<CUdeviceptr>(cb->dev.episodeSteps), sizeof(int32_t) * n), "reading results");
    if (s) return s;
    // A pending again turn and a rule's message live in the environments:
    // read them back only where they can be set.
    std::vector<Env> envs;
    if (cb->againMode == PSC_AGAIN_ONE_TURN || PSC_HAS_RULE_MESSAGES) {
        envs.resize(n);
        if (int r = check(d.cuMemcpyDtoH(envs.data(), reinterpret_cast<CUdeviceptr>(cb->dev.envs), sizeof(Env) * n),
                          "reading results")) {
            return r;
        }
    }
    for (size_t i = 0; i < n; ++i) {
        results[i] = psc_step_result{};
        results[i].message = -1;
        if (!envs.empty()) {
            results[i].againing = envs[i].againing;
            results[i].message = shownMessageOf(envs[i]);
        }
        results[i].reward = rewards[i];
        results[i].terminated = terminated[i];
        results[i].truncated = truncated[i];
        results[i].won = won[i];
        results[i].episode_steps = steps[i];
    }
    return PSC_OK;
}

static int psc_cuda_observe(psc_batch* b, uint8_t* observations, size_t size) {
    using namespace psc_game;
    using namespace psc_game::cuda;
    if (!observations) return fail(PSC_ERROR_NULL_POINTER, "observations is NULL");
    const size_t bytes = static_cast<size_t>(kChannelCount) * kMaxWidth * kMaxHeight * static_cast<size_t>(b->numEnvs);
    if (size < bytes) return fail(PSC_ERROR_BUFFER_TOO_SMALL, "observations need " + std::to_string(bytes) + " bytes");
    Batch* cb = of(b);
    ContextScope scope(cb->context);
    void* args[] = {&cb->dev};
    if (int s = cb->launch(cb->observe, b->numEnvs, args)) return s;
    if (int s = cb->sync()) return s;
    return check(driver().cuMemcpyDtoH(observations, reinterpret_cast<CUdeviceptr>(cb->dev.observations), bytes), "reading observations");
}

static int psc_cuda_get_buffers(psc_batch* b, psc_buffers* buffers) {
    using namespace psc_game;
    if (!buffers) return fail(PSC_ERROR_NULL_POINTER, "buffers is NULL");
    *buffers = psc_game::cuda::of(b)->buffers;
    return PSC_OK;
}

static int psc_cuda_set_stream(psc_batch* b, void* stream) {
    psc_game::cuda::of(b)->stream = stream;
    return PSC_OK;
}

static int psc_cuda_synchronize(psc_batch* b) {
    unsigned long long counts[4];
    return psc_game::cuda::readCounters(b, counts);
}

static int psc_cuda_rollout(psc_batch* b, int32_t steps, uint64_t seed, psc_rollout_stats* stats) {
    using namespace psc_game::cuda;
    if (int s = run(b, steps, nullptr, seed, nullptr, nullptr, nullptr, nullptr, 0)) return s;
    if (!stats) return PSC_OK;
    unsigned long long counts[4];
    if (int s = readCounters(b, counts)) return s;
    stats->steps = static_cast<int64_t>(counts[0]);
    stats->wins = static_cast<int64_t>(counts[1]);
    stats->episodes = static_cast<int64_t>(counts[2]);
    return PSC_OK;
}

static int psc_cuda_fetch_env(const psc_batch* b, int env, psc_game::Env* out) {
    using namespace psc_game::cuda;
    Batch* cb = of(b);
    Driver& d = driver();
    ContextScope scope(cb->context);
    if (int s = cb->sync()) return s;
    return check(d.cuMemcpyDtoH(out, reinterpret_cast<CUdeviceptr>(cb->dev.envs + env), sizeof(psc_game::Env)),
                 "reading an environment");
}

static int psc_cuda_read_state(const psc_batch* b, int env, psc_game::Env* out, std::vector<psc_game::Snapshot>& undo) {
    using namespace psc_game;
    using namespace psc_game::cuda;
    if (int s = psc_cuda_fetch_env(b, env, out)) return s;
    undo.clear();
    Batch* cb = of(b);
    if (!cb->dev.undoDepth) return PSC_OK;
    Driver& d = driver();
    ContextScope scope(cb->context);
    int count = 0;
    int head = 0;
    if (int s = check(d.cuMemcpyDtoH(&count, reinterpret_cast<CUdeviceptr>(cb->dev.undoCount + env), sizeof(int)), "reading undo")) return s;
    if (int s = check(d.cuMemcpyDtoH(&head, reinterpret_cast<CUdeviceptr>(cb->dev.undoHead + env), sizeof(int)), "reading undo")) return s;
    const size_t depth = static_cast<size_t>(cb->dev.undoDepth);
    std::vector<Snapshot> ring(depth);
    const CUdeviceptr entries = reinterpret_cast<CUdeviceptr>(cb->dev.undoEntries + depth * static_cast<size_t>(env));
    if (int s = check(d.cuMemcpyDtoH(ring.data(), entries, sizeof(Snapshot) * depth), "reading undo")) return s;
    for (int k = 0; k < count; ++k) undo.push_back(ring[static_cast<size_t>((head + k) % cb->dev.undoDepth)]);
    return PSC_OK;
}

static int psc_cuda_write_state(psc_batch* b, int env, const psc_game::Env& in, const std::vector<psc_game::Snapshot>& undo) {
    using namespace psc_game;
    using namespace psc_game::cuda;
    Batch* cb = of(b);
    Driver& d = driver();
    ContextScope scope(cb->context);
    if (int s = cb->sync()) return s;
    if (int s = check(d.cuMemcpyHtoD(reinterpret_cast<CUdeviceptr>(cb->dev.envs + env), &in, sizeof(Env)), "writing an environment")) return s;
    if (!cb->dev.undoDepth) return PSC_OK;
    const int count = static_cast<int>(undo.size());
    const int head = 0;
    const size_t depth = static_cast<size_t>(cb->dev.undoDepth);
    const CUdeviceptr entries = reinterpret_cast<CUdeviceptr>(cb->dev.undoEntries + depth * static_cast<size_t>(env));
    if (count && check(d.cuMemcpyHtoD(entries, undo.data(), sizeof(Snapshot) * undo.size()), "writing undo")) return PSC_ERROR_DEVICE;
    if (int s = check(d.cuMemcpyHtoD(reinterpret_cast<CUdeviceptr>(cb->dev.undoCount + env), &count, sizeof(int)), "writing undo")) return s;
    return check(d.cuMemcpyHtoD(reinterpret_cast<CUdeviceptr>(cb->dev.undoHead + env), &head, sizeof(int)), "writing undo");
}

static int psc_cuda_expand(psc_batch* b, int32_t templateEnv, const void* keys, int32_t count, const int32_t* actions,
                           int32_t actionCount, void* children, uint8_t* flags, uint64_t* hashes, int32_t* estimates) {
    using namespace psc_game;
    using namespace psc_game::cuda;
    if (!PSC_SEARCH_KERNELS) {
        return fail(PSC_ERROR_BACKEND_UNAVAILABLE,
                    "this plugin was built without search's GPU kernel (psc --search-kernels); CPU batches expand states");
    }
    if (kExpandTooLarge) {
        return fail(PSC_ERROR_DEVICE, "this game's environments (" + std::to_string(sizeof(Env)) +
                                          " bytes) are too large to expand on the GPU: use the CPU backend");
    }
    const long long pairs = static_cast<long long>(count) * actionCount;
    if (pairs > INT32_MAX) return fail(PSC_ERROR_BAD_ARGUMENT, "count * action_count must be below 2^31");
    int n = static_cast<int>(pairs);
    Batch* cb = of(b);
    ContextScope scope(cb->context);
    void* args[] = {&cb->dev, &templateEnv, &keys, &count, &actions, &actionCount, &children, &flags, &hashes, &estimates};
    return cb->launch(cb->expand, n, args);
}

static int psc_cuda_alloc(psc_batch* b, size_t bytes, void** pointer) {
    using namespace psc_game::cuda;
    ContextScope scope(of(b)->context);
    CUdeviceptr p = 0;
    if (int s = check(driver().cuMemAlloc(&p, std::max<size_t>(bytes, 1)), "allocating device memory")) return s;
    *pointer = reinterpret_cast<void*>(p);
    return PSC_OK;
}

static int psc_cuda_free(psc_batch* b, void* pointer) {
    using namespace psc_game::cuda;
    ContextScope scope(of(b)->context);
    return check(driver().cuMemFree(reinterpret_cast<CUdeviceptr>(pointer)), "freeing device memory");
}

static int psc_cuda_copy(psc_batch* b, void* destination, const void* source, size_t bytes) {
    using namespace psc_game::cuda;
    Batch* cb = of(b);
    ContextScope scope(cb->context);
    if (int s = cb->sync()) return s;
    return check(driver().cuMemcpy(reinterpret_cast<CUdeviceptr>(destination), reinterpret_cast<CUdeviceptr>(source), bytes),
                 "copying memory");
}
