#include "StateStore.h"

#include <algorithm>
#include <cstring>

namespace psc::search {

StateStore::StateStore(size_t keyWords, size_t memoryLimit) : keyWords_(keyWords), memoryLimit_(memoryLimit) {
    const size_t stateBytes = keyWords * 8 + sizeof(Meta);
    blockBits_ = 16;
    while (blockBits_ > 8 && (size_t{1} << blockBits_) * stateBytes > (size_t{64} << 20)) --blockBits_;
    blockMask_ = (1u << blockBits_) - 1;
    slots_.assign(size_t{1} << 12, 0);
}

size_t StateStore::bytes() const {
    const size_t blockStates = size_t{1} << blockBits_;
    return keyBlocks_.size() * blockStates * (keyWords_ * 8 + sizeof(Meta)) + slots_.size() * sizeof(uint32_t);
}

bool StateStore::reserveOne() {
    if (count_ >= kMaxStates) return false;
    if ((count_ & blockMask_) == 0 && (count_ >> blockBits_) == keyBlocks_.size()) {
        const size_t blockStates = size_t{1} << blockBits_;
        if (bytes() + blockStates * (keyWords_ * 8 + sizeof(Meta)) > memoryLimit_) return false;
        keyBlocks_.emplace_back(new (std::nothrow) uint64_t[blockStates * keyWords_]);
        metaBlocks_.emplace_back(new (std::nothrow) Meta[blockStates]);
        if (!keyBlocks_.back() || !metaBlocks_.back()) {
            keyBlocks_.pop_back();
            metaBlocks_.pop_back();
            return false;
        }
    }
    // The table stays at most half full.
    if ((count_ + 1) * 2 > slots_.size() && !growTable()) return false;
    return true;
}

bool StateStore::growTable() {
    const size_t size = slots_.size() * 2;
    if (bytes() + size * sizeof(uint32_t) > memoryLimit_) return false;
    std::vector<uint32_t> grown;
    try {
        grown.assign(size, 0);
    } catch (const std::bad_alloc&) {
        return false;
    }
    const size_t mask = size - 1;
    for (size_t i = 0; i < count_; ++i) {
        size_t at = meta(static_cast<uint32_t>(i)).hash & mask;
        while (grown[at]) at = (at + 1) & mask;
        grown[at] = static_cast<uint32_t>(i + 1);
    }
    slots_.swap(grown);
    return true;
}

// The slot holding `key`, or the empty slot where its probe ends.
size_t StateStore::probe(const uint64_t* key, uint64_t hash) const {
    const size_t mask = slots_.size() - 1;
    size_t at = hash & mask;
    for (; slots_[at]; at = (at + 1) & mask) {
        const uint32_t i = slots_[at] - 1;
        if (meta(i).hash == hash && std::memcmp(this->key(i), key, keyWords_ * 8) == 0) break;
    }
    return at;
}

bool StateStore::contains(const uint64_t* key, uint64_t hash) const { return slots_[probe(key, hash)] != 0; }

StateStore::Insert StateStore::insert(const uint64_t* key, uint64_t hash, uint32_t parent, uint8_t input, uint32_t depth,
                                      uint32_t* index) {
    size_t at = probe(key, hash);
    if (slots_[at]) {
        *index = slots_[at] - 1;
        return Insert::Known;
    }
    const size_t tableSize = slots_.size();
    if (!reserveOne()) return Insert::Full;
    if (slots_.size() != tableSize) at = probe(key, hash);  // the grown table's empty slot for it
    const uint32_t i = static_cast<uint32_t>(count_++);
    std::memcpy(&keyBlocks_[i >> blockBits_][(i & blockMask_) * keyWords_], key, keyWords_ * 8);
    metaBlocks_[i >> blockBits_][i & blockMask_] = Meta{hash, parent, depth, input};
    slots_[at] = i + 1;
    *index = i;
    return Insert::Added;
}

std::vector<int> StateStore::path(uint32_t i) const {
    std::vector<int> inputs;
    for (; parent(i) != kNoParent; i = parent(i)) inputs.push_back(input(i));
    std::reverse(inputs.begin(), inputs.end());
    return inputs;
}

}  // namespace psc::search
