#include "ExpandDeadline.h"

#include <chrono>

namespace psc_host {

int64_t steadyNanoseconds() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace psc_host
