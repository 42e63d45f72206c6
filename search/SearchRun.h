// What one search keeps while it runs (internal to search/): the state space,
// the store of reached states, the limits and the counters.
#pragma once

#include <chrono>
#include <vector>

#include "Solver.h"
#include "StateSpace.h"
#include "StateStore.h"

namespace psc::search {

class SearchRun {
public:
    SearchRun(StateSpace& space, const SolveOptions& options, double timeLimit);

    StateSpace& space;
    StateStore store;
    SolveResult result;

    double elapsed() const;
    // Whether a limit has been reached; sets result.status and result.limit if so.
    bool stopped();
    // Records the path to `state`, then `input` if not negative, as the solution.
    SolveResult& solved(uint32_t state, int input = -1);
    SolveResult& finish(Status status);
    // Adds a child; sets the limit when the store is full.  Returns Added or Known, or Full.
    StateStore::Insert add(const uint64_t* key, uint64_t hash, uint32_t parent, uint8_t input, uint32_t depth, uint32_t* index);
    void reportProgress(int depth);

private:
    const SolveOptions& options_;
    double timeLimit_;
    std::chrono::steady_clock::time_point start_;
    double lastProgress_ = 0;
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

SolveResult breadthFirst(SearchRun& run);
// f = gWeight * depth + hWeight * estimate.
SolveResult bestFirst(SearchRun& run, double gWeight, double hWeight);

}  // namespace psc::search
