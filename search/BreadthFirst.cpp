// Breadth-first search, one layer at a time, each layer expanded in batches.
// A child is tested for a win when it is generated: every state of layer d
// is expanded before any of layer d + 1, so the first win found is a
// shortest solution.  A winning input counts even when it changes nothing
// (a level whose win conditions already hold is won by any input).
//
// The store keeps prints, not keys (StateStore::Keys::Prints): the search
// keeps the keys of the layer it expands and of the layer it builds, whose
// states are consecutive in the store.  Limerick level 6's states took about
// 370 bytes each with their keys, and the kernel's work to hand the store
// fresh pages was a third of the search's time.
#include <algorithm>
#include <new>
#include <stdexcept>

#include "SearchRun.h"

namespace psc::search {
namespace {

// The keys of one layer's states, in store order, grown within the run's memory limit.
class LayerKeys {
public:
    explicit LayerKeys(size_t words) : words_(words) {}
    const uint64_t* at(size_t i) const { return &keys_[i * words_]; }
    size_t size() const { return keys_.size() / words_; }
    size_t bytes() const { return keys_.capacity() * sizeof(uint64_t); }
    void clear() { keys_.clear(); }
    void swap(LayerKeys& other) { keys_.swap(other.keys_); }
    // Appends a key unless growing would pass `room` more bytes (or fails); false then.
    bool append(const uint64_t* key, size_t room) {
        if (keys_.size() + words_ > keys_.capacity()) {
            const size_t grown = std::max(keys_.capacity() + keys_.capacity() / 2, words_ * 1024);
            if ((grown - keys_.capacity()) * sizeof(uint64_t) > room) return false;
            try {
                keys_.reserve(grown);
            } catch (const std::bad_alloc&) {
                return false;
            }
        }
        keys_.insert(keys_.end(), key, key + words_);
        return true;
    }

private:
    size_t words_;
    std::vector<uint64_t> keys_;
};

// Children whose table slots are loaded ahead of their insertion.
constexpr size_t kPrefetchAhead = 16;

}  // namespace

SolveResult breadthFirst(SearchRun& run) {
    StateSpace& space = run.space;
    StateStore& store = run.store;
    const size_t words = space.keyWords();
    const size_t inputs = space.inputs().size();
    const uint32_t root = run.addRoot();
    if (space.rootWon()) return run.solved(root);

    LayerKeys layer(words);
    LayerKeys next(words);
    auto declareKeys = [&] { store.setOtherBytes(layer.bytes() + next.bytes()); };
    auto room = [&] { return store.memoryLimit() - std::min(store.memoryLimit(), store.bytes()); };
    auto outOfMemory = [&] {
        run.result.limit = "memory";
        return run.finish(Status::Limit);
    };
    if (!layer.append(space.root().data(), room())) return outOfMemory();
    declareKeys();
    uint32_t first = root;  // the layer's first state; its others follow it in the store
    ExpandBuffers b;
    for (uint32_t depth = 0; layer.size() > 0; ++depth) {
        next.clear();
        const uint32_t nextFirst = static_cast<uint32_t>(store.size());
        for (size_t begin = 0, count = 0; begin < layer.size(); begin += count) {
            if (run.stopped()) return run.finish(Status::Limit);
            count = run.batchWithinTime(std::min(space.maxBatch(), layer.size() - begin));
            expandKeys(run, layer.at(begin), count, b, false);
            for (size_t c = 0; c < count * inputs; ++c) {
                if (c + kPrefetchAhead < count * inputs) store.prefetch(b.hashes[c + kPrefetchAhead]);
                const uint32_t parent = first + static_cast<uint32_t>(begin + c / inputs);
                if (b.flags[c] & PSC_EXPAND_INVALID) throw std::runtime_error("the plugin refused to expand a state");
                if (b.flags[c] & PSC_EXPAND_WON) return run.solved(parent, static_cast<int>(c % inputs));
                if (b.flags[c] & kChildNotSearched) continue;
                const uint64_t* key = &b.children[c * words];
                uint32_t child = 0;
                const StateStore::Insert r =
                    run.add(key, b.hashes[c], parent, static_cast<uint8_t>(c % inputs), depth + 1, &child);
                if (r == StateStore::Insert::Full) return run.finish(Status::Limit);
                if (r == StateStore::Insert::Known) continue;
                if (!next.append(key, room())) return outOfMemory();
                declareKeys();
            }
            run.reportProgress(static_cast<int>(depth));
        }
        layer.swap(next);
        first = nextFirst;
    }
    return run.exhausted();
}

}  // namespace psc::search
