#include "CudaBackend.h"

#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <string>
#include <type_traits>
#include <vector>

#include "DeviceImage.h"
#include "ExpandDeadline.h"
#include "HostErrors.h"
#include "PluginFile.h"
#include "StackStride.h"

namespace psc_host {
namespace {

typedef int CUresult;
typedef int CUdevice;
typedef void* CUcontext;
typedef void* CUmodule;
typedef void* CUfunction;
typedef void* CUstream;
typedef unsigned long long CUdeviceptr;
typedef void* CUlinkState;
constexpr int kJitInputPtx = 1;  // CU_JIT_INPUT_PTX
constexpr int kJitMaxRegisters = 0;  // CU_JIT_MAX_REGISTERS
constexpr int kPointerMemoryType = 2;  // CU_POINTER_ATTRIBUTE_MEMORY_TYPE

struct Driver {
    CUresult (*cuInit)(unsigned);
    CUresult (*cuDeviceGet)(CUdevice*, int);
    CUresult (*cuDeviceGetAttribute)(int*, int, CUdevice);
    CUresult (*cuDevicePrimaryCtxRetain)(CUcontext*, CUdevice);
    CUresult (*cuDevicePrimaryCtxRelease)(CUdevice);
    CUresult (*cuCtxPushCurrent)(CUcontext);
    CUresult (*cuCtxPopCurrent)(CUcontext*);
    CUresult (*cuCtxGetLimit)(size_t*, int);
    CUresult (*cuCtxSetLimit)(int, size_t);
    CUresult (*cuModuleLoadData)(CUmodule*, const void*);
    CUresult (*cuModuleUnload)(CUmodule);
    CUresult (*cuLinkCreate)(unsigned, int*, void**, CUlinkState*);
    CUresult (*cuLinkAddData)(CUlinkState, int, void*, size_t, const char*, unsigned, int*, void**);
    CUresult (*cuLinkComplete)(CUlinkState, void**, size_t*);
    CUresult (*cuLinkDestroy)(CUlinkState);
    CUresult (*cuModuleGetFunction)(CUfunction*, CUmodule, const char*);
    CUresult (*cuFuncSetAttribute)(CUfunction, int, int);
    CUresult (*cuMemAlloc)(CUdeviceptr*, size_t);
    CUresult (*cuMemFree)(CUdeviceptr);
    CUresult (*cuMemcpyHtoD)(CUdeviceptr, const void*, size_t);
    CUresult (*cuMemcpyDtoH)(void*, CUdeviceptr, size_t);
    CUresult (*cuMemsetD8)(CUdeviceptr, unsigned char, size_t);
    CUresult (*cuMemcpy)(CUdeviceptr, CUdeviceptr, size_t);
    CUresult (*cuPointerGetAttribute)(void*, int, CUdeviceptr);
    CUresult (*cuLaunchKernel)(CUfunction, unsigned, unsigned, unsigned, unsigned, unsigned, unsigned, unsigned,
                               CUstream, void**, void**);
    CUresult (*cuStreamSynchronize)(CUstream);
    CUresult (*cuGetErrorString)(CUresult, const char**);
    bool loaded = false;
    std::string error;
};

Driver& driver() {
    static Driver d = [] {
        Driver d{};
        void* lib = dlopen("libcuda.so.1", RTLD_NOW | RTLD_LOCAL);
        if (!lib) lib = dlopen("libcuda.so", RTLD_NOW | RTLD_LOCAL);
        if (!lib) {
            d.error = "the CUDA driver (libcuda.so.1) is not available";
            return d;
        }
        bool ok = true;
        auto load = [&](auto& fn, const char* name) {
            fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(lib, name));
            ok = ok && fn;
        };
        load(d.cuInit, "cuInit");
        load(d.cuDeviceGet, "cuDeviceGet");
        load(d.cuDeviceGetAttribute, "cuDeviceGetAttribute");
        load(d.cuDevicePrimaryCtxRetain, "cuDevicePrimaryCtxRetain");
        load(d.cuDevicePrimaryCtxRelease, "cuDevicePrimaryCtxRelease_v2");
        load(d.cuCtxPushCurrent, "cuCtxPushCurrent_v2");
        load(d.cuCtxPopCurrent, "cuCtxPopCurrent_v2");
        load(d.cuCtxGetLimit, "cuCtxGetLimit");
        load(d.cuCtxSetLimit, "cuCtxSetLimit");
        load(d.cuModuleLoadData, "cuModuleLoadData");
        load(d.cuModuleUnload, "cuModuleUnload");
        load(d.cuLinkCreate, "cuLinkCreate_v2");
        load(d.cuLinkAddData, "cuLinkAddData_v2");
        load(d.cuLinkComplete, "cuLinkComplete");
        load(d.cuLinkDestroy, "cuLinkDestroy");
        load(d.cuModuleGetFunction, "cuModuleGetFunction");
        load(d.cuFuncSetAttribute, "cuFuncSetAttribute");
        load(d.cuMemAlloc, "cuMemAlloc_v2");
        load(d.cuMemFree, "cuMemFree_v2");
        load(d.cuMemcpyHtoD, "cuMemcpyHtoD_v2");
        load(d.cuMemcpyDtoH, "cuMemcpyDtoH_v2");
        load(d.cuMemsetD8, "cuMemsetD8_v2");
        load(d.cuMemcpy, "cuMemcpy");
        load(d.cuPointerGetAttribute, "cuPointerGetAttribute");
        load(d.cuLaunchKernel, "cuLaunchKernel");
        load(d.cuStreamSynchronize, "cuStreamSynchronize");
        load(d.cuGetErrorString, "cuGetErrorString");
        if (!ok) {
            d.error = "the CUDA driver lacks functions psc needs";
            return d;
        }
        if (CUresult r = d.cuInit(0)) {
            d.error = "cuInit failed (error " + std::to_string(r) + ")";
            return d;
        }
        d.loaded = true;
        return d;
    }();
    return d;
}

// The game's device code, read from the plugin's file once, at the first
// batch (DeviceImage.h); null, with the reason in *error, when it cannot be.
const DeviceImage* deviceImage(std::string* error) {
    struct Loaded {
        DeviceImage image;
        std::string error;
    };
    static const Loaded loaded = [] {
        Loaded l;
        std::string bytes;
        if (readElfSection(pluginFilePath(), kDeviceImageSection, &bytes, &l.error)) decodeDeviceImage(bytes, &l.image, &l.error);
        return l;
    }();
    *error = loaded.error;
    return loaded.error.empty() ? &loaded.image : nullptr;
}

// The game's kernels: the cubin, or, on another architecture (or with
// PSC_CUDA_FROM_PTX=1, which tests this path), the PTX compiled by the driver
// and, from several compile units or under a register cap, linked by it.
CUresult loadModule(const DeviceImage& device, const DeviceCode& code, CUmodule* module) {
    Driver& d = driver();
    const char* fromPtx = std::getenv("PSC_CUDA_FROM_PTX");
    if (!(fromPtx && *fromPtx && *fromPtx != '0') && d.cuModuleLoadData(module, device.cubin.data()) == 0) return 0;
    if (device.ptx.size() == 1 && code.unitMaxRegisters == 0) return d.cuModuleLoadData(module, device.ptx[0].c_str());
    CUlinkState link = nullptr;
    int capOption = kJitMaxRegisters;
    void* cap = reinterpret_cast<void*>(static_cast<uintptr_t>(code.unitMaxRegisters));
    CUresult r = d.cuLinkCreate(code.unitMaxRegisters > 0 ? 1 : 0, &capOption, &cap, &link);
    for (size_t k = 0; r == 0 && k < device.ptx.size(); ++k) {
        const std::string name = "unit" + std::to_string(k) + ".ptx";
        r = d.cuLinkAddData(link, kJitInputPtx, const_cast<char*>(device.ptx[k].c_str()), device.ptx[k].size() + 1,
                            name.c_str(), 0, nullptr, nullptr);
    }
    void* image = nullptr;
    size_t size = 0;
    if (r == 0) r = d.cuLinkComplete(link, &image, &size);
    if (r == 0) r = d.cuModuleLoadData(module, image);  // the image belongs to the link state
    if (link) d.cuLinkDestroy(link);
    return r;
}

// Makes a batch's context current for one call and then gives the caller's
// back: a process that drives several GPUs (or PyTorch, whose current device
// follows the current context) must not find another device selected after
// stepping a batch.
class ContextScope {
public:
    explicit ContextScope(CUcontext context) : pushed_(context && driver().cuCtxPushCurrent(context) == 0) {}
    ~ContextScope() {
        CUcontext popped = nullptr;
        if (pushed_) driver().cuCtxPopCurrent(&popped);
    }
    ContextScope(const ContextScope&) = delete;
    ContextScope& operator=(const ContextScope&) = delete;

private:
    bool pushed_;
};

int check(CUresult r, const char* what) {
    if (r == 0) return PSC_OK;
    const char* text = nullptr;
    if (driver().cuGetErrorString) driver().cuGetErrorString(r, &text);
    return fail(PSC_ERROR_DEVICE, std::string(what) + ": " + (text ? text : ("CUDA error " + std::to_string(r))));
}

}  // namespace

