// SlotArray: the state store's table, a zeroed array of 64-bit slots in a
// mapping of its own, marked for transparent huge pages (madvise: Linux's
// default mode gives them only where asked).  Probes land at random in a
// table of up to gigabytes; with 4 KB pages nearly every probe missed the
// TLB, and breadth-first's inserts waited on the page walks.
#pragma once

#include <cstddef>
#include <cstdint>

namespace psc::search {

class SlotArray {
public:
    SlotArray() = default;
    explicit SlotArray(size_t count);  // zeroed; throws std::bad_alloc
    ~SlotArray();
    SlotArray(SlotArray&& other) noexcept;
    SlotArray& operator=(SlotArray&& other) noexcept;
    SlotArray(const SlotArray&) = delete;
    SlotArray& operator=(const SlotArray&) = delete;

    size_t size() const { return count_; }
    uint64_t& operator[](size_t i) { return data_[i]; }
    const uint64_t& operator[](size_t i) const { return data_[i]; }
    const uint64_t* begin() const { return data_; }
    const uint64_t* end() const { return data_ + count_; }

private:
    size_t bytes() const { return count_ * sizeof(uint64_t); }

    uint64_t* data_ = nullptr;
    size_t count_ = 0;
};

}  // namespace psc::search
