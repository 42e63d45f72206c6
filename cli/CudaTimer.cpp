#include "CudaTimer.h"

#include <dlfcn.h>

namespace psc::cli {
namespace {

struct Driver {
    int (*cuInit)(unsigned) = nullptr;
    int (*cuDeviceGet)(int*, int) = nullptr;
    int (*cuDevicePrimaryCtxRetain)(void**, int) = nullptr;
    int (*cuCtxPushCurrent)(void*) = nullptr;
    int (*cuCtxPopCurrent)(void**) = nullptr;
    int (*cuEventCreate)(void**, unsigned) = nullptr;
    int (*cuEventRecord)(void*, void*) = nullptr;
    int (*cuEventSynchronize)(void*) = nullptr;
    int (*cuEventElapsedTime)(float*, void*, void*) = nullptr;
};

Driver* driver() {
    static Driver d;
    static bool tried = false;
    static bool ok = false;
    if (!tried) {
        tried = true;
        void* lib = dlopen("libcuda.so.1", RTLD_NOW | RTLD_LOCAL);
        if (lib) {
            d.cuInit = reinterpret_cast<decltype(d.cuInit)>(dlsym(lib, "cuInit"));
            d.cuDeviceGet = reinterpret_cast<decltype(d.cuDeviceGet)>(dlsym(lib, "cuDeviceGet"));
            d.cuDevicePrimaryCtxRetain = reinterpret_cast<decltype(d.cuDevicePrimaryCtxRetain)>(dlsym(lib, "cuDevicePrimaryCtxRetain"));
            d.cuCtxPushCurrent = reinterpret_cast<decltype(d.cuCtxPushCurrent)>(dlsym(lib, "cuCtxPushCurrent_v2"));
            d.cuCtxPopCurrent = reinterpret_cast<decltype(d.cuCtxPopCurrent)>(dlsym(lib, "cuCtxPopCurrent_v2"));
            d.cuEventCreate = reinterpret_cast<decltype(d.cuEventCreate)>(dlsym(lib, "cuEventCreate"));
            d.cuEventRecord = reinterpret_cast<decltype(d.cuEventRecord)>(dlsym(lib, "cuEventRecord"));
            d.cuEventSynchronize = reinterpret_cast<decltype(d.cuEventSynchronize)>(dlsym(lib, "cuEventSynchronize"));
            d.cuEventElapsedTime = reinterpret_cast<decltype(d.cuEventElapsedTime)>(dlsym(lib, "cuEventElapsedTime_v2"));
            if (!d.cuEventElapsedTime) d.cuEventElapsedTime = reinterpret_cast<decltype(d.cuEventElapsedTime)>(dlsym(lib, "cuEventElapsedTime"));
            ok = d.cuInit && d.cuDeviceGet && d.cuDevicePrimaryCtxRetain && d.cuCtxPushCurrent && d.cuCtxPopCurrent && d.cuEventCreate &&
                 d.cuEventRecord && d.cuEventSynchronize && d.cuEventElapsedTime;
        }
    }
    return ok ? &d : nullptr;
}

// Runs f with `context` current, then gives the caller's context back.
template <typename F>
void inContext(void* context, F f) {
    void* popped = nullptr;
    driver()->cuCtxPushCurrent(context);
    f();
    driver()->cuCtxPopCurrent(&popped);
}

}  // namespace

std::optional<CudaTimer> CudaTimer::create(int device, std::string* error) {
    Driver* d = driver();
    if (!d) {
        *error = "the CUDA driver is not available";
        return std::nullopt;
    }
    int dev = 0;
    void* ctx = nullptr;
    if (d->cuInit(0) || d->cuDeviceGet(&dev, device) || d->cuDevicePrimaryCtxRetain(&ctx, dev)) {
        *error = "no usable CUDA device " + std::to_string(device);
        return std::nullopt;
    }
    CudaTimer t;
    t.context_ = ctx;
    bool created = false;
    inContext(ctx, [&] { created = !d->cuEventCreate(&t.begin_, 0) && !d->cuEventCreate(&t.end_, 0); });
    if (!created) {
        *error = "cannot create CUDA events";
        return std::nullopt;
    }
    return t;
}

// Events go on the default stream of the timer's device, whatever context the caller has current.
void CudaTimer::start() {
    inContext(context_, [&] { driver()->cuEventRecord(begin_, nullptr); });
}

double CudaTimer::stop() {
    Driver* d = driver();
    inContext(context_, [&] { d->cuEventRecord(end_, nullptr); });
    d->cuEventSynchronize(end_);
    float ms = 0;
    d->cuEventElapsedTime(&ms, begin_, end_);
    return ms;
}

}  // namespace psc::cli
