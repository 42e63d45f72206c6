// ExpandDeadline: the deadline of the psc_expand running on this thread
// (psc_set_deadline).  The engine's again loop reads it on CPU plugins
// (templates/engine.h), so that one input's long chain does not keep a
// search far past its time limit.
#pragma once

#include <stdint.h>

namespace psc_host {

int64_t steadyNanoseconds();

// Sets this thread's deadline (steady-clock nanoseconds, 0: none) for its lifetime.
class ExpandDeadlineScope {
public:
    explicit ExpandDeadlineScope(int64_t deadline);
    ~ExpandDeadlineScope();
    ExpandDeadlineScope(const ExpandDeadlineScope&) = delete;
    ExpandDeadlineScope& operator=(const ExpandDeadlineScope&) = delete;

private:
    int64_t previous_;
};

// Whether this thread has a deadline and it has passed.
bool expandDeadlinePassed();

}  // namespace psc_host
