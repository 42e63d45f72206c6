#include "SearchRun.h"

#include <unistd.h>

#include <algorithm>

namespace psc::search {
namespace {

size_t defaultMemoryLimit() {
    const long pages = sysconf(_SC_PHYS_PAGES);
    const long pageSize = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || pageSize <= 0) return size_t{4} << 30;
    return static_cast<size_t>(pages) * static_cast<size_t>(pageSize) / 2;
}

}  // namespace

SearchRun::SearchRun(StateSpace& s, const SolveOptions& options, double timeLimit)
    : space(s),
      store(s.keyWords(), options.maxMemory ? options.maxMemory : defaultMemoryLimit()),
      options_(options),
      timeLimit_(timeLimit),
      start_(std::chrono::steady_clock::now()) {}

double SearchRun::elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

bool SearchRun::stopped() {
    if (!result.limit.empty()) return true;
    if (elapsed() >= timeLimit_) result.limit = "time";
    else if (options_.maxStates && store.size() >= options_.maxStates) result.limit = "states";
    return !result.limit.empty();
}

StateStore::Insert SearchRun::add(const uint64_t* key, uint64_t hash, uint32_t parent, uint8_t input, uint32_t depth,
                                  uint32_t* index) {
    const StateStore::Insert r = store.insert(key, hash, parent, input, depth, index);
    if (r == StateStore::Insert::Full) result.limit = "memory";
    return r;
}

SolveResult& SearchRun::finish(Status status) {
    result.status = status;
    result.unique = store.size();
    result.seconds = elapsed();
    result.bytes = std::max(result.bytes, store.bytes());
    return result;
}

SolveResult& SearchRun::solved(uint32_t state, int input) {
    result.solution.clear();
    for (int action : store.path(state)) result.solution += inputLetter(space.inputs()[static_cast<size_t>(action)]);
    if (input >= 0) result.solution += inputLetter(space.inputs()[static_cast<size_t>(input)]);
    return finish(Status::Solved);
}

void SearchRun::reportProgress(int depth) {
    if (!options_.progress) return;
    const double now = elapsed();
    if (now - lastProgress_ < 1.0) return;
    lastProgress_ = now;
    options_.progress(Progress{depth, result.expanded, store.size(), now, store.bytes()});
}

void ExpandBuffers::fit(size_t count, size_t words, size_t inputs, bool withEstimates) {
    if (keys.size() < count * words) keys.resize(count * words);
    if (children.size() < count * inputs * words) children.resize(count * inputs * words);
    if (flags.size() < count * inputs) flags.resize(count * inputs);
    if (hashes.size() < count * inputs) hashes.resize(count * inputs);
    if (withEstimates && estimates.size() < count * inputs) estimates.resize(count * inputs);
}

}  // namespace psc::search
