// Breadth-first search, one layer at a time, each layer expanded in batches.
// A child is tested for a win when it is generated: every state of layer d
// is expanded before any of layer d + 1, so the first win found is a
// shortest solution.  A winning input counts even when it changes nothing
// (a level whose win conditions already hold is won by any input).
#include <stdexcept>

#include "SearchRun.h"

namespace psc::search {

SolveResult breadthFirst(SearchRun& run) {
    StateSpace& space = run.space;
    const size_t words = space.keyWords();
    const size_t inputs = space.inputs().size();
    const uint32_t root = run.addRoot();
    if (space.rootWon()) return run.solved(root);

    std::vector<uint32_t> layer = {root};
    std::vector<uint32_t> next;
    ExpandBuffers b;
    for (uint32_t depth = 0; !layer.empty(); ++depth) {
        next.clear();
        for (size_t begin = 0, count = 0; begin < layer.size(); begin += count) {
            if (run.stopped()) return run.finish(Status::Limit);
            count = run.batchWithinTime(std::min(space.maxBatch(), layer.size() - begin));
            expandStored(run, &layer[begin], count, b, false);
            for (size_t c = 0; c < count * inputs; ++c) {
                if (b.flags[c] & PSC_EXPAND_INVALID) throw std::runtime_error("the plugin refused to expand a state");
                if (b.flags[c] & PSC_EXPAND_WON) return run.solved(layer[begin + c / inputs], static_cast<int>(c % inputs));
                if (b.flags[c] & kChildNotSearched) continue;
                uint32_t child = 0;
                const StateStore::Insert r = run.add(&b.children[c * words], b.hashes[c], layer[begin + c / inputs],
                                                     static_cast<uint8_t>(c % inputs), depth + 1, &child);
                if (r == StateStore::Insert::Full) return run.finish(Status::Limit);
                if (r == StateStore::Insert::Added) next.push_back(child);
            }
            run.reportProgress(static_cast<int>(depth));
        }
        layer.swap(next);
    }
    return run.exhausted();
}

}  // namespace psc::search
