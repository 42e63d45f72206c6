// Every state a search has reached, each once: its key, the state it was first
// reached from and by which input, and its depth.  Duplicates are found by an
// open-addressing table over the keys' 64-bit hashes and confirmed on the
// whole key, so two distinct states never merge (a hash-only table, like
// script-doctor's 30-bit one, would prune reachable states).  Storage grows
// in fixed blocks (no reallocation doubling the footprint) and stops at a
// memory limit instead of swapping.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace psc::search {

class StateStore {
public:
    static constexpr uint32_t kNoParent = UINT32_MAX;
    static constexpr uint32_t kMaxStates = UINT32_MAX - 1;

    StateStore(size_t keyWords, size_t memoryLimit);

    enum class Insert { Added, Known, Full };
    // Adds the state unless its key is known; *index receives its index either way (not when Full).
    Insert insert(const uint64_t* key, uint64_t hash, uint32_t parent, uint8_t input, uint32_t depth, uint32_t* index);

    bool contains(const uint64_t* key, uint64_t hash) const;

    size_t size() const { return count_; }
    size_t bytes() const;  // memory held, tables included
    const uint64_t* key(uint32_t i) const { return &keyBlocks_[i >> blockBits_][(i & blockMask_) * keyWords_]; }
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
    size_t probe(const uint64_t* key, uint64_t hash) const;
    bool growTable();
    bool reserveOne();

    size_t keyWords_;
    size_t memoryLimit_;
    size_t count_ = 0;
    std::vector<std::unique_ptr<uint64_t[]>> keyBlocks_;
    std::vector<std::unique_ptr<Meta[]>> metaBlocks_;
    std::vector<uint32_t> slots_;  // state index + 1, 0 when empty; a power of two long
};

}  // namespace psc::search
