// Every state a search has reached, each once: its key, the state it was first
// reached from and by which input, and its depth.  Duplicates are found by an
// open-addressing table over the keys' 64-bit hashes and confirmed on the
// whole key, so two distinct states never merge (a hash-only table, like
// script-doctor's 30-bit one, would prune reachable states).  Storage grows
// in fixed blocks (no reallocation doubling the footprint) and stops at a
// memory limit instead of swapping.
//
// A store of prints (Keys::Prints) keeps no keys past four words: a state is
// known by its 128-bit print, the plugin's 64-bit hash beside a second,
// independent one (as the GPU's store's prints, state_set_kernels.cu), so two
// states merge with a probability of about 2^-128 a pair.  A state
// then costs 32 bytes and its table slots whatever its key's size (limerick
// level 6: about 370 bytes a state with keys); breadth-first search, which
// needs only the keys of the layer it expands and the layer it builds, keeps
// those itself (memory it declares with setOtherBytes).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "SlotArray.h"

namespace psc::search {

class StateStore {
public:
    static constexpr uint32_t kNoParent = UINT32_MAX;
    static constexpr uint32_t kMaxStates = UINT32_MAX - 1;

    enum class Keys { Kept, Prints };
    StateStore(size_t keyWords, size_t memoryLimit, Keys keys = Keys::Kept);

    enum class Insert { Added, Known, Full };
    // Adds the state unless its key is known; *index receives its index either way (not when Full).
    Insert insert(const uint64_t* key, uint64_t hash, uint32_t parent, uint8_t input, uint32_t depth, uint32_t* index);

    bool contains(const uint64_t* key, uint64_t hash) const;
    // About how long the table's growth would take if `more` states were
    // added now (0 where they fit): twice the last growth's seconds a slot,
    // since a larger table's fresh pages took up to that (zenpuzzle level 4
    // on the development machine: 0.5 s to 2^26 slots, about 2 s to 2^27),
    // which a search with less time left should not start.
    double growthSeconds(size_t more) const {
        return (count_ + more) * 2 > slots_.size() ? 2 * secondsPerGrownSlot_ * 2 * static_cast<double>(slots_.size())
                                                   : 0;
    }
    // Starts loading the table slot where a probe for `hash` begins (a batch's
    // inserts otherwise wait on one cache miss after another).
    void prefetch(uint64_t hash) const { __builtin_prefetch(&slots_[homeOf(hash)]); }

    size_t size() const { return count_; }
    size_t bytes() const;  // memory held, tables and setOtherBytes' included
    // Memory the search holds beside the store, counted against the same limit.
    void setOtherBytes(size_t bytes) { otherBytes_ = bytes; }
    size_t memoryLimit() const { return memoryLimit_; }
    bool keepsKeys() const { return keepKeys_; }
    // The key of state i; only where keepsKeys().
    const uint64_t* key(uint32_t i) const { return stored(i); }
    // How many states from i on have their keys in one piece of memory.
    size_t contiguousFrom(uint32_t i) const { return size_t{blockMask_} + 1 - (i & blockMask_); }
    uint32_t parent(uint32_t i) const { return meta(i).parent; }
    uint8_t input(uint32_t i) const { return meta(i).input; }
    uint32_t depth(uint32_t i) const { return meta(i).depth; }
    // The inputs from the first state to state i (psc_action values).
    std::vector<int> path(uint32_t i) const;

private:
    // States a block holds: a power of two, a block at most about 64 MB (a
    // first block of huge keys would otherwise cost seconds to map).
    int blockBits_;
    uint32_t blockMask_;
    struct Meta {
        uint64_t hash;
        uint32_t parent;
        uint32_t depth;
        uint8_t input;
    };
    const Meta& meta(uint32_t i) const { return metaBlocks_[i >> blockBits_][i & blockMask_]; }
    const uint64_t* stored(uint32_t i) const { return &wordBlocks_[i >> blockBits_][(i & blockMask_) * storedWords_]; }
    size_t probe(const uint64_t* key, uint64_t hash, uint64_t print) const;
    size_t stateBytes() const { return storedWords_ * 8 + sizeof(Meta); }
    bool growTable();
    bool reserveOne();

    size_t keyWords_;
    size_t memoryLimit_;
    bool keepKeys_;
    size_t otherBytes_ = 0;
    double secondsPerGrownSlot_ = 0;
    size_t count_ = 0;
    size_t storedWords_;  // a state's words in wordBlocks_: its key, or its second print
    std::vector<std::unique_ptr<uint64_t[]>> wordBlocks_;
    std::vector<std::unique_ptr<Meta[]>> metaBlocks_;
    // A state's index + 1 in the low half, its hash's high half in the high
    // one (a tag: a probe reads a state's meta only where the tags agree);
    // 0 when empty; a power of two long.  A state's home slot is its hash's
    // high bits, so that the tags alone rehash the table when it grows.
    static constexpr int kFirstTableBits = 12;
    SlotArray slots_;
    int homeShift_ = 64 - kFirstTableBits;
    size_t homeOf(uint64_t hash) const { return hash >> homeShift_; }
    static uint64_t slotOf(uint32_t i, uint64_t hash) { return (hash >> 32 << 32) | (uint64_t{i} + 1); }
    static uint32_t indexOf(uint64_t slot) { return static_cast<uint32_t>(slot) - 1; }
};

}  // namespace psc::search
