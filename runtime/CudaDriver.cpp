#include "CudaDriver.h"

#include <dlfcn.h>

namespace psc {
namespace {

struct Loaded {
    CudaDriver driver{};
    std::string problem;
};

template <typename F>
bool bind(void* lib, F& f, const char* name, const char* fallback = nullptr) {
    void* p = dlsym(lib, name);
    if (!p && fallback) p = dlsym(lib, fallback);
    f = reinterpret_cast<F>(p);
    return p != nullptr;
}

Loaded load() {
    Loaded l;
    void* lib = dlopen("libcuda.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        l.problem = "the CUDA driver (libcuda.so.1) is not available";
        return l;
    }
    CudaDriver& d = l.driver;
    // The _v2 names are the 64-bit versions the CUDA headers map the plain names to.
    const bool ok = bind(lib, d.cuInit, "cuInit") && bind(lib, d.cuDeviceGet, "cuDeviceGet") &&
                    bind(lib, d.cuDeviceGetAttribute, "cuDeviceGetAttribute") &&
                    bind(lib, d.cuDevicePrimaryCtxRetain, "cuDevicePrimaryCtxRetain") &&
                    bind(lib, d.cuDevicePrimaryCtxRelease, "cuDevicePrimaryCtxRelease_v2", "cuDevicePrimaryCtxRelease") &&
                    bind(lib, d.cuCtxPushCurrent, "cuCtxPushCurrent_v2") && bind(lib, d.cuCtxPopCurrent, "cuCtxPopCurrent_v2") &&
                    bind(lib, d.cuGetErrorString, "cuGetErrorString") && bind(lib, d.cuMemGetInfo, "cuMemGetInfo_v2") &&
                    bind(lib, d.cuMemAlloc, "cuMemAlloc_v2") && bind(lib, d.cuMemFree, "cuMemFree_v2") &&
                    bind(lib, d.cuMemcpyHtoD, "cuMemcpyHtoD_v2") && bind(lib, d.cuMemcpyDtoH, "cuMemcpyDtoH_v2") &&
                    bind(lib, d.cuMemcpyDtoD, "cuMemcpyDtoD_v2") &&
                    bind(lib, d.cuMemsetD32Async, "cuMemsetD32Async") && bind(lib, d.cuModuleLoadData, "cuModuleLoadData") &&
                    bind(lib, d.cuModuleUnload, "cuModuleUnload") && bind(lib, d.cuModuleGetFunction, "cuModuleGetFunction") &&
                    bind(lib, d.cuLaunchKernel, "cuLaunchKernel") && bind(lib, d.cuStreamCreate, "cuStreamCreate") &&
                    bind(lib, d.cuStreamDestroy, "cuStreamDestroy_v2", "cuStreamDestroy") &&
                    bind(lib, d.cuStreamSynchronize, "cuStreamSynchronize") && bind(lib, d.cuEventCreate, "cuEventCreate") &&
                    bind(lib, d.cuEventRecord, "cuEventRecord") && bind(lib, d.cuEventSynchronize, "cuEventSynchronize") &&
                    bind(lib, d.cuEventElapsedTime, "cuEventElapsedTime_v2", "cuEventElapsedTime");
    if (!ok) {
        l.problem = "the CUDA driver (libcuda.so.1) lacks a function psc needs: it is older than CUDA 12";
    } else if (const CuResult r = d.cuInit(0)) {
        l.problem = cudaErrorText(r, "initialising the CUDA driver");
    }
    return l;
}

}  // namespace

const CudaDriver* cudaDriver(std::string* problem) {
    static const Loaded loaded = load();
    if (problem) *problem = loaded.problem;
    return loaded.problem.empty() ? &loaded.driver : nullptr;
}

std::string cudaErrorText(CuResult result, const std::string& what) {
    const char* text = nullptr;
    // Before the driver is loaded (or when it is not) there is only the number.
    void* lib = dlopen("libcuda.so.1", RTLD_NOW | RTLD_LOCAL | RTLD_NOLOAD);
    if (lib) {
        CuResult (*getErrorString)(CuResult, const char**) = nullptr;
        if (bind(lib, getErrorString, "cuGetErrorString")) getErrorString(result, &text);
        dlclose(lib);
    }
    return what + ": " + (text ? text : "CUDA error " + std::to_string(result));
}

CudaContextScope::CudaContextScope(CuContext context) { cudaDriver()->cuCtxPushCurrent(context); }

CudaContextScope::~CudaContextScope() {
    CuContext popped = nullptr;
    cudaDriver()->cuCtxPopCurrent(&popped);
}

}  // namespace psc
