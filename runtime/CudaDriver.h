// The CUDA driver API as psc itself uses it (timing benchmarks, search's
// duplicate detection on the GPU), found at run time: psc starts on machines
// without a driver, and says so only when device work is asked for.  Plugins
// carry their own loader (plugin_host/CudaBackend.cpp); both work in the
// device's primary context, so device memory and streams pass between them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace psc {

using CuResult = int;
using CuDevicePtr = unsigned long long;
using CuContext = void*;
using CuModule = void*;
using CuFunction = void*;
using CuStream = void*;
using CuEvent = void*;

struct CudaDriver {
    CuResult (*cuInit)(unsigned);
    CuResult (*cuDeviceGet)(int*, int);
    CuResult (*cuDeviceGetAttribute)(int*, int, int);
    CuResult (*cuDevicePrimaryCtxRetain)(CuContext*, int);
    CuResult (*cuDevicePrimaryCtxRelease)(int);
    CuResult (*cuCtxPushCurrent)(CuContext);
    CuResult (*cuCtxPopCurrent)(CuContext*);
    CuResult (*cuGetErrorString)(CuResult, const char**);
    CuResult (*cuMemGetInfo)(size_t*, size_t*);
    CuResult (*cuMemAlloc)(CuDevicePtr*, size_t);
    CuResult (*cuMemFree)(CuDevicePtr);
    CuResult (*cuMemcpyHtoD)(CuDevicePtr, const void*, size_t);
    CuResult (*cuMemcpyDtoH)(void*, CuDevicePtr, size_t);
    CuResult (*cuMemcpyDtoD)(CuDevicePtr, CuDevicePtr, size_t);
    CuResult (*cuMemsetD32Async)(CuDevicePtr, unsigned, size_t, CuStream);
    CuResult (*cuModuleLoadData)(CuModule*, const void*);
    CuResult (*cuModuleUnload)(CuModule);
    CuResult (*cuModuleGetFunction)(CuFunction*, CuModule, const char*);
    CuResult (*cuLaunchKernel)(CuFunction, unsigned, unsigned, unsigned, unsigned, unsigned, unsigned, unsigned,
                               CuStream, void**, void**);
    CuResult (*cuStreamCreate)(CuStream*, unsigned);
    CuResult (*cuStreamDestroy)(CuStream);
    CuResult (*cuStreamSynchronize)(CuStream);
    CuResult (*cuEventCreate)(CuEvent*, unsigned);
    CuResult (*cuEventRecord)(CuEvent, CuStream);
    CuResult (*cuEventSynchronize)(CuEvent);
    CuResult (*cuEventElapsedTime)(float*, CuEvent, CuEvent);
};

// The driver, initialised; null when libcuda cannot be loaded or initialised
// (*problem then says why, when given).
const CudaDriver* cudaDriver(std::string* problem = nullptr);

// `what` and the driver's name for a failed result, as an error message.
std::string cudaErrorText(CuResult result, const std::string& what);

// Makes a context current for the scope, and the caller's current again after it.
class CudaContextScope {
public:
    explicit CudaContextScope(CuContext context);
    ~CudaContextScope();
    CudaContextScope(const CudaContextScope&) = delete;
    CudaContextScope& operator=(const CudaContextScope&) = delete;
};

}  // namespace psc