class CudaBatch {
public:
    CUdevice device = 0;
    CUcontext context = nullptr;
    CUmodule module = nullptr;
    CUfunction reset = nullptr;
    CUfunction run = nullptr;
    CUfunction observe = nullptr;
    CUfunction expand = nullptr;
    CUfunction clock = nullptr;
    CUstream stream = nullptr;
    DeviceBuffers dev{};
    std::vector<CUdeviceptr> allocations;
    std::vector<size_t> allocationBytes;  // of each allocation
    psc_buffers buffers{};
    int autoReset = 0;
    int againMode = 0;
    int maxEpisodeSteps = 0;
    unsigned long long rolloutSteps = 0;  // steps run by rollouts so far (the random actions' counter)
    bool clockKnown = false;               // gpuClockOffset below was measured
    int64_t gpuClockOffset = 0;            // the GPU's clock (globaltimer) minus the host's steady clock, ns
    static constexpr unsigned kBlock = 128;  // threads a block of every kernel but a shared-memory stepping one
    unsigned runBlock = kBlock;              // the stepping kernel's threads a block
    unsigned runShared = 0;                  // and dynamic shared memory a block (PSC_STATE_IN_SHARED)

    ~CudaBatch() {
        Driver& d = driver();
        ContextScope scope(context);
        for (CUdeviceptr p : allocations) d.cuMemFree(p);
        if (module) d.cuModuleUnload(module);
        if (context) d.cuDevicePrimaryCtxRelease(device);
    }
    // Device memory for the batch's lifetime, cleared.
    int allocateBytes(void** out, size_t bytes) {
        CUdeviceptr p = 0;
        if (int s = check(driver().cuMemAlloc(&p, std::max<size_t>(1, bytes)), "allocating device memory")) return s;
        allocations.push_back(p);
        allocationBytes.push_back(std::max<size_t>(1, bytes));
        *out = reinterpret_cast<void*>(p);
        return check(driver().cuMemsetD8(p, 0, std::max<size_t>(1, bytes)), "clearing device memory");
    }
    // Every allocation cleared again, as allocateBytes left it.
    int clearAllocations() {
        for (size_t i = 0; i < allocations.size(); ++i) {
            if (int s = check(driver().cuMemsetD8(allocations[i], 0, allocationBytes[i]), "clearing device memory")) return s;
        }
        return PSC_OK;
    }
    template <typename T>
    int allocate(T** out, size_t count) {
        void* p = nullptr;
        const int s = allocateBytes(&p, count * sizeof(T));
        *out = static_cast<T*>(p);
        return s;
    }
    int launch(CUfunction f, int threads, void** args, unsigned block = kBlock, unsigned sharedBytes = 0) {
        const unsigned grid = static_cast<unsigned>((threads + block - 1) / block);
        if (grid == 0) return PSC_OK;
        return check(driver().cuLaunchKernel(f, grid, 1, 1, block, 1, 1, sharedBytes, stream, args, nullptr),
                     "launching a kernel");
    }
    // With PSC_STATE_IN_SHARED: as many warps a block (four at most) as the
    // shared memory a block may have holds environments.
    int fitSharedEnvs() {
        constexpr int kMaxSharedPerBlockOptin = 97;  // CU_DEVICE_ATTRIBUTE_MAX_SHARED_MEMORY_PER_BLOCK_OPTIN
        constexpr int kMaxDynamicShared = 8;         // CU_FUNC_ATTRIBUTE_MAX_DYNAMIC_SHARED_SIZE_BYTES
        int limit = 0;
        if (int s = check(driver().cuDeviceGetAttribute(&limit, kMaxSharedPerBlockOptin, device), "reading the shared memory size")) {
            return s;
        }
        const unsigned stride = game().device->sharedEnvStride;
        const unsigned warps = std::min(4u, static_cast<unsigned>(limit) / (32 * stride));
        if (warps == 0) {
            return fail(PSC_ERROR_DEVICE, "a warp's environments need " + std::to_string(32 * stride) +
                                              " bytes of shared memory, over the " + std::to_string(limit) +
                                              " a block may have: build with --gpu-state memory");
        }
        runBlock = 32 * warps;
        runShared = runBlock * stride;
        return check(driver().cuFuncSetAttribute(run, kMaxDynamicShared, static_cast<int>(runShared)),
                     "reserving shared memory for the environments");
    }
    int sync() { return check(driver().cuStreamSynchronize(stream), "waiting for the device"); }
    // gpuClockOffset, once: the GPU's clock read by a kernel, against the
    // middle of the host's steady clock before the launch and after the read.
    int measureGpuClock() {
        if (clockKnown) return PSC_OK;
        Driver& d = driver();
        unsigned long long* now = nullptr;
        if (int s = allocate(&now, 1)) return s;
        if (int s = sync()) return s;
        const int64_t before = psc_host::steadyNanoseconds();
        void* args[] = {&now};
        if (int s = launch(clock, 1, args, 1)) return s;
        unsigned long long gpu = 0;
        if (int s = sync()) return s;
        if (int s = check(d.cuMemcpyDtoH(&gpu, reinterpret_cast<CUdeviceptr>(now), sizeof gpu), "reading the GPU's clock")) return s;
        const int64_t after = psc_host::steadyNanoseconds();
        gpuClockOffset = static_cast<int64_t>(gpu) - (before + (after - before) / 2);
        clockKnown = true;
        return PSC_OK;
    }
};


