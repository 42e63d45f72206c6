// Breadth-first search, one layer at a time, each layer expanded in batches.
// A child is tested for a win when it is generated: every state of layer d
// is expanded before any of layer d + 1, so the first win found is a
// shortest solution.  A winning input counts even when it changes nothing
// (a level whose win conditions already hold is won by any input).
//
// The store keeps prints, not keys (StateStore::Keys::Prints), where keys
// are longer than four words: the search keeps the keys of the layer it
// expands and of the layer it builds, whose states are consecutive in the
// store.  Limerick level 6's states took about 370 bytes each with their
// keys, and the kernel's work to hand the store fresh pages was a third of
// the search's time.
#include <algorithm>
#include <cstring>
#include <memory>
#include <new>
#include <stdexcept>

#include "SearchRun.h"

namespace psc::search {
namespace {

// The keys of one layer's states, in store order, in chunks that double in
// size up to about 64 MB: a chunk is never copied (growing one vector of a
// large layer's keys copied gigabytes at once, long past the time limit), and
// a layer that is cleared keeps its chunks for the next layer.
class LayerKeys {
public:
    explicit LayerKeys(size_t words)
        : words_(words), largestChunk_(std::max<size_t>(1, (size_t{64} << 20) / (words * sizeof(uint64_t)))) {}
    size_t size() const { return size_; }
    size_t bytes() const { return capacity() * words_ * sizeof(uint64_t); }
    const uint64_t* at(size_t i) const { return address(i); }
    // How many states from i on lie in one piece of memory.
    size_t contiguousFrom(size_t i) const {
        const Chunk& c = chunkOf(i);
        return c.first + c.states - i;
    }
    void clear() { size_ = 0; }
    void swap(LayerKeys& other) {
        chunks_.swap(other.chunks_);
        std::swap(size_, other.size_);
    }
    // Appends a key unless a new chunk would pass `room` more bytes (or cannot be had); false then.
    bool append(const uint64_t* key, size_t room) {
        if (size_ == capacity()) {
            const size_t states = chunks_.empty() ? 1024 : std::min(2 * chunks_.back().states, largestChunk_);
            if (states * words_ * sizeof(uint64_t) > room) return false;
            std::unique_ptr<uint64_t[]> keys(new (std::nothrow) uint64_t[states * words_]);
            if (!keys) return false;
            chunks_.push_back(Chunk{std::move(keys), capacity(), states});
        }
        std::memcpy(address(size_), key, words_ * sizeof(uint64_t));
        ++size_;
        return true;
    }

private:
    struct Chunk {
        std::unique_ptr<uint64_t[]> keys;
        size_t first;   // the layer's index of its first key
        size_t states;  // keys it holds
    };
    uint64_t* address(size_t i) const {
        const Chunk& c = chunkOf(i);
        return &c.keys[(i - c.first) * words_];
    }
    size_t capacity() const { return chunks_.empty() ? 0 : chunks_.back().first + chunks_.back().states; }
    const Chunk& chunkOf(size_t i) const {
        return *(std::upper_bound(chunks_.begin(), chunks_.end(), i,
                                  [](size_t index, const Chunk& c) { return index < c.first; }) -
                 1);
    }

    size_t words_;
    size_t largestChunk_;
    size_t size_ = 0;
    std::vector<Chunk> chunks_;
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

    // Where the store keeps keys (of up to four words), a layer's keys are
    // the store's own, consecutive within each of its blocks.
    const bool ownKeys = !store.keepsKeys();
    LayerKeys layer(words);
    LayerKeys next(words);
    auto declareKeys = [&] { store.setOtherBytes(layer.bytes() + next.bytes()); };
    auto room = [&] { return store.memoryLimit() - std::min(store.memoryLimit(), store.bytes()); };
    auto outOfMemory = [&] {
        run.result.limit = "memory";
        return run.finish(Status::Limit);
    };
    if (ownKeys && !layer.append(space.root().data(), room())) return outOfMemory();
    declareKeys();
    uint32_t first = root;  // the layer's first state; its others follow it in the store
    size_t layerSize = 1;
    auto keyOf = [&](size_t i) { return ownKeys ? layer.at(i) : store.key(first + static_cast<uint32_t>(i)); };
    auto contiguousFrom = [&](size_t i) {
        return ownKeys ? layer.contiguousFrom(i) : store.contiguousFrom(first + static_cast<uint32_t>(i));
    };
    ExpandBuffers b;
    for (uint32_t depth = 0; layerSize > 0; ++depth) {
        next.clear();
        const uint32_t nextFirst = static_cast<uint32_t>(store.size());
        size_t nextSize = 0;
        for (size_t begin = 0, count = 0; begin < layerSize; begin += count) {
            if (run.stopped()) return run.finish(Status::Limit);
            count = run.batchWithinTime(std::min({space.maxBatch(), layerSize - begin, contiguousFrom(begin)}));
            if (store.growthSeconds(count * inputs) > run.timeLeft()) {
                run.result.limit = "time";  // the table's growth would run past it
                return run.finish(Status::Limit);
            }
            expandKeys(run, keyOf(begin), count, b, false);
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
                ++nextSize;
                if (!ownKeys) continue;
                if (!next.append(key, room())) return outOfMemory();
                declareKeys();
            }
            run.reportProgress(static_cast<int>(depth));
        }
        layer.swap(next);
        layerSize = nextSize;
        first = nextFirst;
    }
    return run.exhausted();
}

}  // namespace psc::search
