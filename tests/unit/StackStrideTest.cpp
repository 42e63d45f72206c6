#include <catch2/catch.hpp>

#include <vector>

#include "plugin_host/StackStride.h"

using psc_host::keptStride;
using psc_host::strideCandidates;

TEST_CASE("the stack limits a batch times: its bound, 128, 256 and 512 bytes over it, and the power of two", "[stack]") {
    // limerick's kernels' bound, in a context at the driver's default of 1,024 bytes
    CHECK(strideCandidates(3504, 1024) == std::vector<size_t>{3504, 3632, 3760, 4016, 4096});
    // a bound that is a power of two appears once
    CHECK(strideCandidates(4096, 1024) == std::vector<size_t>{4096, 4224, 4352, 4608});
}

TEST_CASE("no stack limit timed is below the context's, which other batches may need", "[stack]") {
    // kettle's second batch, after the first had kept 2,808 bytes
    CHECK(strideCandidates(2680, 2808) == std::vector<size_t>{2808, 2936, 3192, 4096});
    CHECK(strideCandidates(2680, 8192) == std::vector<size_t>{8192});
}

TEST_CASE("a higher stack limit is kept only where it is more than 3 % faster than the lowest", "[stack]") {
    CHECK(keptStride({1.0, 0.98, 0.99, 1.02}) == 0);  // within the timing's noise
    CHECK(keptStride({0.856, 0.850, 0.717, 0.7065, 0.7075}) == 3);  // limerick's times, ms
    CHECK(keptStride({1.0, 0.5, 0.96}) == 1);
    CHECK(keptStride({0.9, 1.2, 1.1}) == 0);
}

TEST_CASE("a timed launch takes at least 64 steps, about 4 ms of them, at most 256", "[stack]") {
    using psc_host::timedStepCount;
    CHECK(timedStepCount(0.22e-3) == 64);  // limerick's first step over 16,384, its launch's loads and stores in it
    CHECK(timedStepCount(0.02e-3) == 200);
    CHECK(timedStepCount(1e-9) == 256);
    CHECK(timedStepCount(2.4e-3) == 64);  // the slowest step still timed
}