namespace {

CudaBatch* of(const psc_batch* b) { return b->cuda; }

CUdeviceptr address(const void* p, size_t offset = 0) { return reinterpret_cast<CUdeviceptr>(p) + offset; }

size_t envOffset(int env) { return game().envBytes * static_cast<size_t>(env); }

// Queues psc_run_kernel: `steps` steps with device actions [steps][num_envs]
// (NULL: random actions from `seed`), per-step results where not NULL.
int run(psc_batch* b, int32_t steps, const int32_t* actions, uint64_t seed, float* rewards, uint8_t* terminated,
        uint8_t* truncated, uint8_t* won, int observe) {
    CudaBatch* cb = of(b);
    ContextScope scope(cb->context);
    int actionCount = (game().info->flags & PSC_FLAG_NOACTION) ? 4 : 5;
    unsigned long long first = cb->rolloutSteps;
    void* args[] = {&cb->dev, &steps, &actions, &seed, &actionCount, &first, &rewards, &terminated, &truncated, &won, &observe};
    if (int s = cb->launch(cb->run, b->numEnvs, args, cb->runBlock, cb->runShared)) return s;
    if (!actions) cb->rolloutSteps += static_cast<unsigned long long>(steps);
    return PSC_OK;
}

// Reads and clears the kernels' counters; reports invalid actions they skipped.
int readCounters(psc_batch* b, unsigned long long counts[4]) {
    CudaBatch* cb = of(b);
    Driver& d = driver();
    ContextScope scope(cb->context);
    if (int s = cb->sync()) return s;
    const CUdeviceptr stats = address(cb->dev.stats);
    if (int s = check(d.cuMemcpyDtoH(counts, stats, 4 * sizeof(unsigned long long)), "reading counters")) return s;
    if (int s = check(d.cuMemsetD8(stats, 0, 4 * sizeof(unsigned long long)), "clearing counters")) return s;
    if (counts[3]) {
        return fail(PSC_ERROR_BAD_ACTION, std::to_string(counts[3]) + " steps had an action outside [0, 8) and were skipped");
    }
    return PSC_OK;
}

constexpr int kStackLimit = 0;  // CU_LIMIT_STACK_SIZE

// Held while a batch reads and raises the context's stack limit, and while one
// tunes it: a batch raising the limit as another times lower ones would
// be left with less than its kernels need.
std::mutex& stackLimitMutex() {
    static std::mutex m;
    return m;
}

// The stack limit (the context's, for all its batches) is each thread's
// stride in local memory, so it moves the stepping kernel's speed without
// changing what it computes: on one H200, limerick stepped 1.35x as fast
// with 512 bytes over its kernels' bound and kettle 0.95x with 256, and
// nothing known before a run tells the games apart (StackStride.h).  So a
// batch large enough to feel it times a few steps of its first environments
// at each of a few limits and keeps the fastest; its creation then starts
// every environment again.
constexpr int kStrideTuningEnvs = 16384;      // batches smaller than this keep the bound
constexpr int kStrideTuningMaxEnvs = 32768;  // environments stepped to time a limit

int tuneStackStride(CudaBatch* cb, size_t bound, bool* stepped) {
    const char* setting = std::getenv("PSC_CUDA_STACK_TUNING");
    if (setting && std::strcmp(setting, "0") == 0) return PSC_OK;
    if (bound == 0 || cb->dev.numEnvs < kStrideTuningEnvs) return PSC_OK;
    const bool verbose = setting && std::strcmp(setting, "verbose") == 0;
    Driver& d = driver();
    std::lock_guard<std::mutex> lock(stackLimitMutex());
    size_t contextLimit = 0;
    if (int s = check(d.cuCtxGetLimit(&contextLimit, kStackLimit), "reading the stack limit")) return s;
    const std::vector<size_t> limits = strideCandidates(bound, contextLimit);
    if (limits.size() < 2) return PSC_OK;
    DeviceBuffers first = cb->dev;
    first.numEnvs = std::min(cb->dev.numEnvs, kStrideTuningMaxEnvs);
    int steps = 0;  // the kernel's argument, set by launchSteps
    int actionCount = (game().info->flags & PSC_FLAG_NOACTION) ? 4 : 5;
    void* none = nullptr;
    unsigned long long seed = 1, firstStep = 0;
    int observe = 0;
    void* args[] = {&first, &steps, &none, &seed, &actionCount, &firstStep, &none, &none, &none, &none, &observe};
    auto launchSteps = [&](int count) {
        steps = count;
        return cb->launch(cb->run, first.numEnvs, args, cb->runBlock, cb->runShared);
    };
    // The first launch after the limit changes lays out local memory anew: one step, untimed.
    auto timeLaunch = [&](size_t limit, int count, double* seconds) -> int {
        if (int s = check(d.cuCtxSetLimit(kStackLimit, limit), "setting the stack limit")) return s;
        if (int s = launchSteps(1)) return s;
        const auto start = std::chrono::steady_clock::now();
        if (int s = launchSteps(count)) return s;
        if (int s = cb->sync()) return s;
        *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return PSC_OK;
    };
    double step = 0;
    *stepped = true;
    if (int s = timeLaunch(limits[0], 1, &step)) return s;
    if (step > kMaxTimedStepSeconds) {
        if (verbose) {
            std::fprintf(stderr, "psc: stack limit kept at %zu bytes a thread: a step of %d environments took %.1f ms, too long to time\n",
                         limits[0], first.numEnvs, step * 1e3);
        }
        return PSC_OK;
    }
    const int timedSteps = timedStepCount(step);
    std::vector<double> best(limits.size(), 1e300);
    for (int round = 0; round < 2; ++round) {
        for (size_t i = 0; i < limits.size(); ++i) {
            double seconds = 0;
            if (int s = timeLaunch(limits[i], timedSteps, &seconds)) return s;
            best[i] = std::min(best[i], seconds);
        }
    }
    const size_t kept = keptStride(best);
    if (verbose) {
        std::string line = "psc: stack limit, bytes a thread (ms for " + std::to_string(first.numEnvs) + " environments x " +
                           std::to_string(timedSteps) + " steps):";
        for (size_t i = 0; i < limits.size(); ++i) {
            line += " " + std::to_string(limits[i]) + " (" + std::to_string(best[i] * 1e3) + ")";
        }
        std::fprintf(stderr, "%s; kept %zu\n", line.c_str(), limits[kept]);
    }
    return check(d.cuCtxSetLimit(kStackLimit, limits[kept]), "setting the stack limit");
}

}  // namespace

