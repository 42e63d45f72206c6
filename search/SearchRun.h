// What one search keeps while it runs (internal to search/): the state space,
// the store of reached states, the limits and the counters.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "Solver.h"
#include "StateSpace.h"
#include "StateStore.h"

namespace psc::search {

class SearchRun {
public:
    // `stage` names the search in progress lines ("bfs", "beam 4096"); `keys`
    // says whether the store keeps its states' keys (StateStore.h).
    SearchRun(StateSpace& space, const SolveOptions& options, double timeLimit, std::string stage,
              StateStore::Keys keys = StateStore::Keys::Kept);

    const SolveOptions& options() const { return options_; }

    StateSpace& space;
    StateStore store;
    SolveResult result;

    double elapsed() const;
    double timeLeft() const { return timeLimit_ - elapsed(); }
    // Whether a limit has been reached; sets result.status and result.limit if so.
    bool stopped() { return stopped(store.size()); }
    bool stopped(uint64_t unique);  // for a search whose states are kept elsewhere (on the device)
    // The search ran out of states to expand: exhausted, unless an expansion
    // was cut short by the time limit (then the states it missed were never seen).
    SolveResult& exhausted() { return finish(result.limit.empty() ? Status::Exhausted : Status::Limit); }
    // Records the path to `state`, then `input` if not negative, as the solution.
    SolveResult& solved(uint32_t state, int input = -1) { return solved(store.path(state), input); }
    SolveResult& solved(const std::vector<int>& path, int input, uint64_t unique, size_t bytes);
    SolveResult& finish(Status status) { return finish(status, store.size(), store.bytes()); }
    SolveResult& finish(Status status, uint64_t unique, size_t bytes);
    // Stores the space's root (state 0).
    uint32_t addRoot();
    // Adds a child; sets the limit when the store is full.  Returns Added or Known, or Full.
    StateStore::Insert add(const uint64_t* key, uint64_t hash, uint32_t parent, uint8_t input, uint32_t depth, uint32_t* index);
    // How many of `wanted` states the next expand call may take (at least one):
    // as many as fit in a quarter of the time left at the last call's rate,
    // at most twice the last call's, and a few at first.  One call of a large
    // batch of a slow game (a state whose inputs each run a long `again`
    // chain) would otherwise overrun the time limit many times over, and a
    // portfolio stage's overrun is taken from the stages after it.
    size_t batchWithinTime(size_t wanted) const;
    // Counts an expand call of `count` states begun when elapsed() was `began`.
    void countExpansion(size_t count, double began);
    void reportProgress(int depth) { reportProgress(depth, store.size(), store.bytes()); }
    void reportProgress(int depth, uint64_t unique, size_t bytes);

private:
    SolveResult& solved(const std::vector<int>& path, int input) { return solved(path, input, store.size(), store.bytes()); }

    const SolveOptions& options_;
    std::string stage_;
    double timeLimit_;
    std::chrono::steady_clock::time_point start_;
    double lastProgress_ = 0;
    double secondsPerState_ = 0;  // of the last expand call; 0 before the first
    size_t lastCount_ = 0;        // the last expand call's states
};

// One expand call's keys in and children out, grown to the largest batch
// expanded so far: sized for maxBatch() up front, their zero-filling alone
// took a large level's search about 50 ms before its first expansion.
struct ExpandBuffers {
    std::vector<uint64_t> keys;
    std::vector<uint64_t> children;
    std::vector<uint8_t> flags;
    std::vector<uint64_t> hashes;
    std::vector<int32_t> estimates;

    void fit(size_t count, size_t words, size_t inputs, bool withEstimates);
};

// Children no search goes on from: those equal to their parent, and those
// reached through an `again` chain that never settles (cut off after 10,000
// turns): the original engine never finishes that input, and its player
// takes no input while a chain runs, so no solution passes through them;
// and those the expansion deadline left out (the time limit then stops the search).
constexpr uint8_t kChildNotSearched = PSC_EXPAND_UNCHANGED | PSC_EXPAND_CUT_OFF | PSC_EXPAND_TIMED_OUT;

// Expands the states of keys[0..count) into b (estimates too when asked) and
// counts them in run.result.
void expandKeys(SearchRun& run, const uint64_t* keys, size_t count, ExpandBuffers& b, bool withEstimates);
// The same for stored states states[0..count), their keys gathered first.
void expandStored(SearchRun& run, const uint32_t* states, size_t count, ExpandBuffers& b, bool withEstimates);

// Its store need not keep keys (StateStore::Keys::Prints): it keeps its two layers' own.
SolveResult breadthFirst(SearchRun& run);
// Breadth-first with every state kept on the GPU (DeviceStateSet.h): CUDA spaces.
SolveResult deviceBreadthFirst(SearchRun& run);
// Breadth-first keeping the `width` best new states of each layer.
SolveResult beamSearch(SearchRun& run, size_t width);
// The same with every state kept on the GPU: CUDA spaces.
SolveResult deviceBeamSearch(SearchRun& run, size_t width);
// f = gWeight * depth + hWeight * estimate.
SolveResult bestFirst(SearchRun& run, double gWeight, double hWeight);

}  // namespace psc::search
