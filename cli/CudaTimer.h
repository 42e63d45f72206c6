// Timing device work with CUDA events on the default stream of one device's
// primary context (the one psc plugins use), through the driver found at run time.
#pragma once

#include <optional>
#include <string>

namespace psc::cli {

class CudaTimer {
public:
    // Null when no CUDA driver or device is usable; *error says why.
    static std::optional<CudaTimer> create(int device, std::string* error);
    void start();
    // Milliseconds since start(), after the device finished the work queued since.
    double stop();

private:
    CudaTimer() = default;
    void* context_ = nullptr;  // the device's primary context
    void* begin_ = nullptr;
    void* end_ = nullptr;
};

}  // namespace psc::cli
