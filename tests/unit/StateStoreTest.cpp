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