int cudaBatchCreate(const psc_batch_options* options, psc_batch** out) {
    const GameModule& g = game();
    const DeviceCode& code = *g.device;
    const psc_game_info& info = *g.info;
    Driver& d = driver();
    if (!d.loaded) return fail(PSC_ERROR_BACKEND_UNAVAILABLE, d.error);
    std::string imageError;
    const DeviceImage* device = deviceImage(&imageError);
    if (!device) return fail(PSC_ERROR_BACKEND_UNAVAILABLE, imageError);
    auto* cb = new (std::nothrow) CudaBatch;
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
    {
        std::lock_guard<std::mutex> lock(stackLimitMutex());
        size_t stack = 0;
        if (int s = check(d.cuCtxGetLimit(&stack, kStackLimit), "reading the stack limit")) return cleanup(s);
        if (stack < device->stackBytes) {
            // The driver refuses more than 512 kB a thread, and reserves the limit
            // for every thread the GPU can hold.
            const std::string what = "raising the stack limit to the " + std::to_string(device->stackBytes) +
                                     " bytes a thread this game's kernels need (a game whose levels need more than the driver "
                                     "allows, at most 512 kB, runs on the CPU backend)";
            if (int s = check(d.cuCtxSetLimit(kStackLimit, device->stackBytes), what.c_str())) return cleanup(s);
        }
    }
    const CUresult loaded = loadModule(*device, code, &cb->module);
    if (int s = check(loaded, "loading the game's kernels")) {
        cb->module = nullptr;
        return cleanup(s);
    }
    struct Named {
        CUfunction* f;
        const char* name;
    } kernels[] = {{&cb->reset, "psc_reset_kernel"}, {&cb->run, "psc_run_kernel"}, {&cb->observe, "psc_observe_kernel"},
                   {&cb->expand, code.searchKernels ? "psc_expand_kernel" : nullptr},
                   {&cb->clock, code.searchKernels ? "psc_clock_kernel" : nullptr}};
    for (const Named& k : kernels) {
        if (!k.name) continue;
        if (int s = check(d.cuModuleGetFunction(k.f, cb->module, k.name), k.name)) return cleanup(s);
    }
    if (code.stateInShared) {
        if (int s = cb->fitSharedEnvs()) return cleanup(s);
    }
    const int n = options->num_envs;
    const size_t count = static_cast<size_t>(n);
    DeviceBuffers& b = cb->dev;
    b.numEnvs = n;
    b.undoDepth = options->undo_depth;
    b.channels = info.object_count;
    b.maxWidth = info.max_width;
    b.maxHeight = info.max_height;
    const size_t obsBytes = static_cast<size_t>(info.object_count) * static_cast<size_t>(info.max_width) * static_cast<size_t>(info.max_height);
    int* channelObjects = nullptr;
    int s = PSC_OK;
    if (!s) s = cb->allocateBytes(&b.envs, count * g.envBytes);
    if (!s) s = cb->allocateBytes(&b.undoEntries, count * static_cast<size_t>(b.undoDepth) * g.snapshotBytes);
    if (!s) s = cb->allocate(&b.undoCount, count);
    if (!s) s = cb->allocate(&b.undoHead, count);
    if (!s) s = cb->allocate(&b.actions, count);
    if (!s) s = cb->allocate(&b.observations, count * obsBytes);
    if (!s) s = cb->allocate(&b.rewards, count);
    if (!s) s = cb->allocate(&b.terminated, count);
    if (!s) s = cb->allocate(&b.truncated, count);
    if (!s) s = cb->allocate(&b.won, count);
    if (!s) s = cb->allocate(&b.episodeSteps, count);
    if (!s) s = cb->allocate(&channelObjects, static_cast<size_t>(info.object_count));
    if (!s) s = cb->allocate(&b.stats, 4);
    if (!s && code.turnScratchBytes) {
        s = count > SIZE_MAX / code.turnScratchBytes
                ? fail(PSC_ERROR_OUT_OF_MEMORY, "num_envs environments' turn scratch is more bytes than memory has")
                : cb->allocateBytes(&b.turnScratch, count * code.turnScratchBytes);
    }
    if (s) return cleanup(s);
    b.channelObjects = channelObjects;
    cb->autoReset = options->auto_reset;
    cb->againMode = options->again_mode;
    cb->maxEpisodeSteps = options->max_episode_steps;
    int firstBuilt = 0;
    while (!info.level_built[firstBuilt]) ++firstBuilt;
    // The environments' fixed settings, then (below) every environment started at the first level built.
    std::vector<uint64_t> envs(count * g.envBytes / 8);
    for (int i = 0; i < n; ++i) {
        g.initEnv(reinterpret_cast<char*>(envs.data()) + envOffset(i), info.level_entries[firstBuilt], options->auto_reset,
                  options->again_mode, options->max_episode_steps);
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
    std::vector<int32_t> entries(count, info.level_entries[firstBuilt]);
    std::vector<std::u16string> seeds(count, u"0");
    auto destroy = [&](int status) {
        cudaBatchDestroy(batch);
        delete batch;
        return status;
    };
    // Into memory as allocated: the tables, the environments' settings, and each started.
    auto start = [&]() -> int {
        if (int e = check(d.cuMemcpyHtoD(address(channelObjects), g.channelObjects, sizeof(int) * static_cast<size_t>(info.object_count)),
                          "uploading tables")) {
            return e;
        }
        if (int e = check(d.cuMemcpyHtoD(address(b.envs), envs.data(), count * g.envBytes), "uploading the environments")) return e;
        return cudaResetEntries(batch, nullptr, n, entries.data(), seeds);
    };
    if (int e = start()) return destroy(e);
    bool stepped = false;
    if (int e = tuneStackStride(cb, device->stackBytes, &stepped)) return destroy(e);
    if (stepped) {  // tuning stepped the environments: they start again
        if (int e = cb->clearAllocations()) return destroy(e);
        if (int e = start()) return destroy(e);
    }
    *out = batch;
    return PSC_OK;
}

void cudaBatchDestroy(psc_batch* b) {
    delete b->cuda;
    b->cuda = nullptr;
}

int cudaResetEntries(psc_batch* b, const int32_t* envIds, int32_t count, const int32_t* entries,
                     const std::vector<std::u16string>& seeds) {
    const int seedUnits = game().seedUnits;
    CudaBatch* cb = of(b);
    Driver& d = driver();
    ContextScope scope(cb->context);
    std::vector<int32_t> ids(static_cast<size_t>(count));
    std::vector<uint16_t> units(static_cast<size_t>(count) * static_cast<size_t>(seedUnits), 0);
    std::vector<uint8_t> lengths(static_cast<size_t>(count), 0);
    for (int32_t k = 0; k < count; ++k) {
        ids[static_cast<size_t>(k)] = envIds ? envIds[k] : k;
        const std::u16string& seed = seeds[static_cast<size_t>(k)];
        if (seed.size() > static_cast<size_t>(seedUnits)) {
            return fail(PSC_ERROR_BAD_ARGUMENT, "the seed is longer than " + std::to_string(seedUnits) + " UTF-16 units");
        }
        for (size_t c = 0; c < seed.size(); ++c) units[static_cast<size_t>(k) * static_cast<size_t>(seedUnits) + c] = seed[c];
        lengths[static_cast<size_t>(k)] = static_cast<uint8_t>(seed.size());
    }
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
    int* dIds = reinterpret_cast<int*>(raw[0]);
    int* dEntries = reinterpret_cast<int*>(raw[1]);
    unsigned short* dUnits = reinterpret_cast<unsigned short*>(raw[2]);
    unsigned char* dLengths = reinterpret_cast<unsigned char*>(raw[3]);
    if (int s = check(d.cuMemcpyHtoD(raw[0], ids.data(), sizeof(int) * ids.size()), "uploading")) return release(s);
    if (int s = check(d.cuMemcpyHtoD(raw[1], entries, sizeof(int) * ids.size()), "uploading")) return release(s);
    if (int s = check(d.cuMemcpyHtoD(raw[2], units.data(), sizeof(uint16_t) * units.size()), "uploading")) return release(s);
    if (int s = check(d.cuMemcpyHtoD(raw[3], lengths.data(), lengths.size()), "uploading")) return release(s);
    void* args[] = {&cb->dev, &dIds, &dEntries, &dUnits, &dLengths, &count};
    if (int s = cb->launch(cb->reset, count, args)) return release(s);
    return release(cb->sync());
}

int cudaStepBuffers(psc_batch* b) {
    const DeviceBuffers& dev = of(b)->dev;
    return run(b, 1, dev.actions, 0, dev.rewards, dev.terminated, dev.truncated, dev.won, 1);
}

int cudaStepMany(psc_batch* b, int32_t steps, const int32_t* actions, float* rewards, uint8_t* terminated, uint8_t* truncated,
                 uint8_t* won) {
    return run(b, steps, actions, 0, rewards, terminated, truncated, won, 1);
}

int cudaStep(psc_batch* b, const int32_t* actions, psc_step_result* results) {
    const GameModule& g = game();
    CudaBatch* cb = of(b);
    Driver& d = driver();
    ContextScope scope(cb->context);
    const size_t n = static_cast<size_t>(b->numEnvs);
    if (int s = check(d.cuMemcpyHtoD(address(cb->dev.actions), actions, sizeof(int32_t) * n), "uploading actions")) return s;
    if (int s = cudaStepBuffers(b)) return s;
    unsigned long long counts[4];
    if (int s = readCounters(b, counts)) return s;
    if (!results) return PSC_OK;
    std::vector<float> rewards(n);
    std::vector<uint8_t> terminated(n), truncated(n), won(n);
    std::vector<int32_t> steps(n);
    int s = PSC_OK;
    if (!s) s = check(d.cuMemcpyDtoH(rewards.data(), address(cb->dev.rewards), sizeof(float) * n), "reading results");
    if (!s) s = check(d.cuMemcpyDtoH(terminated.data(), address(cb->dev.terminated), n), "reading results");
    if (!s) s = check(d.cuMemcpyDtoH(truncated.data(), address(cb->dev.truncated), n), "reading results");
    if (!s) s = check(d.cuMemcpyDtoH(won.data(), address(cb->dev.won), n), "reading results");
    if (!s) s = check(d.cuMemcpyDtoH(steps.data(), address(cb->dev.episodeSteps), sizeof(int32_t) * n), "reading results");
    if (s) return s;
    // A pending again turn and a rule's message live in the environments:
    // read them back only where they can be set.
    std::vector<uint64_t> envs;
    if (cb->againMode == PSC_AGAIN_ONE_TURN || g.info->rule_message_count > 0) {
        envs.resize(n * g.envBytes / 8);
        if (int r = check(d.cuMemcpyDtoH(envs.data(), address(cb->dev.envs), g.envBytes * n), "reading results")) return r;
    }
    for (size_t i = 0; i < n; ++i) {
        results[i] = psc_step_result{};
        results[i].message = -1;
        if (!envs.empty()) {
            EnvView v;
            g.view(reinterpret_cast<const char*>(envs.data()) + envOffset(static_cast<int>(i)), &v);
            results[i].againing = static_cast<uint8_t>(v.againing);
            results[i].message = static_cast<int16_t>(v.shownMessage);
        }
        results[i].reward = rewards[i];
        results[i].terminated = terminated[i];
        results[i].truncated = truncated[i];
        results[i].won = won[i];
        results[i].episode_steps = steps[i];
    }
    return PSC_OK;
}

int cudaObserve(psc_batch* b, uint8_t* observations, size_t size) {
    CudaBatch* cb = of(b);
    ContextScope scope(cb->context);
    void* args[] = {&cb->dev};
    if (int s = cb->launch(cb->observe, b->numEnvs, args)) return s;
    if (int s = cb->sync()) return s;
    const psc_game_info& info = *game().info;
    const size_t bytes = static_cast<size_t>(info.object_count) * static_cast<size_t>(info.max_width) *
                         static_cast<size_t>(info.max_height) * static_cast<size_t>(b->numEnvs);
    (void)size;  // checked by psc_observe
    return check(driver().cuMemcpyDtoH(observations, address(cb->dev.observations), bytes), "reading observations");
}

int cudaGetBuffers(psc_batch* b, psc_buffers* buffers) {
    *buffers = of(b)->buffers;
    return PSC_OK;
}

int cudaSetStream(psc_batch* b, void* stream) {
    of(b)->stream = stream;
    return PSC_OK;
}

int cudaSynchronize(psc_batch* b) {
    unsigned long long counts[4];
    return readCounters(b, counts);
}

int cudaRollout(psc_batch* b, int32_t steps, uint64_t seed, psc_rollout_stats* stats) {
    if (int s = run(b, steps, nullptr, seed, nullptr, nullptr, nullptr, nullptr, 0)) return s;
    if (!stats) return PSC_OK;
    unsigned long long counts[4];
    if (int s = readCounters(b, counts)) return s;
    stats->steps = static_cast<int64_t>(counts[0]);
    stats->wins = static_cast<int64_t>(counts[1]);
    stats->episodes = static_cast<int64_t>(counts[2]);
    return PSC_OK;
}

int cudaFetchEnv(const psc_batch* b, int env, void* out) {
    CudaBatch* cb = of(b);
    Driver& d = driver();
    ContextScope scope(cb->context);
    if (int s = cb->sync()) return s;
    return check(d.cuMemcpyDtoH(out, address(cb->dev.envs, envOffset(env)), game().envBytes), "reading an environment");
}

int cudaReadState(const psc_batch* b, int env, void* out, void* undo, int* undoCount) {
    *undoCount = 0;
    if (int s = cudaFetchEnv(b, env, out)) return s;
    CudaBatch* cb = of(b);
    if (!cb->dev.undoDepth) return PSC_OK;
    Driver& d = driver();
    ContextScope scope(cb->context);
    int count = 0;
    int head = 0;
    if (int s = check(d.cuMemcpyDtoH(&count, address(cb->dev.undoCount + env), sizeof(int)), "reading undo")) return s;
    if (int s = check(d.cuMemcpyDtoH(&head, address(cb->dev.undoHead + env), sizeof(int)), "reading undo")) return s;
    const size_t depth = static_cast<size_t>(cb->dev.undoDepth);
    const size_t snapshot = game().snapshotBytes;
    std::vector<uint64_t> ring(depth * snapshot / 8);
    const CUdeviceptr entries = address(cb->dev.undoEntries, depth * snapshot * static_cast<size_t>(env));
    if (int s = check(d.cuMemcpyDtoH(ring.data(), entries, snapshot * depth), "reading undo")) return s;
    for (int k = 0; k < count; ++k) {
        std::memcpy(static_cast<char*>(undo) + snapshot * static_cast<size_t>(k),
                    reinterpret_cast<const char*>(ring.data()) + snapshot * static_cast<size_t>((head + k) % cb->dev.undoDepth),
                    snapshot);
    }
    *undoCount = count;
    return PSC_OK;
}

int cudaWriteState(psc_batch* b, int env, const void* in, const void* undo, int undoCount) {
    CudaBatch* cb = of(b);
    Driver& d = driver();
    ContextScope scope(cb->context);
    if (int s = cb->sync()) return s;
    if (int s = check(d.cuMemcpyHtoD(address(cb->dev.envs, envOffset(env)), in, game().envBytes), "writing an environment")) return s;
    if (!cb->dev.undoDepth) return PSC_OK;
    const int head = 0;
    const size_t depth = static_cast<size_t>(cb->dev.undoDepth);
    const size_t snapshot = game().snapshotBytes;
    const CUdeviceptr entries = address(cb->dev.undoEntries, depth * snapshot * static_cast<size_t>(env));
    if (undoCount) {
        if (int s = check(d.cuMemcpyHtoD(entries, undo, snapshot * static_cast<size_t>(undoCount)), "writing undo")) return s;
    }
    if (int s = check(d.cuMemcpyHtoD(address(cb->dev.undoCount + env), &undoCount, sizeof(int)), "writing undo")) return s;
    return check(d.cuMemcpyHtoD(address(cb->dev.undoHead + env), &head, sizeof(int)), "writing undo");
}

// Whether the driver knows `p` (device memory, or host memory registered
// with CUDA; null passes): a kernel handed other host memory fails with a
// launch error, which ends the batch's context.
int checkDeviceMemory(const void* p, const char* name) {
    unsigned type = 0;
    if (!p || driver().cuPointerGetAttribute(&type, kPointerMemoryType, address(p)) == 0) return PSC_OK;
    return fail(PSC_ERROR_BAD_ARGUMENT, std::string(name) + " is not memory the GPU can read: a CUDA batch expands "
                                        "from and into device memory (psc_device_alloc)");
}

int cudaExpand(psc_batch* b, int32_t templateEnv, const void* keys, int32_t count, const int32_t* actions, int32_t actionCount,
               void* children, uint8_t* flags, uint64_t* hashes, int32_t* estimates) {
    const DeviceCode& code = *game().device;
    if (!code.searchKernels) {
        return fail(PSC_ERROR_BACKEND_UNAVAILABLE,
                    "this plugin was built without search's GPU kernel (psc --search-kernels); CPU batches expand states");
    }
    if (code.expandTooLarge) {
        return fail(PSC_ERROR_DEVICE, "this game's environments (" + std::to_string(game().envBytes) +
                                          " bytes) are too large to expand on the GPU: use the CPU backend");
    }
    const long long pairs = static_cast<long long>(count) * actionCount;
    if (pairs > INT32_MAX) return fail(PSC_ERROR_BAD_ARGUMENT, "count * action_count must be below 2^31");
    int n = static_cast<int>(pairs);
    CudaBatch* cb = of(b);
    ContextScope scope(cb->context);
    const std::pair<const void*, const char*> pointers[] = {{keys, "keys"},     {actions, "actions"},     {children, "children"},
                                                            {flags, "flags"},   {hashes, "hashes"},       {estimates, "estimates"}};
    for (const auto& [pointer, name] : pointers) {
        if (int s = checkDeviceMemory(pointer, name)) return s;
    }
    unsigned long long deadline = 0;
    if (b->expandDeadline) {
        if (int s = cb->measureGpuClock()) return s;
        deadline = static_cast<unsigned long long>(std::max<int64_t>(1, b->expandDeadline + cb->gpuClockOffset));
    }
    void* args[] = {&cb->dev, &templateEnv, &keys, &count, &actions, &actionCount, &children, &flags, &hashes, &estimates,
                    &deadline};
    return cb->launch(cb->expand, n, args);
}

int cudaAlloc(psc_batch* b, size_t bytes, void** pointer) {
    ContextScope scope(of(b)->context);
    CUdeviceptr p = 0;
    if (int s = check(driver().cuMemAlloc(&p, std::max<size_t>(bytes, 1)), "allocating device memory")) return s;
    *pointer = reinterpret_cast<void*>(p);
    return PSC_OK;
}

int cudaFree(psc_batch* b, void* pointer) {
    ContextScope scope(of(b)->context);
    return check(driver().cuMemFree(address(pointer)), "freeing device memory");
}

int cudaCopy(psc_batch* b, void* destination, const void* source, size_t bytes) {
    CudaBatch* cb = of(b);
    ContextScope scope(cb->context);
    if (int s = cb->sync()) return s;
    return check(driver().cuMemcpy(address(destination), address(source), bytes), "copying memory");
}

}  // namespace psc_host
