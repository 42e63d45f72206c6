// ---- psc template: the CUDA backend's host side ----------------------------
// Loads the game's kernels (cubin for the device's architecture, else PTX)
// with the CUDA driver API, found at run time with dlopen so that the plugin
// also loads on machines without a GPU, and keeps the batch in device memory.
// Expects psc_device_cubin, psc_device_ptx (PTX per compile unit) and their
// sizes declared above, and defined by the plugin's device code source.

#include <dlfcn.h>

#include <cstdlib>

struct psc_batch;

namespace psc_game {
namespace cuda {

typedef int CUresult;
typedef int CUdevice;
typedef void* CUcontext;
typedef void* CUmodule;
typedef void* CUfunction;
typedef void* CUstream;
typedef unsigned long long CUdeviceptr;
typedef void* CUlinkState;
constexpr int kJitInputPtx = 1;  // CU_JIT_INPUT_PTX

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

// The game's kernels: the cubin, or, on another architecture (or with
// PSC_CUDA_FROM_PTX=1, which tests this path), the PTX compiled by the driver
// and, from several compile units, linked by it.
CUresult loadModule(CUmodule* module) {
    Driver& d = driver();
    const char* fromPtx = std::getenv("PSC_CUDA_FROM_PTX");
    if (!(fromPtx && *fromPtx && *fromPtx != '0') && d.cuModuleLoadData(module, psc_device_cubin) == 0) return 0;
    if (psc_device_ptx_units == 1) return d.cuModuleLoadData(module, psc_device_ptx);
    CUlinkState link = nullptr;
    CUresult r = d.cuLinkCreate(0, nullptr, nullptr, &link);
    const unsigned char* ptx = psc_device_ptx;
    for (int k = 0; r == 0 && k < psc_device_ptx_units; ptx += psc_device_ptx_bytes[k] + 1, ++k) {
        const std::string name = "unit" + std::to_string(k) + ".ptx";
        r = d.cuLinkAddData(link, kJitInputPtx, const_cast<unsigned char*>(ptx), psc_device_ptx_bytes[k] + 1, name.c_str(),
                            0, nullptr, nullptr);
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

struct Batch {
    CUdevice device = 0;
    CUcontext context = nullptr;
    CUmodule module = nullptr;
    CUfunction reset = nullptr;
    CUfunction run = nullptr;
    CUfunction observe = nullptr;
    CUfunction expand = nullptr;
    CUstream stream = nullptr;
    DeviceBatch dev{};
    std::vector<CUdeviceptr> allocations;
    psc_buffers buffers{};
    int autoReset = 0;
    int againMode = 0;
    int maxEpisodeSteps = 0;
    unsigned long long rolloutSteps = 0;  // steps run by rollouts so far (the random actions' counter)
    static constexpr unsigned kBlock = 128;  // threads a block of every kernel but a shared-memory stepping one
    unsigned runBlock = kBlock;              // the stepping kernel's threads a block
    unsigned runShared = 0;                  // and dynamic shared memory a block (PSC_STATE_IN_SHARED)

    ~Batch() {
        Driver& d = driver();
        ContextScope scope(context);
        for (CUdeviceptr p : allocations) d.cuMemFree(p);
        if (module) d.cuModuleUnload(module);
        if (context) d.cuDevicePrimaryCtxRelease(device);
    }
    template <typename T>
    int allocate(T** out, size_t count) {
        CUdeviceptr p = 0;
        if (int s = check(driver().cuMemAlloc(&p, std::max<size_t>(1, count * sizeof(T))), "allocating device memory")) return s;
        allocations.push_back(p);
        *out = reinterpret_cast<T*>(p);
        return check(driver().cuMemsetD8(p, 0, std::max<size_t>(1, count * sizeof(T))), "clearing device memory");
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
        const unsigned warps = std::min(4u, static_cast<unsigned>(limit) / (32 * kSharedEnvStride));
        if (warps == 0) {
            return fail(PSC_ERROR_DEVICE, "a warp's environments need " + std::to_string(32 * kSharedEnvStride) +
                                              " bytes of shared memory, over the " + std::to_string(limit) +
                                              " a block may have: build with --gpu-state memory");
        }
        runBlock = 32 * warps;
        runShared = runBlock * kSharedEnvStride;
        return check(driver().cuFuncSetAttribute(run, kMaxDynamicShared, static_cast<int>(runShared)),
                     "reserving shared memory for the environments");
    }
    int sync() { return check(driver().cuStreamSynchronize(stream), "waiting for the device"); }
};

Batch* of(const psc_batch* b);

}  // namespace cuda
}  // namespace psc_game

static bool psc_cuda_owns(const psc_batch* b);

static int psc_cuda_batch_create(const psc_batch_options* options, psc_batch** out);
static bool psc_cuda_batch_destroy(psc_batch* b);
static int psc_cuda_reset_entries(psc_batch* b, const int32_t* envIds, int32_t count, const int32_t* entries,
                                  const std::vector<std::u16string>& seeds);
static int psc_cuda_reset(psc_batch* b, const int32_t* envIds, int32_t count, const int32_t* levels, const uint64_t* seeds);
static int psc_cuda_step(psc_batch* b, const int32_t* actions, psc_step_result* results);
static int psc_cuda_step_many(psc_batch* b, int32_t steps, const int32_t* actions, float* rewards, uint8_t* terminated,
                              uint8_t* truncated, uint8_t* won);
static int psc_cuda_observe(psc_batch* b, uint8_t* observations, size_t size);
static int psc_cuda_get_buffers(psc_batch* b, psc_buffers* buffers);
static int psc_cuda_step_buffers(psc_batch* b);
static int psc_cuda_set_stream(psc_batch* b, void* stream);
static int psc_cuda_synchronize(psc_batch* b);
static int psc_cuda_rollout(psc_batch* b, int32_t steps, uint64_t seed, psc_rollout_stats* stats);
static int psc_cuda_fetch_env(const psc_batch* b, int env, psc_game::Env* out);
static int psc_cuda_read_state(const psc_batch* b, int env, psc_game::Env* out, std::vector<psc_game::Snapshot>& undo);
static int psc_cuda_write_state(psc_batch* b, int env, const psc_game::Env& in, const std::vector<psc_game::Snapshot>& undo);
static int psc_cuda_expand(psc_batch* b, int32_t templateEnv, const void* keys, int32_t count, const int32_t* actions,
                           int32_t actionCount, void* children, uint8_t* flags, uint64_t* hashes, int32_t* estimates);
static int psc_cuda_alloc(psc_batch* b, size_t bytes, void** pointer);
static int psc_cuda_free(psc_batch* b, void* pointer);
static int psc_cuda_copy(psc_batch* b, void* destination, const void* source, size_t bytes);
