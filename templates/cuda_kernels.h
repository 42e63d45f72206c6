// ---- psc template: CUDA kernels ---------------------------------------------
// One thread per environment.  The stepping kernel copies its environment
// into registers (local storage where it does not fit, or shared memory with
// PSC_STATE_IN_SHARED), runs any number of steps on it, and writes it back
// once; an environment too large for a thread's stack is stepped where it
// lies in the batch (SteppedEnv).

namespace psc_game {

// Where a stepping thread's environment lies: a copy on its stack, the
// environment in the batch (kEnvInBatch, too large for the stack), or a
// copy in shared memory.
enum class EnvHome { kStack, kBatch, kShared };
constexpr EnvHome kEnvHome = PSC_STATE_IN_SHARED ? EnvHome::kShared : kEnvInBatch ? EnvHome::kBatch : EnvHome::kStack;

template <EnvHome Home = kEnvHome>
struct SteppedEnv {
    Env e;
    __device__ PSC_INLINE explicit SteppedEnv(const Env& batchEnv) : e(batchEnv) {}
    __device__ PSC_INLINE void keep(Env& batchEnv) const { batchEnv = e; }
};
template <>
struct SteppedEnv<EnvHome::kBatch> {
    Env& e;
    __device__ PSC_INLINE explicit SteppedEnv(Env& batchEnv) : e(batchEnv) {}
    __device__ PSC_INLINE void keep(Env&) const {}
};
// The block's copies, kSharedEnvStride bytes apart; the launch sizes it
// (CudaBatch::runShared, runtime/plugin_host/CudaBackend.cpp).
extern __shared__ unsigned long long psc_shared_envs[];
template <>
struct SteppedEnv<EnvHome::kShared> {
    Env& e;
    __device__ PSC_INLINE explicit SteppedEnv(const Env& batchEnv)
        : e(*reinterpret_cast<Env*>(psc_shared_envs + threadIdx.x * (kSharedEnvStride / 8))) {
        e = batchEnv;
    }
    __device__ PSC_INLINE void keep(Env& batchEnv) const { batchEnv = e; }
};

__device__ PSC_INLINE UndoStack undoOf(const DeviceBatch& b, int i) {
    UndoStack u;
    u.entries = b.undoEntries + static_cast<unsigned long long>(i) * static_cast<unsigned long long>(b.undoDepth);
    u.capacity = b.undoDepth;
    u.count = b.undoDepth ? b.undoCount[i] : 0;
    u.head = b.undoDepth ? b.undoHead[i] : 0;
    u.scratch = b.turnScratch ? b.turnScratch + static_cast<unsigned long long>(i) * kMaxTurnNesting : nullptr;
    u.scratchDepth = 0;
    u.deadline = 0;
    return u;
}

__device__ PSC_INLINE void keepUndo(const DeviceBatch& b, int i, const UndoStack& u) {
    if (!b.undoDepth) return;
    b.undoCount[i] = u.count;
    b.undoHead[i] = u.head;
}

__device__ PSC_INLINE unsigned long long warpSum(unsigned long long v) {
    for (int offset = 16; offset > 0; offset >>= 1) v += __shfl_down_sync(0xffffffffu, v, offset);
    return v;
}

}  // namespace psc_game

// Which unit defines each kernel: PSC_DEFINES_RUN_KERNEL, PSC_DEFINES_OTHER_KERNELS (templates/core.h).
#if PSC_DEFINES_OTHER_KERNELS
// Restarts environments ids[k] at entries[k], with the seed seeds[k] (kSeedUnits units, lengths[k] used).
// Level loads are rare: this kernel works on the environments in place.
extern "C" __global__ void psc_reset_kernel(psc_game::DeviceBatch b, const int* ids, const int* entries,
                                            const unsigned short* seeds, const unsigned char* lengths, int count) {
    using namespace psc_game;
    const int k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k >= count) return;
    const int i = ids[k];
    // On the stack where the turns expect it (PSC_ON_STACK, templates/core.h).
    SteppedEnv<kStateOnStack ? EnvHome::kStack : EnvHome::kBatch> started(b.envs[i]);
    Env& e = started.e;
    e.levelEntry = entries[k];
#if PSC_USES_RANDOM
    for (int c = 0; c < kSeedUnits; ++c) e.seed[c] = seeds[k * kSeedUnits + c];
    e.seedLength = lengths[k];
#else
    (void)seeds;
    (void)lengths;
#endif
    UndoStack u = undoOf(b, i);
    u.count = 0;
    u.head = 0;
    startEpisode(e, u);
    keepUndo(b, i, u);
    started.keep(b.envs[i]);
}
#endif

