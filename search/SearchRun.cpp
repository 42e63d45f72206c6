#include "SearchRun.h"

#include <unistd.h>

#include <algorithm>
#include <utility>

namespace psc::search {
namespace {

size_t defaultMemoryLimit() {
    const long pages = sysconf(_SC_PHYS_PAGES);
    const long pageSize = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || pageSize <= 0) return size_t{4} << 30;
    return static_cast<size_t>(pages) * static_cast<size_t>(pageSize) / 2;
}

}  // namespace

SearchRun::SearchRun(StateSpace& s, const SolveOptions& options, double timeLimit, std::string stage,
                     StateStore::Keys keys)
    : space(s),
      store(s.keyWords(), options.maxMemory ? options.maxMemory : defaultMemoryLimit(), keys),
      options_(options),
      stage_(std::move(stage)),
      timeLimit_(timeLimit),
      start_(std::chrono::steady_clock::now()) {}

double SearchRun::elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

bool SearchRun::stopped(uint64_t unique) {
    if (!result.limit.empty()) return true;
    if (elapsed() >= timeLimit_) result.limit = "time";
    else if (options_.maxStates && unique >= options_.maxStates) result.limit = "states";
    return !result.limit.empty();
}

uint32_t SearchRun::addRoot() {
    uint32_t root = 0;
    add(space.root().data(), space.rootHash(), StateStore::kNoParent, 0, 0, &root);
    return root;
}

StateStore::Insert SearchRun::add(const uint64_t* key, uint64_t hash, uint32_t parent, uint8_t input, uint32_t depth,
                                  uint32_t* index) {
    const StateStore::Insert r = store.insert(key, hash, parent, input, depth, index);
    if (r == StateStore::Insert::Full) result.limit = "memory";
    return r;
}

SolveResult& SearchRun::finish(Status status, uint64_t unique, size_t bytes) {
    result.status = status;
    result.unique = unique;
    result.seconds = elapsed();
    result.bytes = std::max(result.bytes, bytes);
    return result;
}

SolveResult& SearchRun::solved(const std::vector<int>& path, int input, uint64_t unique, size_t bytes) {
    result.solution.clear();
    for (int action : path) result.solution += inputLetter(space.inputs()[static_cast<size_t>(action)]);
    if (input >= 0) result.solution += inputLetter(space.inputs()[static_cast<size_t>(input)]);
    return finish(Status::Solved, unique, bytes);
}

void SearchRun::reportProgress(int depth, uint64_t unique, size_t bytes) {
    if (!options_.progress) return;
    const double now = elapsed();
    if (now - lastProgress_ < 1.0) return;
    lastProgress_ = now;
    options_.progress(Progress{stage_, depth, result.expanded, unique, now, bytes});
}

size_t SearchRun::batchWithinTime(size_t wanted) const {
    constexpr size_t kFirstBatch = 16;
    size_t most = kFirstBatch;
    if (secondsPerState_ > 0) {
        const double states = std::max(0.0, timeLimit_ - elapsed()) / 4 / secondsPerState_;
        most = states >= static_cast<double>(wanted) ? wanted : static_cast<size_t>(states);
        // A rate measured on a few states says little about the next ones (a
        // start whose inputs settle, children whose inputs each run a long
        // `again` chain): a call takes at most twice the last one's states.
        most = std::min(most, 2 * lastCount_);
    }
    return std::max<size_t>(1, std::min(wanted, most));
}

void SearchRun::countExpansion(size_t count, double began) {
    result.expanded += count;
    result.generated += count * space.inputs().size();
    secondsPerState_ = (elapsed() - began) / static_cast<double>(std::max<size_t>(count, 1));
    lastCount_ = count;
}

void expandStored(SearchRun& run, const uint32_t* states, size_t count, ExpandBuffers& b, bool withEstimates) {
    const size_t words = run.space.keyWords();
    if (b.keys.size() < count * words) b.keys.resize(count * words);
    for (size_t i = 0; i < count; ++i) {
        const uint64_t* key = run.store.key(states[i]);
        std::copy(key, key + words, b.keys.begin() + static_cast<std::ptrdiff_t>(i * words));
    }
    expandKeys(run, b.keys.data(), count, b, withEstimates);
}

void expandKeys(SearchRun& run, const uint64_t* keys, size_t count, ExpandBuffers& b, bool withEstimates) {
    const size_t inputs = run.space.inputs().size();
    b.fit(count, run.space.keyWords(), inputs, withEstimates);
    const double began = run.elapsed();
    run.space.setDeadline(run.timeLeft());
    run.space.expand(keys, count, b.children.data(), b.flags.data(), b.hashes.data(),
                     withEstimates ? b.estimates.data() : nullptr);
    run.countExpansion(count, began);
    // Children the deadline left out: the time limit stops the search.
    const size_t children = count * inputs;
    if (std::any_of(b.flags.begin(), b.flags.begin() + static_cast<std::ptrdiff_t>(children),
                    [](uint8_t f) { return (f & PSC_EXPAND_TIMED_OUT) != 0; })) {
        run.result.limit = "time";
    }
}

void ExpandBuffers::fit(size_t count, size_t words, size_t inputs, bool withEstimates) {
    if (children.size() < count * inputs * words) children.resize(count * inputs * words);
    if (flags.size() < count * inputs) flags.resize(count * inputs);
    if (hashes.size() < count * inputs) hashes.resize(count * inputs);
    if (withEstimates && estimates.size() < count * inputs) estimates.resize(count * inputs);
}

}  // namespace psc::search
