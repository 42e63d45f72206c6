#include "StateStore.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <utility>

namespace psc::search {

namespace {

uint64_t mix64(uint64_t x) {
    x ^= x >> 33;
    x *= 0xFF51AFD7ED558CCDull;
    x ^= x >> 33;
    x *= 0xC4CEB9FE1A85EC53ull;
    x ^= x >> 33;
    return x;
}

uint64_t rotateLeft(uint64_t x, int bits) { return (x << bits) | (x >> (64 - bits)); }

// The print's second half: four independent lanes of xxHash64's round over
// the words (a single chain of mixes waited on every multiply: limerick's
// 46-word keys took longer to print than to find in the table), then mixed
// together.  Independent of the plugin's hash, which is the first half.
uint64_t secondPrint(const uint64_t* key, size_t words) {
    constexpr uint64_t kPrime1 = 0x9E3779B185EBCA87ull;
    constexpr uint64_t kPrime2 = 0xC2B2AE3D27D4EB4Full;
    uint64_t lanes[4] = {kPrime1 + kPrime2, kPrime2, 0, 0 - kPrime1};
    for (size_t i = 0; i < words; ++i) {
        uint64_t& lane = lanes[i & 3];
        lane = rotateLeft(lane + key[i] * kPrime2, 31) * kPrime1;
    }
    const uint64_t h = rotateLeft(lanes[0], 1) + rotateLeft(lanes[1], 7) + rotateLeft(lanes[2], 12) +
                       rotateLeft(lanes[3], 18);
    return mix64(h ^ words);
}

}  // namespace

StateStore::StateStore(size_t keyWords, size_t memoryLimit, Keys keys)
    : keyWords_(keyWords),
      memoryLimit_(memoryLimit),
      // A key of up to four words costs about what its print and a layer's copy of it would.
      keepKeys_(keys == Keys::Kept || keyWords <= 4),
      storedWords_(keepKeys_ ? keyWords : 1) {
    blockBits_ = 16;
    while (blockBits_ > 8 && (size_t{1} << blockBits_) * stateBytes() > (size_t{64} << 20)) --blockBits_;
    blockMask_ = (1u << blockBits_) - 1;
    slots_ = SlotArray(size_t{1} << kFirstTableBits);
}

size_t StateStore::bytes() const {
    const size_t blockStates = size_t{1} << blockBits_;
    return wordBlocks_.size() * blockStates * stateBytes() + slots_.size() * sizeof(uint64_t) + otherBytes_;
}

bool StateStore::reserveOne() {
    if (count_ >= kMaxStates) return false;
    if ((count_ & blockMask_) == 0 && (count_ >> blockBits_) == wordBlocks_.size()) {
        const size_t blockStates = size_t{1} << blockBits_;
        if (bytes() + blockStates * stateBytes() > memoryLimit_) return false;
        wordBlocks_.emplace_back(new (std::nothrow) uint64_t[blockStates * storedWords_]);
        metaBlocks_.emplace_back(new (std::nothrow) Meta[blockStates]);
        if (!wordBlocks_.back() || !metaBlocks_.back()) {
            wordBlocks_.pop_back();
            metaBlocks_.pop_back();
            return false;
        }
    }
    // The table stays at most half full.
    if ((count_ + 1) * 2 > slots_.size() && !growTable()) return false;
    return true;
}

bool StateStore::growTable() {
    const auto began = std::chrono::steady_clock::now();
    const size_t size = slots_.size() * 2;
    if (bytes() + size * sizeof(uint64_t) > memoryLimit_) return false;
    SlotArray grown;
    try {
        grown = SlotArray(size);
    } catch (const std::bad_alloc&) {
        return false;
    }
    // The old slots in order, their new homes (the hash's high bits, which
    // the tag holds while the table has at most 2^32 slots) nearly in order
    // too: a rehash of tens of millions of states by their metas' hashes,
    // written at random, took seconds past a search's time limit.
    const int shift = homeShift_ - 1;
    const size_t mask = size - 1;
    for (const uint64_t slot : slots_) {
        if (!slot) continue;
        const uint64_t hash = shift >= 32 ? slot >> 32 << 32 : meta(indexOf(slot)).hash;
        size_t at = hash >> shift;
        while (grown[at]) at = (at + 1) & mask;
        grown[at] = slot;
    }
    slots_ = std::move(grown);
    homeShift_ = shift;
    secondsPerGrownSlot_ =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count() / static_cast<double>(size);
    return true;
}

// The slot holding `key` (whose second print is `print` where keys are not
// kept), or the empty slot where its probe ends.
size_t StateStore::probe(const uint64_t* key, uint64_t hash, uint64_t print) const {
    const size_t mask = slots_.size() - 1;
    size_t at = homeOf(hash);
    for (; slots_[at]; at = (at + 1) & mask) {
        if ((slots_[at] >> 32) != (hash >> 32)) continue;  // the tag tells most states apart without their meta
        const uint32_t i = indexOf(slots_[at]);
        if (meta(i).hash != hash) continue;
        if (keepKeys_ ? std::memcmp(stored(i), key, keyWords_ * 8) == 0 : stored(i)[0] == print) break;
    }
    return at;
}

bool StateStore::contains(const uint64_t* key, uint64_t hash) const {
    return slots_[probe(key, hash, keepKeys_ ? 0 : secondPrint(key, keyWords_))] != 0;
}

StateStore::Insert StateStore::insert(const uint64_t* key, uint64_t hash, uint32_t parent, uint8_t input, uint32_t depth,
                                      uint32_t* index) {
    const uint64_t print = keepKeys_ ? 0 : secondPrint(key, keyWords_);
    size_t at = probe(key, hash, print);
    if (slots_[at]) {
        *index = indexOf(slots_[at]);
        return Insert::Known;
    }
    const size_t tableSize = slots_.size();
    if (!reserveOne()) return Insert::Full;
    if (slots_.size() != tableSize) at = probe(key, hash, print);  // the grown table's empty slot for it
    const uint32_t i = static_cast<uint32_t>(count_++);
    uint64_t* words = &wordBlocks_[i >> blockBits_][(i & blockMask_) * storedWords_];
    if (keepKeys_) std::memcpy(words, key, keyWords_ * 8);
    else words[0] = print;
    metaBlocks_[i >> blockBits_][i & blockMask_] = Meta{hash, parent, depth, input};
    slots_[at] = slotOf(i, hash);
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
