// Breadth-first search with its states on the GPU: as BreadthFirst.cpp, layer
// by layer and a child tested for a win when generated, but the states stay
// in a DeviceStateSet, where each layer is a contiguous range expanded in
// batches straight from its key window.  It finds the same solution as the host
// search (the stores hold the same states in the same order); the host only
// reads each batch's outcome.  Batches are sized to the time left, as the
// host searches' are.
#include "DeviceStateSet.h"
#include "SearchRun.h"

namespace psc::search {

SolveResult deviceBreadthFirst(SearchRun& run) {
    StateSpace& space = run.space;
    DeviceStateSet set(space, run.options().maxMemory);
    auto memoryFull = [&] {
        run.result.limit = "memory";
        return run.finish(Status::Limit, set.size(), set.bytes());
    };
    if (!set.addRoot()) return memoryFull();
    if (space.rootWon()) return run.solved({}, -1, set.size(), set.bytes());
    size_t layerBegin = 0;
    size_t layerEnd = 1;
    for (uint32_t depth = 0; layerBegin < layerEnd; ++depth) {
        set.beginLayer();
        for (size_t begin = layerBegin; begin < layerEnd;) {
            if (run.stopped(set.size())) return run.finish(Status::Limit, set.size(), set.bytes());
            const size_t count = set.room(run.batchWithinTime(std::min(space.maxBatch(), layerEnd - begin)));
            if (count == 0) return memoryFull();
            const double began = run.elapsed();
            space.setDeadline(run.timeLeft());
            const DeviceStateSet::Outcome o = set.expand(static_cast<uint32_t>(begin), count);
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
        layerBegin = layerEnd;
        layerEnd = set.size();
    }
    return run.finish(Status::Exhausted, set.size(), set.bytes());
}

}  // namespace psc::search