// `steps` steps of every environment, its state held by the thread
// throughout.  Step k's action for environment i is actions[k * numEnvs + i],
// or, when actions is NULL, drawn by randomAction(seed, i, firstStep + k).
// Step k's results go to rewards/terminated/truncated/won[k * numEnvs + i]
// where those are not NULL; totals go to b.stats; observations of the final
// state to b.observations when `observe` is set.
//
// The registers layout's launch bounds: PSC_RUN_KERNEL_BLOCKS 128-thread
// blocks an SM, chosen by psc from the state's size and the rules' code
// (codegen/CppSource.cpp's registerLayoutBlocks).  The launch's block is
// CudaBatch::kBlock, 128.
#if PSC_DEFINES_RUN_KERNEL
#if PSC_RUN_KERNEL_BLOCKS > 0
#define PSC_RUN_KERNEL_BOUNDS __launch_bounds__(128, PSC_RUN_KERNEL_BLOCKS)
#else
#define PSC_RUN_KERNEL_BOUNDS
#endif
extern "C" __global__ void PSC_RUN_KERNEL_BOUNDS psc_run_kernel(psc_game::DeviceBatch b, int steps, const int* actions,
                                          unsigned long long seed, int actionCount, unsigned long long firstStep,
                                          float* rewards, unsigned char* terminated, unsigned char* truncated,
                                          unsigned char* won, int observe) {
    using namespace psc_game;
    const int i = blockIdx.x * blockDim.x + threadIdx.x;
    unsigned long long wins = 0;
    unsigned long long episodes = 0;
    unsigned long long done = 0;
    unsigned long long badActions = 0;
    if (i < b.numEnvs) {
        SteppedEnv<> stepped(b.envs[i]);
        Env& e = stepped.e;
        UndoStack u = undoOf(b, i);
        for (int k = 0; k < steps; ++k) {
            const unsigned long long at = static_cast<unsigned long long>(k) * b.numEnvs + i;
            const int action = actions ? actions[at]
                                       : randomAction(seed, static_cast<u64>(i), firstStep + static_cast<u64>(k), actionCount);
            if (action < 0 || action >= kInputCount) {
                // Misuse: the step is skipped and psc_synchronize reports it.
                ++badActions;
                continue;
            }
            const StepOutcome o = stepEnvironment(e, u, action);
            wins += o.won;
            episodes += (o.terminated || o.truncated) ? 1u : 0u;
            if (rewards) rewards[at] = o.reward;
            if (terminated) terminated[at] = o.terminated;
            if (truncated) truncated[at] = o.truncated;
            if (won) won[at] = o.won;
        }
        done = static_cast<unsigned long long>(steps);
        keepUndo(b, i, u);
        b.episodeSteps[i] = e.episodeSteps;
        stepped.keep(b.envs[i]);
        if (observe) {
            const unsigned long long bytes = static_cast<unsigned long long>(b.channels) * b.maxWidth * b.maxHeight;
            observeEnvironment(b.envs[i], b.channelObjects, b.channels, b.maxWidth, b.maxHeight, b.observations + bytes * i);
        }
    }
    done = warpSum(done);
    wins = warpSum(wins);
    episodes = warpSum(episodes);
    badActions = warpSum(badActions);
    if ((threadIdx.x & 31) == 0 && done) {
        atomicAdd(&b.stats[0], done - badActions);
        atomicAdd(&b.stats[1], wins);
        atomicAdd(&b.stats[2], episodes);
        if (badActions) atomicAdd(&b.stats[3], badActions);
    }
}
#endif

#if PSC_DEFINES_OTHER_KERNELS
extern "C" __global__ void psc_observe_kernel(psc_game::DeviceBatch b) {
    using namespace psc_game;
    const int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= b.numEnvs) return;
    const unsigned long long bytes = static_cast<unsigned long long>(b.channels) * b.maxWidth * b.maxHeight;
    observeEnvironment(b.envs[i], b.channelObjects, b.channels, b.maxWidth, b.maxHeight, b.observations + bytes * i);
}

#if PSC_SEARCH_KERNELS
// Child k = i * actionCount + a of psc_expand: key i after input actions[a],
// decoded over a copy of the template environment (templates/state_key.h).
// With a deadline (on the GPU's clock, deadlineClock; 0: none), children
// the deadline leaves out are flagged kExpandTimedOut (expandKey).
extern "C" __global__ void psc_expand_kernel(psc_game::DeviceBatch b, int templateEnv, const unsigned long long* keys,
                                             int count, const int* actions, int actionCount, unsigned long long* children,
                                             unsigned char* flags, unsigned long long* hashes, int* estimates,
                                             unsigned long long deadline) {
    using namespace psc_game;
    const long long k = static_cast<long long>(blockIdx.x) * blockDim.x + threadIdx.x;
    if (k >= static_cast<long long>(count) * actionCount) return;
    const u64* parent = keys + static_cast<unsigned long long>(k / actionCount) * kKeyWords;
    u64* child = children + static_cast<unsigned long long>(k) * kKeyWords;
    const int action = actions[k % actionCount];
    if constexpr (kExpandTooLarge) {
        flags[k] = kExpandInvalid;  // refused on the host
    } else {
        Env e = b.envs[templateEnv];
        if (action < 0 || action >= kInputCount || keyEntry(parent) != e.entry) {
            flags[k] = kExpandInvalid;
            return;
        }
        const u8 f = expandKey(e, parent, action, child, deadline);
        flags[k] = f;
        const bool noChild = f == kExpandTimedOut || f == kExpandInvalid;
        if (hashes) hashes[k] = noChild ? 0 : hashKey(child);
        if (estimates) estimates[k] = noChild ? 0 : winDistance(e);
    }
}

// The GPU's clock, read once a batch to put psc_set_deadline's deadline on it.
extern "C" __global__ void psc_clock_kernel(unsigned long long* now) { *now = psc_game::deadlineClock(); }
#endif
#endif  // PSC_DEFINES_OTHER_KERNELS
