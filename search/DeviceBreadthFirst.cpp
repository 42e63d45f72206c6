// Breadth-first and beam search with their states on the GPU: as
// BreadthFirst.cpp and BeamSearch.cpp, layer by layer and a child tested for
// a win when generated, but the states stay in a DeviceStateSet, where each
// layer is expanded in batches straight from its key window.  Each finds the
// same solution as its host search (the stores hold the same states, and a
// layer the same states in the same order); the host only reads each
// batch's outcome, and for a beam each layer's histogram of estimates.
// Batches are sized to the time left, as the host searches' are.
#include "DeviceStateSet.h"
#include "SearchRun.h"

namespace psc::search {
namespace {

// Breadth-first, each layer cut to `width` states if not 0 (beam search).
SolveResult deviceLayers(SearchRun& run, size_t width) {
    StateSpace& space = run.space;
    DeviceStateSet set(space, run.options().maxMemory, width != 0);
    auto memoryFull = [&] {
        run.result.limit = "memory";
        return run.finish(Status::Limit, set.size(), set.bytes());
    };
    if (!set.addRoot()) return memoryFull();
    if (space.rootWon()) return run.solved({}, -1, set.size(), set.bytes());
    for (uint32_t depth = 0;; ++depth) {
        if (!set.beginLayer(width)) return memoryFull();
        if (set.layerSize() == 0) break;
        for (size_t begin = 0; begin < set.layerSize();) {
            if (run.stopped(set.size())) return run.finish(Status::Limit, set.size(), set.bytes());
            const size_t count = set.room(run.batchWithinTime(std::min(space.maxBatch(), set.layerSize() - begin)));
            if (count == 0) return memoryFull();
            const double began = run.elapsed();
            space.setDeadline(run.timeLeft());
            const DeviceStateSet::Outcome o = set.expand(begin, count);
            run.countExpansion(count, began);
            if (o.won) return run.solved(set.path(o.parent), o.input, set.size(), set.bytes());
            if (o.full) return memoryFull();
            if (o.timedOut) {
                run.result.limit = "time";
                return run.finish(Status::Limit, set.size(), set.bytes());
            }
            begin += count;
            run.reportProgress(static_cast<int>(depth), set.size(), set.bytes());
        }
    }
    // A beam that dropped states and then emptied has not seen every state.
    if (!set.dropped()) return run.finish(Status::Exhausted, set.size(), set.bytes());
    run.result.limit = "beam";
    return run.finish(Status::Limit, set.size(), set.bytes());
}

}  // namespace

SolveResult deviceBreadthFirst(SearchRun& run) { return deviceLayers(run, 0); }

SolveResult deviceBeamSearch(SearchRun& run, size_t width) { return deviceLayers(run, width); }

}  // namespace psc::search
