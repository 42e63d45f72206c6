#include "ExpandDeadline.h"

#include <chrono>

namespace psc_host {
namespace {

thread_local int64_t threadDeadline = 0;

}  // namespace

int64_t steadyNanoseconds() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

ExpandDeadlineScope::ExpandDeadlineScope(int64_t deadline) : previous_(threadDeadline) { threadDeadline = deadline; }

ExpandDeadlineScope::~ExpandDeadlineScope() { threadDeadline = previous_; }

bool expandDeadlinePassed() { return threadDeadline != 0 && steadyNanoseconds() >= threadDeadline; }

}  // namespace psc_host
