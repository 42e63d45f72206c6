// StackStride: the CUDA stack limits a large batch times when it is created,
// and the one it keeps (CudaBackend.cpp's tuneStackStride).  The limit is
// each thread's stride in local memory, which moves a kernel's speed by more
// than any rule known before a run predicts (docs/performance.md, "The
// stack's stride").
#pragma once

#include <stddef.h>

#include <algorithm>
#include <vector>

namespace psc_host {

// The limits timed: the kernels' bound, 128, 256 and 512 bytes over it, and
// the power of two at or above it; none below what the context has, which
// its other batches may need; ascending, without repeats.
inline std::vector<size_t> strideCandidates(size_t bound, size_t contextLimit) {
    size_t power = 1;
    while (power < bound) power *= 2;
    std::vector<size_t> limits;
    for (size_t limit : {bound, bound + 128, bound + 256, bound + 512, power}) limits.push_back(std::max(limit, contextLimit));
    std::sort(limits.begin(), limits.end());
    limits.erase(std::unique(limits.begin(), limits.end()), limits.end());
    return limits;
}

// A higher limit is kept only where it took at most this share of the
// lowest's time: closer than that is the timing's noise (kettle's timed
// limits differ by 1-2 % and step alike).
constexpr double kStrideMargin = 0.97;

// Of the candidates' times, in strideCandidates' order, the one kept.
inline size_t keptStride(const std::vector<double>& seconds) {
    const size_t fastest = static_cast<size_t>(std::min_element(seconds.begin(), seconds.end()) - seconds.begin());
    return seconds[fastest] < kStrideMargin * seconds[0] ? fastest : 0;
}

// Steps a timed launch takes, from one step's time.  Every launch also loads
// and stores each environment it steps (for limerick's 16,384, about 0.2 ms,
// the time of some 20 steps), a cost that the stride moves otherwise and that
// hides its effect on stepping in a short launch: at 9 steps a launch limerick
// kept its bound, 1.33x slower at large batches than the 4,096 bytes that 51
// steps a launch kept.  So at least 64 steps, about 4 ms, at most 256.
inline int timedStepCount(double stepSeconds) {
    return static_cast<int>(std::clamp(4e-3 / std::max(stepSeconds, 1e-6), 64.0, 256.0));
}

// A step slower than this keeps the bound untimed: 11 launches of 64 such
// steps would add seconds to the batch's creation.
constexpr double kMaxTimedStepSeconds = 2.5e-3;

}  // namespace psc_host
