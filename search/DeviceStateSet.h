// Every state a breadth-first or beam search on the GPU has reached, each
// once, in device memory: prints (128 bits that tell states apart), parents and
// inputs, indexed by state, and an open-addressing table of state indices
// over the prints.  Keys are kept only for two layers: the one being expanded
// and the one being built, each in a window of its own.  A state thus costs
// 21 bytes and 5-11 bytes of table, whatever its key's size (a key of atlas'
// large levels is 3.6 kB), up to 2^31 states.
//
// A print is the key itself where the key has at most two words; otherwise
// the plugin's hash and a second, independent 64-bit hash: two states are
// then taken for one with a probability of about 2^-128 a pair (below 10^-20
// that any two of 2^31 states are; state_set_kernels.cu's printOf).  Children
// of one batch are compared with each other by key.
//
// A batch of states is expanded (psc_expand, on the plugin's batch) and its
// children inserted without leaving the device: four kernels
// (state_set_kernels.cu) claim table slots, count the new states per block,
// scan the counts and append the new states in the children's order, so the
// store's contents and order equal the host store's (StateStore.h) for the
// same search.  The host reads 32 bytes a batch: the store's size and the
// first winning child.
//
// States of one breadth-first layer are contiguous in the store and in their
// window, so a layer is expanded straight from it, with no gathering.  The
// store grows by chunks that double in size, never copied, and its window by
// doubling, up to the memory limit; a search that needs more stops there.
//
// Beam search cuts each layer once it is built (beginLayer's width): the
// states with the smallest estimates stay, in their order, and the others
// are dropped, forgotten by the table so that a later layer may store them
// again, as the host's beam search (BeamSearch.cpp) never stored them.  A
// cut layer is no longer contiguous in the store: its window then keeps each
// state's store index beside its key.
#pragma once

#include <cstdint>
#include <vector>

#include "CudaDriver.h"
#include "StateSpace.h"

namespace psc::search {

class DeviceStateSet {
public:
    // On the GPU of `space` (a CUDA space), at most `memoryLimit` bytes of
    // device memory (0: nine tenths of what is free); `withEstimates` keeps
    // each new state's distance estimate for beginLayer's cut.  Throws
    // std::runtime_error when the device or the kernels are unavailable.
    DeviceStateSet(StateSpace& space, size_t memoryLimit, bool withEstimates = false);
    ~DeviceStateSet();
    DeviceStateSet(const DeviceStateSet&) = delete;
    DeviceStateSet& operator=(const DeviceStateSet&) = delete;

    // Stores the space's root as state 0, the first layer; false when the memory limit holds no state.
    bool addRoot();
    // The states stored since the last call (or addRoot) become the layer
    // that expand() takes: the previous layer's keys are dropped.  With a
    // width (and estimates), only the `width` of them with the smallest
    // estimates, ties to the earlier, stay; the others are dropped.  Returns
    // false where the memory limit leaves no room for the cut's buffers.
    bool beginLayer(size_t width = 0);
    size_t layerSize() const { return layerSize_; }
    // Whether a cut has dropped a state.
    bool dropped() const { return dropped_ != 0; }

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
    // Expands states [first, first + count) of the layer begun last, by
    // position in it (count <= room()), and stores their new children, as
    // many as fit; waits for the device.
    Outcome expand(size_t first, size_t count);

    size_t size() const { return size_ - dropped_; }  // the states it knows
    size_t bytes() const;  // device memory held
    std::vector<int> path(uint32_t state) const;  // input indices from the root

private:
    struct KernelArgs;  // the kernels' StateSet
    void acquire(size_t memoryLimit);
    void release();
    void check(CuResult result, const char* what) const;
    void launch(CuFunction f, size_t threads, unsigned block, void** args);
    KernelArgs kernelArgs() const;
    void rehash(size_t count);
    void grow(size_t wanted, size_t minimum);
    void rebuildTable(int bits);
    bool growWindow(size_t wanted, size_t minimum);
    size_t windowBytes(size_t states) const { return states * (words_ * 8 + (withEstimates_ ? 4 : 0)); }
    CuDevicePtr nextEstimates() const;
    bool cut(size_t width);
    uint32_t threshold(uint32_t count, size_t width, uint32_t* ties);
    uint32_t tieEnd(uint32_t count, uint32_t threshold, uint32_t ties);

    StateSpace& space_;
    const CudaDriver& d_;
    CuContext context_ = nullptr;
    int device_ = 0;
    CuStream stream_ = nullptr;
    CuModule module_ = nullptr;
    CuFunction insert_ = nullptr, count_ = nullptr, scan_ = nullptr, append_ = nullptr, rehash_ = nullptr,
               addRoot_ = nullptr, histogram_ = nullptr, tieCount_ = nullptr, keptCount_ = nullptr,
               pack_ = nullptr;
    bool withEstimates_ = false;
    size_t memoryLimit_ = 0;
    size_t words_ = 0;
    size_t size_ = 0;     // states stored, dropped ones included
    size_t dropped_ = 0;  // states beam search dropped
    size_t capacity_ = 0;
    int tableBits_ = 0;
    // The key windows: the layer being expanded (layerSize_ states: [layerBase_,
    // nextBase_), or those of layerStates_ after a cut), and states
    // [nextBase_, size_) being stored, room for layerCapacity_ and
    // nextCapacity_; with estimates, the window's keys are followed by their estimates.
    size_t layerBase_ = 0, nextBase_ = 0, layerSize_ = 0, layerCapacity_ = 0, nextCapacity_ = 0;
    bool layerCut_ = false;
    // The store's chunks, three arrays each (state_set_kernels.cu's StateSet
    // says what they hold): one smaller than its nominal size is the last.
    std::vector<CuDevicePtr> chunks_;
    bool lastChunk_ = false;
    // Device arrays: the chunks' addresses, the table, the windows, per-child
    // slots and prints, per-block counts, the counters.
    CuDevicePtr chunkTable_ = 0, table_ = 0, layerKeys_ = 0, nextKeys_ = 0;
    CuDevicePtr slotOf_ = 0, childPrints_ = 0, blockCounts_ = 0, counters_ = 0;
    // The cut's: the cut layer's store indices, the histogram, per-block counts.
    CuDevicePtr layerStates_ = 0, bins_ = 0, cutCounts_ = 0;
    size_t layerStatesCapacity_ = 0, cutCountsCapacity_ = 0;
};

}  // namespace psc::search
