#include <catch2/catch.hpp>

#include <vector>

#include "StateStore.h"

using psc::search::StateStore;

TEST_CASE("state store: keys with equal hashes stay distinct states", "[search]") {
    StateStore store(2, size_t{64} << 20);
    const uint64_t a[2] = {1, 2};
    const uint64_t b[2] = {1, 3};
    uint32_t ia = 0, ib = 0, again = 0;
    REQUIRE(store.insert(a, 42, StateStore::kNoParent, 0, 0, &ia) == StateStore::Insert::Added);
    REQUIRE(store.insert(b, 42, ia, 3, 1, &ib) == StateStore::Insert::Added);
    REQUIRE(ia != ib);
    REQUIRE(store.insert(b, 42, ia, 1, 1, &again) == StateStore::Insert::Known);
    REQUIRE(again == ib);
    REQUIRE(store.input(ib) == 3);  // the first way in is kept
    REQUIRE(store.size() == 2);
}

TEST_CASE("state store: grows past its first table and finds every state again", "[search]") {
    StateStore store(3, size_t{256} << 20);
    const uint32_t n = 200000;
    uint32_t index = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const uint64_t key[3] = {i, i * 7ull, 5};
        REQUIRE(store.insert(key, i * 0x9E3779B97F4A7C15ull, i ? i - 1 : StateStore::kNoParent, i % 5, i, &index) ==
                StateStore::Insert::Added);
        REQUIRE(index == i);
    }
    for (uint32_t i = 0; i < n; i += 997) {
        const uint64_t key[3] = {i, i * 7ull, 5};
        REQUIRE(store.insert(key, i * 0x9E3779B97F4A7C15ull, 0, 0, 0, &index) == StateStore::Insert::Known);
        REQUIRE(index == i);
        REQUIRE(store.key(i)[1] == i * 7ull);
    }
    const std::vector<int> path = store.path(9);
    REQUIRE(path == std::vector<int>{1, 2, 3, 4, 0, 1, 2, 3, 4});
}

TEST_CASE("state store: stops at its memory limit instead of growing", "[search]") {
    StateStore store(4, size_t{4} << 20);
    StateStore::Insert last = StateStore::Insert::Added;
    uint32_t index = 0;
    uint64_t i = 0;
    for (; last == StateStore::Insert::Added && i < 10000000; ++i) {
        const uint64_t key[4] = {i, 0, 0, 0};
        last = store.insert(key, i * 0xBF58476D1CE4E5B9ull, 0, 0, 0, &index);
    }
    REQUIRE(last == StateStore::Insert::Full);
    REQUIRE(store.bytes() <= size_t{4} << 20);
    REQUIRE(store.size() == i - 1);
}

TEST_CASE("state store of prints: keys past four words are known by their print, not kept", "[search]") {
    StateStore store(5, size_t{64} << 20, StateStore::Keys::Prints);
    REQUIRE_FALSE(store.keepsKeys());
    const uint64_t a[5] = {1, 2, 3, 4, 5};
    const uint64_t b[5] = {1, 2, 3, 4, 6};  // the same plugin hash below, another key
    uint32_t ia = 0, ib = 0, again = 0;
    REQUIRE(store.insert(a, 7, StateStore::kNoParent, 0, 0, &ia) == StateStore::Insert::Added);
    REQUIRE(store.insert(b, 7, ia, 2, 1, &ib) == StateStore::Insert::Added);
    REQUIRE(ia != ib);
    REQUIRE(store.insert(b, 7, ia, 4, 1, &again) == StateStore::Insert::Known);
    REQUIRE(again == ib);
    REQUIRE(store.contains(a, 7));
    const uint64_t c[5] = {1, 2, 3, 5, 4};  // a's words reordered
    REQUIRE_FALSE(store.contains(c, 7));
    REQUIRE(store.path(ib) == std::vector<int>{2});
}

TEST_CASE("state store of prints: a state costs the same whatever its key's size", "[search]") {
    StateStore small(5, size_t{1} << 30, StateStore::Keys::Prints);
    StateStore large(400, size_t{1} << 30, StateStore::Keys::Prints);
    StateStore kept(400, size_t{1} << 30, StateStore::Keys::Kept);
    std::vector<uint64_t> key(400, 0);
    uint32_t index = 0;
    for (uint64_t i = 0; i < 100000; ++i) {
        key[0] = i;
        const uint64_t hash = i * 0x9E3779B97F4A7C15ull;
        REQUIRE(small.insert(key.data(), hash, 0, 0, 0, &index) == StateStore::Insert::Added);
        REQUIRE(large.insert(key.data(), hash, 0, 0, 0, &index) == StateStore::Insert::Added);
        REQUIRE(kept.insert(key.data(), hash, 0, 0, 0, &index) == StateStore::Insert::Added);
    }
    REQUIRE(large.bytes() == small.bytes());
    REQUIRE(StateStore(4, size_t{1} << 20, StateStore::Keys::Prints).keepsKeys());  // short keys are kept
    REQUIRE(large.bytes() * 20 < kept.bytes());
    key[0] = 99999;
    REQUIRE(large.contains(key.data(), 99999 * 0x9E3779B97F4A7C15ull));
}

TEST_CASE("state store: memory the search holds beside it counts against its limit", "[search]") {
    StateStore store(4, size_t{4} << 20, StateStore::Keys::Prints);
    uint32_t index = 0;
    const uint64_t first[4] = {1, 0, 0, 0};
    REQUIRE(store.insert(first, 1, StateStore::kNoParent, 0, 0, &index) == StateStore::Insert::Added);
    store.setOtherBytes(size_t{4} << 20);
    uint64_t i = 2;
    StateStore::Insert last = StateStore::Insert::Added;
    for (; last == StateStore::Insert::Added && i < 1000000; ++i) {
        const uint64_t key[4] = {i, 0, 0, 0};
        last = store.insert(key, i * 0xBF58476D1CE4E5B9ull, 0, 0, 0, &index);
    }
    REQUIRE(last == StateStore::Insert::Full);
}

TEST_CASE("state store: says when its next states would grow its table, and about how long that takes", "[search]") {
    StateStore store(1, size_t{64} << 20);
    uint32_t index = 0;
    for (uint64_t i = 0; i < 5000; ++i) {  // past the first table's 4,096 slots: one growth measured
        REQUIRE(store.insert(&i, i * 0x9E3779B97F4A7C15ull, 0, 0, 0, &index) == StateStore::Insert::Added);
    }
    REQUIRE(store.growthSeconds(1) == 0);      // 8,192 slots hold 4,096 states
    REQUIRE(store.growthSeconds(10000) > 0);  // these would double the table again
}
