#include "SlotArray.h"

#include <sys/mman.h>

#include <new>
#include <utility>

namespace psc::search {

SlotArray::SlotArray(size_t count) : count_(count), bytes_(count * sizeof(uint64_t)) {
    if (bytes_ == 0) return;
    void* p = mmap(nullptr, bytes_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    madvise(p, bytes_, MADV_HUGEPAGE);  // a hint: without huge pages the table works as before
    data_ = static_cast<uint64_t*>(p);
}

SlotArray::~SlotArray() {
    if (data_) munmap(data_, bytes_);
}

SlotArray::SlotArray(SlotArray&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)), count_(std::exchange(other.count_, 0)), bytes_(std::exchange(other.bytes_, 0)) {}

SlotArray& SlotArray::operator=(SlotArray&& other) noexcept {
    if (this != &other) {
        if (data_) munmap(data_, bytes_);
        data_ = std::exchange(other.data_, nullptr);
        count_ = std::exchange(other.count_, 0);
        bytes_ = std::exchange(other.bytes_, 0);
    }
    return *this;
}

}  // namespace psc::search
