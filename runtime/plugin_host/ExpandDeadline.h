// ExpandDeadline: the clock of psc_set_deadline's deadlines on CPU batches.
// psc_expand passes its batch's deadline down to the engine, whose again loop
// reads this clock (templates/engine.h, deadlineClock), so that one input's
// long chain does not keep a search far past its time limit.
#pragma once

#include <stdint.h>

namespace psc_host {

// The steady clock, in nanoseconds.
int64_t steadyNanoseconds();

// Whether a deadline (0: none) has passed, asked before each child of a loop
// over children.  A read of the clock cost as much as a twentieth of a small
// child (5 % of limerick's breadth-first search when read for every child),
// so while children prove fast (under kFastChild nanoseconds each since the
// last read) the clock is read at every second, fourth, ... up to every
// kMostUnread-th child, and at every child again once one is slow: a
// deadline is noticed at most about kMostUnread fast children late.
class DeadlineWatch {
public:
    explicit DeadlineWatch(int64_t deadline) : deadline_(deadline), last_(deadline ? steadyNanoseconds() : 0) {}
    bool passed() {
        if (deadline_ == 0 || passed_) return passed_;
        if (--untilRead_ > 0) return false;
        const int64_t now = steadyNanoseconds();
        passed_ = now >= deadline_;
        every_ = now - last_ < kFastChild * every_ ? (every_ < kMostUnread ? 2 * every_ : kMostUnread) : 1;
        untilRead_ = every_;
        last_ = now;
        return passed_;
    }

private:
    static constexpr int64_t kFastChild = 2000;
    static constexpr int kMostUnread = 16;
    int64_t deadline_;
    int64_t last_;
    int every_ = 1;
    int untilRead_ = 0;
    bool passed_ = false;
};

}  // namespace psc_host
