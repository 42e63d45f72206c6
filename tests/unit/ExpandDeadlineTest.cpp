#include <catch2/catch.hpp>

#include "plugin_host/ExpandDeadline.h"

using psc_host::DeadlineWatch;
using psc_host::steadyNanoseconds;

namespace {

// Busy until `nanoseconds` have passed on the watch's clock: a slow child.
void spin(int64_t nanoseconds) {
    const int64_t until = steadyNanoseconds() + nanoseconds;
    while (steadyNanoseconds() < until) {
    }
}

}  // namespace

TEST_CASE("no deadline never passes; one already past passes at the first child", "[deadline]") {
    DeadlineWatch none(0);
    for (int i = 0; i < 100; ++i) CHECK_FALSE(none.passed());
    DeadlineWatch past(steadyNanoseconds() - 1);
    CHECK(past.passed());
    CHECK(past.passed());  // and stays passed
}

TEST_CASE("while children are slow, the deadline is noticed at the first child after it", "[deadline]") {
    const int64_t deadline = steadyNanoseconds() + 2'000'000;
    DeadlineWatch watch(deadline);
    int lateChildren = 0;
    for (int child = 0; child < 100; ++child) {
        const bool afterDeadline = steadyNanoseconds() >= deadline;
        const bool passed = watch.passed();
        if (afterDeadline && !passed) ++lateChildren;
        if (passed) break;
        spin(100'000);  // each child 0.1 ms: the clock is read at every one
    }
    CHECK(lateChildren == 0);
}

TEST_CASE("while children are fast, the deadline is noticed at most 16 children after it", "[deadline]") {
    const int64_t deadline = steadyNanoseconds() + 2'000'000;
    DeadlineWatch watch(deadline);
    int lateChildren = 0;
    bool passed = false;
    for (int child = 0; child < 100'000'000 && !passed; ++child) {
        const bool afterDeadline = steadyNanoseconds() >= deadline;
        passed = watch.passed();
        if (afterDeadline && !passed) ++lateChildren;
    }
    CHECK(passed);
    CHECK(lateChildren <= 16);
}
