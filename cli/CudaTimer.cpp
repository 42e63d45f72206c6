#include "CudaTimer.h"

#include "CudaDriver.h"

namespace psc::cli {

std::optional<CudaTimer> CudaTimer::create(int device, std::string* error) {
    const CudaDriver* d = cudaDriver(error);
    if (!d) return std::nullopt;
    int dev = 0;
    void* ctx = nullptr;
    if (d->cuDeviceGet(&dev, device) || d->cuDevicePrimaryCtxRetain(&ctx, dev)) {
        *error = "no usable CUDA device " + std::to_string(device);
        return std::nullopt;
    }
    CudaTimer t;
    t.context_ = ctx;
    CudaContextScope scope(ctx);
    if (d->cuEventCreate(&t.begin_, 0) || d->cuEventCreate(&t.end_, 0)) {
        *error = "cannot create CUDA events";
        return std::nullopt;
    }
    return t;
}

// Events go on the default stream of the timer's device, whatever context the caller has current.
void CudaTimer::start() {
    CudaContextScope scope(context_);
    cudaDriver()->cuEventRecord(begin_, nullptr);
}

double CudaTimer::stop() {
    const CudaDriver* d = cudaDriver();
    {
        CudaContextScope scope(context_);
        d->cuEventRecord(end_, nullptr);
    }
    d->cuEventSynchronize(end_);
    float ms = 0;
    d->cuEventElapsedTime(&ms, begin_, end_);
    return ms;
}

}  // namespace psc::cli
