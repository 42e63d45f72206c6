#include "SlotArray.h"

#include <sys/mman.h>

#include <new>
#include <utility>

namespace psc::search {

SlotArray::SlotArray(size_t count) {
    if (count == 0) return;
    void* p = mmap(nullptr, count * sizeof(uint64_t), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    madvise(p, count * sizeof(uint64_t), MADV_HUGEPAGE);  // a hint: without huge pages the table works as before
    data_ = static_cast<uint64_t*>(p);
    count_ = count;
}

SlotArray::~SlotArray() {
    if (data_) munmap(data_, bytes());
}

SlotArray::SlotArray(SlotArray&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)), count_(std::exchange(other.count_, 0)) {}

SlotArray& SlotArray::operator=(SlotArray&& other) noexcept {
    if (this != &other) {
        if (data_) munmap(data_, bytes());
        data_ = std::exchange(other.data_, nullptr);
        count_ = std::exchange(other.count_, 0);
    }
    return *this;
}

}  // namespace psc::search
