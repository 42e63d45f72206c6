// Beam search: breadth-first, but each layer keeps only the `width` new
// states with the smallest win-condition estimate (ties to the earlier
// child), in the order they were reached, as the GPU's beam search
// (DeviceBreadthFirst.cpp), which keeps its states on the device, finds them.
// It reaches depths breadth-first cannot hold in memory (atlas'
// solutions run to hundreds of inputs) at the price of completeness: a level
// whose beam empties after dropping states is a `beam` limit, not exhausted.
// Dropped states are not remembered, so a later layer may reach and keep one.
#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "SearchRun.h"

namespace psc::search {

SolveResult beamSearch(SearchRun& run, size_t width) {
    StateSpace& space = run.space;
    const size_t words = space.keyWords();
    const size_t inputs = space.inputs().size();
    const uint32_t root = run.addRoot();
    if (space.rootWon()) return run.solved(root);

    std::vector<uint32_t> layer = {root};
    std::vector<uint32_t> next;
    ExpandBuffers b;
    // The layer's children that are not known yet, before the cut.
    std::vector<uint64_t> keys, hashes;
    std::vector<uint32_t> parents;
    std::vector<uint8_t> childInputs;
    std::vector<int32_t> estimates;
    std::vector<uint32_t> order;
    std::vector<std::pair<uint32_t, uint32_t>> kept;  // candidate, state
    bool dropped = false;
    for (uint32_t depth = 0; !layer.empty(); ++depth) {
        keys.clear();
        hashes.clear();
        parents.clear();
        childInputs.clear();
        estimates.clear();
        for (size_t begin = 0, count = 0; begin < layer.size(); begin += count) {
            if (run.stopped()) return run.finish(Status::Limit);
            count = run.batchWithinTime(std::min(space.maxBatch(), layer.size() - begin));
            expandStored(run, &layer[begin], count, b, true);
            for (size_t c = 0; c < count * inputs; ++c) {
                if (b.flags[c] & PSC_EXPAND_INVALID) throw std::runtime_error("the plugin refused to expand a state");
                const uint32_t parent = layer[begin + c / inputs];
                if (b.flags[c] & PSC_EXPAND_WON) return run.solved(parent, static_cast<int>(c % inputs));
                if (b.flags[c] & kChildNotSearched || run.store.contains(&b.children[c * words], b.hashes[c])) continue;
                keys.insert(keys.end(), &b.children[c * words], &b.children[(c + 1) * words]);
                hashes.push_back(b.hashes[c]);
                parents.push_back(parent);
                childInputs.push_back(static_cast<uint8_t>(c % inputs));
                estimates.push_back(b.estimates[c]);
            }
            run.reportProgress(static_cast<int>(depth));
        }
        order.resize(hashes.size());
        std::iota(order.begin(), order.end(), 0u);
        std::stable_sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) { return estimates[x] < estimates[y]; });
        kept.clear();
        size_t taken = 0;
        for (; taken < order.size() && kept.size() < width; ++taken) {
            const uint32_t i = order[taken];
            uint32_t child = 0;
            const StateStore::Insert r = run.add(&keys[size_t{i} * words], hashes[i], parents[i], childInputs[i], depth + 1, &child);
            if (r == StateStore::Insert::Full) return run.finish(Status::Limit);
            if (r == StateStore::Insert::Added) kept.emplace_back(i, child);
        }
        std::sort(kept.begin(), kept.end());
        next.clear();
        for (const auto& [candidate, child] : kept) next.push_back(child);
        // Children left over that are copies of kept ones were not dropped.
        for (size_t k = taken; k < order.size() && !dropped; ++k) {
            dropped = !run.store.contains(&keys[size_t{order[k]} * words], hashes[order[k]]);
        }
        layer.swap(next);
    }
    if (!dropped || !run.result.limit.empty()) return run.exhausted();
    run.result.limit = "beam";
    return run.finish(Status::Limit);
}

}  // namespace psc::search
