// Every state a breadth-first search on the GPU has reached, each once, in
// device memory: keys, parents, inputs and hashes in arrays indexed by state,
// and an open-addressing table of state indices over the keys' hashes.  A
// batch of states is expanded (psc_expand, on the plugin's batch) and its
// children inserted without leaving the device: four kernels
// (state_set_kernels.cu) claim table slots, count the new states per block,
// scan the counts and append the new states in the children's order, so the
// store's contents and order equal the host store's (StateStore.h) for the
// same search.  Duplicates are confirmed on the whole key.  The host reads 32
// bytes a batch: the store's size and the first winning child.
//
// States of one breadth-first layer are contiguous in the store, so a layer
// is expanded straight from it, with no gathering.  The store grows by
// doubling up to its memory limit; a search that needs more stops there.
#pragma once

#include <cstdint>
#include <vector>

#include "CudaDriver.h"
#include "StateSpace.h"

namespace psc::search {

class DeviceStateSet {
public:
    // On the GPU of `space` (a CUDA space), at most `memoryLimit` bytes of
    // device memory (0: nine tenths of what is free).  Throws
    // std::runtime_error when the device or the kernels are unavailable.
    DeviceStateSet(StateSpace& space, size_t memoryLimit);
    ~DeviceStateSet();
    DeviceStateSet(const DeviceStateSet&) = delete;
    DeviceStateSet& operator=(const DeviceStateSet&) = delete;

    // Stores the space's root as state 0; false when the memory limit holds no state.
    bool addRoot();

    // The most parents the next expand() may take, up to `wanted` (the store
    // grown for all their children if memory allows).  0 when the store is full.
    size_t room(size_t wanted);

    struct Outcome {
        bool won = false;     // a child won: the first, in the children's order, is
        uint32_t parent = 0;  // this state's
        int input = 0;        // input (its index in space.inputs())
        bool full = false;    // new states were left out: the store is full (stop at the memory limit)
        bool timedOut = false;  // the expansion's deadline left children out (stop at the time limit)
    };
    // Expands states [first, first + count) (count <= room()) and stores
    // their new children, as many as fit; waits for the device.
    Outcome expand(uint32_t first, size_t count);

    size_t size() const { return size_; }
    size_t bytes() const;  // device memory held
    std::vector<int> path(uint32_t state) const;  // input indices from the root

private:
    struct KernelArgs;  // the kernels' StateSet
    void acquire(size_t memoryLimit);
    void release();
    void check(CuResult result, const char* what) const;
    void launch(CuFunction f, size_t threads, unsigned block, void** args);
    KernelArgs kernelArgs() const;
    size_t stateBytes() const;
    void rehash(size_t count);
    bool grow(size_t wanted, size_t minimum);
    void freeArrays();

    StateSpace& space_;
    const CudaDriver& d_;
    CuContext context_ = nullptr;
    int device_ = 0;
    CuStream stream_ = nullptr;
    CuModule module_ = nullptr;
    CuFunction insert_ = nullptr, count_ = nullptr, scan_ = nullptr, append_ = nullptr, rehash_ = nullptr;
    size_t memoryLimit_ = 0;
    size_t words_ = 0;
    size_t size_ = 0;
    size_t capacity_ = 0;
    int tableBits_ = 0;
    // Device arrays: the store, its table, per-child slots, per-block counts, the counters.
    CuDevicePtr keys_ = 0, parents_ = 0, inputs_ = 0, hashes_ = 0, table_ = 0;
    CuDevicePtr slotOf_ = 0, blockCounts_ = 0, counters_ = 0;
};

}  // namespace psc::search
