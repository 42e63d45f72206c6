// Best-first search over the win-condition estimate (A*, weighted A*,
// greedy): the open list is a binary heap on f, ties broken toward the
// smaller estimate, then the older state.  A batch of the best states is
// taken and expanded together (the plugin estimates every child as it
// expands it).  Children are tested for a win when generated, and a
// state is reached once: a cheaper path found later is not taken (no
// reopening).  Both keep weighted searches fast; with an estimate that is not
// a lower bound optimality is not promised anyway (breadth-first promises it).
#include <queue>
#include <stdexcept>

#include "SearchRun.h"

namespace psc::search {
namespace {

struct Open {
    double f;
    int32_t h;
    uint32_t state;
    bool operator<(const Open& o) const {  // std::priority_queue pops the largest: invert
        if (f != o.f) return f > o.f;
        if (h != o.h) return h > o.h;
        return state > o.state;
    }
};

}  // namespace

SolveResult bestFirst(SearchRun& run, double gWeight, double hWeight) {
    StateSpace& space = run.space;
    const size_t words = space.keyWords();
    const size_t inputs = space.inputs().size();
    // Best-first keeps batches small: each batch is chosen on estimates that
    // the previous batch's children may improve on.
    const size_t batch = std::min<size_t>(space.maxBatch(), space.backend() == Backend::Cpu ? 256 : 65536);
    const uint32_t root = run.addRoot();
    if (space.rootWon()) return run.solved(root);

    std::priority_queue<Open> open;
    int32_t rootEstimate = 0;
    space.estimate(space.root().data(), 1, &rootEstimate);
    open.push(Open{hWeight * rootEstimate, rootEstimate, root});

    std::vector<uint32_t> taken;
    ExpandBuffers b;
    std::vector<uint32_t> fresh;
    std::vector<int32_t> freshEstimates;
    int deepest = 0;
    while (!open.empty()) {
        if (run.stopped()) return run.finish(Status::Limit);
        taken.clear();
        const size_t within = run.batchWithinTime(batch);
        while (!open.empty() && taken.size() < within) {
            taken.push_back(open.top().state);
            open.pop();
        }
        for (uint32_t state : taken) deepest = std::max(deepest, static_cast<int>(run.store.depth(state)));
        expandStored(run, taken.data(), taken.size(), b, true);
        fresh.clear();
        freshEstimates.clear();
        for (size_t c = 0; c < taken.size() * inputs; ++c) {
            if (b.flags[c] & PSC_EXPAND_INVALID) throw std::runtime_error("the plugin refused to expand a state");
            const uint32_t parent = taken[c / inputs];
            if (b.flags[c] & PSC_EXPAND_WON) return run.solved(parent, static_cast<int>(c % inputs));
            if (b.flags[c] & kChildNotSearched) continue;
            uint32_t child = 0;
            const StateStore::Insert r = run.add(&b.children[c * words], b.hashes[c], parent, static_cast<uint8_t>(c % inputs),
                                                 run.store.depth(parent) + 1, &child);
            if (r == StateStore::Insert::Full) return run.finish(Status::Limit);
            if (r == StateStore::Insert::Known) continue;
            fresh.push_back(child);
            freshEstimates.push_back(b.estimates[c]);
        }
        for (size_t i = 0; i < fresh.size(); ++i) {
            open.push(Open{gWeight * run.store.depth(fresh[i]) + hWeight * freshEstimates[i], freshEstimates[i], fresh[i]});
        }
        run.reportProgress(deepest);
    }
    return run.exhausted();
}

}  // namespace psc::search
