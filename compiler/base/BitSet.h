// A growable bit set of 32-bit words: object sets (bit i = object id i) and
// movement sets (5 bits per collision layer, in the order up, down, left,
// right, action).  There is no cap on the number of objects or layers.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

namespace psc {

class BitSet {
public:
    BitSet() = default;
    explicit BitSet(size_t bits) : words_((bits + 31) / 32, 0u) {}

    size_t wordCount() const { return words_.size(); }
    const std::vector<uint32_t>& words() const { return words_; }
    uint32_t word(size_t i) const { return i < words_.size() ? words_[i] : 0u; }

    void set(size_t bit) {
        grow(bit / 32 + 1);
        words_[bit / 32] |= 1u << (bit % 32);
    }
    void reset(size_t bit) {
        if (bit / 32 < words_.size()) words_[bit / 32] &= ~(1u << (bit % 32));
    }
    bool test(size_t bit) const { return (word(bit / 32) >> (bit % 32)) & 1u; }

    bool none() const {
        for (uint32_t w : words_) {
            if (w) return false;
        }
        return true;
    }
    bool any() const { return !none(); }

    BitSet& operator|=(const BitSet& o) {
        grow(o.words_.size());
        for (size_t i = 0; i < o.words_.size(); ++i) words_[i] |= o.words_[i];
        return *this;
    }
    BitSet& operator&=(const BitSet& o) {
        for (size_t i = 0; i < words_.size(); ++i) words_[i] &= o.word(i);
        return *this;
    }
    // this &= ~o
    BitSet& clear(const BitSet& o) {
        for (size_t i = 0; i < words_.size(); ++i) words_[i] &= ~o.word(i);
        return *this;
    }
    bool intersects(const BitSet& o) const {
        size_t n = std::min(words_.size(), o.words_.size());
        for (size_t i = 0; i < n; ++i) {
            if (words_[i] & o.words_[i]) return true;
        }
        return false;
    }
    bool subsetOf(const BitSet& o) const {
        for (size_t i = 0; i < words_.size(); ++i) {
            if (words_[i] & ~o.word(i)) return false;
        }
        return true;
    }
    bool operator==(const BitSet& o) const {
        size_t n = std::max(words_.size(), o.words_.size());
        for (size_t i = 0; i < n; ++i) {
            if (word(i) != o.word(i)) return false;
        }
        return true;
    }

    // Calls f(bit) for every set bit, ascending.
    void forEach(const std::function<void(size_t)>& f) const {
        for (size_t w = 0; w < words_.size(); ++w) {
            uint32_t bits = words_[w];
            while (bits) {
                int b = __builtin_ctz(bits);
                f(w * 32 + static_cast<size_t>(b));
                bits &= bits - 1;
            }
        }
    }
    std::vector<int> bits() const {
        std::vector<int> out;
        forEach([&](size_t b) { out.push_back(static_cast<int>(b)); });
        return out;
    }
    size_t count() const {
        size_t n = 0;
        for (uint32_t w : words_) n += static_cast<size_t>(__builtin_popcount(w));
        return n;
    }

    // The 5-bit movement field of collision layer `layer`.
    uint32_t field(int layer) const {
        uint32_t v = 0;
        for (int k = 0; k < 5; ++k) v |= static_cast<uint32_t>(test(static_cast<size_t>(5 * layer + k))) << k;
        return v;
    }
    void orField(int layer, uint32_t value) {
        for (int k = 0; k < 5; ++k) {
            if ((value >> k) & 1u) set(static_cast<size_t>(5 * layer + k));
        }
    }

private:
    void grow(size_t words) {
        if (words > words_.size()) words_.resize(words, 0u);
    }
    std::vector<uint32_t> words_;
};

}  // namespace psc
