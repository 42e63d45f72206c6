#include "DeviceStateSet.h"

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include "CacheFile.h"
#include "CudaCompiler.h"
#include "PluginBuilder.h"
#include "StateStore.h"
#include "base/Sha1.h"

namespace psc::search {

const std::string& stateSetKernelSource();  // state_set_kernels.cu, embedded at build time

// state_set_kernels.cu's StateSet, byte for byte.
struct DeviceStateSet::KernelArgs {
    CuDevicePtr chunks, table, nextKeys, nextEstimates, layerStates;
    uint32_t tableMask, tableBits, words, capacity, nextBase, nextCapacity;
};

namespace {

namespace fs = std::filesystem;

// state_set_kernels.cu's Counters, byte for byte.
struct Counters {
    uint64_t won;
    uint32_t size;
    uint32_t base;
    uint32_t invalid;
    uint32_t overflow;
    uint32_t timedOut;
};

constexpr unsigned kCountBlock = 1024;  // PSC_BLOCK
constexpr unsigned kBlock = 256;
constexpr uint32_t kBins = 65536;           // PSC_BINS
constexpr uint64_t kNoWin = ~uint64_t{0};
constexpr size_t kStateBytes = 16 + 4 + 1;  // print, parent, input
// State indices stay below the kernels' candidate bit.
constexpr size_t kMaxCapacity = (size_t{1} << 31) - 1;
constexpr int kFirstChunkBits = 16;  // PSC_FIRST_CHUNK_BITS
constexpr size_t kMaxChunks = 32 - kFirstChunkBits;

// The largest size from `most` down to `least`, in steps of a sixteenth,
// for which `fits` holds; 0 when none does.
template <typename Fits>
size_t largestFitting(size_t most, size_t least, Fits fits) {
    size_t n = most;
    while (n > least && !fits(n)) n = std::max(least, n - std::max<size_t>(n / 16, 1));
    return fits(n) ? n : 0;
}

// Chunk c's first state and nominal size.
size_t chunkStart(size_t c) { return (size_t{1} << (kFirstChunkBits + c)) - (size_t{1} << kFirstChunkBits); }
size_t chunkSize(size_t c) { return size_t{1} << (kFirstChunkBits + c); }

// A table of 2^bits slots holds `capacity` states at most three quarters full.
int tableBitsFor(size_t capacity) {
    int bits = 10;
    while ((size_t{3} << bits) / 4 < capacity) ++bits;
    return bits;
}

// The kernels for this device's architecture: from psc's cache, or compiled by NVRTC into it.
std::string kernelImage(const CudaDriver& d, int device) {
    int major = 0, minor = 0;
    constexpr int kMajor = 75, kMinor = 76;  // CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MAJOR, _MINOR
    d.cuDeviceGetAttribute(&major, kMajor, device);
    d.cuDeviceGetAttribute(&minor, kMinor, device);
    const int arch = major * 10 + minor;
    const std::string& source = stateSetKernelSource();
    const fs::path path = fs::path(defaultCacheDir()) / "search" /
                          (sha1Hex(source + "\nsm_" + std::to_string(arch)) + ".cubin");
    if (std::ifstream in(path, std::ios::binary); in) {
        std::string image((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        if (!image.empty()) return image;
    }
    CudaCompileOptions options;
    options.architecture = arch;
    const CudaCompileResult r = compileCuda(source, "psc_state_set", options);
    if (!r.ok) throw std::runtime_error("compiling search's GPU kernels for sm_" + std::to_string(arch) + ": " + r.log);
    std::string image(r.cubin.begin(), r.cubin.end());
    std::error_code ec;
    fs::create_directories(path.parent_path(), ec);
    writeCacheFile(path, image);  // a cache: without it the next search compiles again
    return image;
}

const CudaDriver& driverOrThrow() {
    std::string problem;
    const CudaDriver* d = cudaDriver(&problem);
    if (!d) throw std::runtime_error(problem);
    return *d;
}

}  // namespace

void DeviceStateSet::check(CuResult result, const char* what) const {
    if (result) throw std::runtime_error(cudaErrorText(result, what));
}

DeviceStateSet::DeviceStateSet(StateSpace& space, size_t memoryLimit, bool withEstimates)
    : space_(space), d_(driverOrThrow()), withEstimates_(withEstimates), words_(space.keyWords()) {
    try {
        acquire(memoryLimit);
    } catch (...) {
        release();  // the destructor does not run for a constructor that throws
        throw;
    }
}

void DeviceStateSet::acquire(size_t memoryLimit) {
    int ordinal = space_.deviceOrdinal();
    check(d_.cuDeviceGet(&device_, ordinal), "selecting the CUDA device");
    check(d_.cuDevicePrimaryCtxRetain(&context_, device_), "opening the CUDA context");
    CudaContextScope scope(context_);
    const std::string image = kernelImage(d_, device_);
    check(d_.cuModuleLoadData(&module_, image.data()), "loading search's GPU kernels");
    const std::pair<CuFunction*, const char*> kernels[] = {{&insert_, "psc_set_insert"},
                                                          {&count_, "psc_set_count"},
                                                          {&scan_, "psc_set_scan"},
                                                          {&append_, "psc_set_append"},
                                                          {&rehash_, "psc_set_rehash"},
                                                          {&addRoot_, "psc_set_add_root"},
                                                          {&histogram_, "psc_beam_histogram"},
                                                          {&tieCount_, "psc_beam_count_ties"},
                                                          {&keptCount_, "psc_beam_count_kept"},
                                                          {&pack_, "psc_beam_pack"}};
    for (const auto& [f, name] : kernels) check(d_.cuModuleGetFunction(f, module_, name), name);
    check(d_.cuStreamCreate(&stream_, 0), "creating a CUDA stream");
    space_.setStream(stream_);

    const size_t children = space_.maxBatch() * space_.inputs().size();
    const size_t blocks = (children + kCountBlock - 1) / kCountBlock;
    check(d_.cuMemAlloc(&slotOf_, children * 4), "allocating device memory for search");
    check(d_.cuMemAlloc(&childPrints_, children * 16), "allocating device memory for search");
    check(d_.cuMemAlloc(&blockCounts_, std::max<size_t>(blocks, 1) * 4), "allocating device memory for search");
    check(d_.cuMemAlloc(&counters_, sizeof(Counters)), "allocating device memory for search");
    check(d_.cuMemAlloc(&chunkTable_, 3 * kMaxChunks * sizeof(CuDevicePtr)), "allocating device memory for search");
    if (withEstimates_) check(d_.cuMemAlloc(&bins_, kBins * 4), "allocating device memory for search");
    const Counters start{kNoWin, 0, 0, 0, 0, 0};
    check(d_.cuMemcpyHtoD(counters_, &start, sizeof start), "clearing search's counters");

    size_t free = 0, total = 0;
    check(d_.cuMemGetInfo(&free, &total), "reading the device's free memory");
    const size_t usable = free / 10 * 9;
    memoryLimit_ = memoryLimit ? std::min(memoryLimit, usable) : usable;
    // Room for the first batches' children; later batches double it.
    grow(std::max<size_t>(size_t{1} << 16, children + 1), 1);
}

DeviceStateSet::~DeviceStateSet() { release(); }

void DeviceStateSet::release() {
    if (!context_) return;
    CudaContextScope scope(context_);
    if (stream_) {
        d_.cuStreamSynchronize(stream_);
        try {
            space_.setStream(nullptr);
        } catch (const std::exception&) {
            // The batch's stream only matters while this set exists.
        }
    }
    for (CuDevicePtr p : chunks_) d_.cuMemFree(p);
    for (CuDevicePtr p : {chunkTable_, table_, layerKeys_, nextKeys_, slotOf_, childPrints_, blockCounts_, counters_,
                          layerStates_, bins_, cutCounts_}) {
        if (p) d_.cuMemFree(p);
    }
    if (module_) d_.cuModuleUnload(module_);
    if (stream_) d_.cuStreamDestroy(stream_);
    d_.cuDevicePrimaryCtxRelease(device_);
}

size_t DeviceStateSet::bytes() const {
    return capacity_ * kStateBytes + (capacity_ ? size_t{4} << tableBits_ : 0) +
           windowBytes(layerCapacity_ + nextCapacity_) + (layerStatesCapacity_ + cutCountsCapacity_) * 4 +
           (bins_ ? kBins * 4 : 0);
}

CuDevicePtr DeviceStateSet::nextEstimates() const {
    return withEstimates_ && nextKeys_ ? nextKeys_ + nextCapacity_ * words_ * 8 : 0;
}

DeviceStateSet::KernelArgs DeviceStateSet::kernelArgs() const {
    return KernelArgs{chunkTable_,
                      table_,
                      nextKeys_,
                      nextEstimates(),
                      layerCut_ ? layerStates_ : 0,
                      static_cast<uint32_t>((size_t{1} << tableBits_) - 1),
                      static_cast<uint32_t>(tableBits_),
                      static_cast<uint32_t>(words_),
                      static_cast<uint32_t>(capacity_),
                      static_cast<uint32_t>(nextBase_),
                      static_cast<uint32_t>(nextCapacity_)};
}

// States [0, count) entered into the (empty) table.
void DeviceStateSet::rehash(size_t count) {
    KernelArgs s = kernelArgs();
    uint32_t n = static_cast<uint32_t>(count);
    void* args[] = {&s, &n};
    launch(rehash_, count, kBlock, args);
}

void DeviceStateSet::launch(CuFunction f, size_t threads, unsigned block, void** args) {
    const size_t grid = (threads + block - 1) / block;
    if (grid == 0) return;
    check(d_.cuLaunchKernel(f, static_cast<unsigned>(grid), 1, 1, block, 1, 1, 0, stream_, args, nullptr),
          "launching search's GPU kernels");
}

// A store of at least `minimum` states (and `wanted` if memory allows):
// chunks added, the last one cut to what memory holds, and the table rebuilt
// for the new capacity.  The chunks already filled stay where they are.
void DeviceStateSet::grow(size_t wanted, size_t minimum) {
    if (minimum > kMaxCapacity) return;
    wanted = std::min(std::max(wanted, minimum), kMaxCapacity);
    const size_t oldTable = capacity_ ? size_t{4} << tableBits_ : 0;
    // Memory for `more` states in a new chunk; the old table is freed before the new one is made.
    auto fits = [&](size_t more) {
        return bytes() - oldTable + more * kStateBytes + (size_t{4} << tableBitsFor(capacity_ + more)) <= memoryLimit_;
    };
    CudaContextScope scope(context_);
    const size_t before = capacity_;
    while (capacity_ < wanted && !lastChunk_ && chunks_.size() < 3 * kMaxChunks) {
        const size_t c = chunks_.size() / 3;
        const size_t least = minimum > capacity_ ? minimum - capacity_ : 1;
        // Where the whole chunk does not fit, as much of it as does: the last chunk.
        const size_t states = largestFitting(std::min(chunkSize(c), kMaxCapacity - chunkStart(c)), least, fits);
        if (states == 0) break;
        CuDevicePtr parts[3] = {0, 0, 0};
        const size_t bytes[3] = {states * 16, states * 4, states};
        bool allocated = true;
        for (int i = 0; i < 3 && allocated; ++i) allocated = !d_.cuMemAlloc(&parts[i], bytes[i]);
        if (!allocated) {
            for (CuDevicePtr p : parts) {
                if (p) d_.cuMemFree(p);
            }
            memoryLimit_ = 0;  // the driver's memory ran out before the limit did (another process took some)
            break;
        }
        check(d_.cuMemcpyHtoD(chunkTable_ + 3 * c * sizeof(CuDevicePtr), parts, sizeof parts), "recording a chunk");
        chunks_.insert(chunks_.end(), parts, parts + 3);
        capacity_ = chunkStart(c) + states;
        lastChunk_ = states < chunkSize(c);
    }
    if (capacity_ != before && (!table_ || tableBitsFor(capacity_) != tableBits_)) rebuildTable(tableBitsFor(capacity_));
}

// The table made anew with 2^bits slots, the stored states entered.
void DeviceStateSet::rebuildTable(int bits) {
    CudaContextScope scope(context_);
    check(d_.cuStreamSynchronize(stream_), "waiting for the device");
    if (table_) check(d_.cuMemFree(table_), "freeing device memory");
    table_ = 0;
    if (d_.cuMemAlloc(&table_, size_t{4} << bits)) {
        // Too little memory for the larger table: the old size again, whose memory was just freed.
        memoryLimit_ = 0;
        check(d_.cuMemAlloc(&table_, size_t{4} << tableBits_), "allocating device memory for search");
        capacity_ = std::min(capacity_, (size_t{3} << tableBits_) / 4);
    } else {
        tableBits_ = bits;
    }
    check(d_.cuMemsetD32Async(table_, 0xffffffffu, size_t{1} << tableBits_, stream_), "clearing the table");
    rehash(size_);
    check(d_.cuStreamSynchronize(stream_), "rebuilding search's table");
}

// A window for the layer being built of at least `minimum` keys (and
// `wanted` if memory allows, or twice the present one), its keys copied.
bool DeviceStateSet::growWindow(size_t wanted, size_t minimum) {
    const size_t held = bytes();  // the old window lives until copied
    minimum = std::max(minimum, nextCapacity_ + 1);
    const size_t target = largestFitting(std::min(std::max(wanted, nextCapacity_ * 2), kMaxCapacity), minimum,
                                         [&](size_t keys) { return held + windowBytes(keys) <= memoryLimit_; });
    if (target < minimum) return false;

    CudaContextScope scope(context_);
    check(d_.cuStreamSynchronize(stream_), "waiting for the device");
    CuDevicePtr keys = 0;
    if (d_.cuMemAlloc(&keys, windowBytes(target))) {
        memoryLimit_ = 0;  // as in grow(): the driver's memory ran out first
        return false;
    }
    if (size_ > nextBase_) {
        check(d_.cuMemcpyDtoD(keys, nextKeys_, (size_ - nextBase_) * words_ * 8), "copying the layer's keys");
        if (withEstimates_) {
            check(d_.cuMemcpyDtoD(keys + target * words_ * 8, nextEstimates(), (size_ - nextBase_) * 4),
                  "copying the layer's estimates");
        }
    }
    if (nextKeys_) check(d_.cuMemFree(nextKeys_), "freeing device memory");
    nextKeys_ = keys;
    nextCapacity_ = target;
    return true;
}

bool DeviceStateSet::addRoot() {
    if (size_) throw std::logic_error("DeviceStateSet::addRoot: the store is not empty");
    if (capacity_ == 0 || (nextCapacity_ == 0 && !growWindow(1, 1))) return false;
    CudaContextScope scope(context_);
    check(d_.cuMemcpyHtoD(nextKeys_, space_.root().data(), windowBytes(1)), "storing the first state");
    KernelArgs s = kernelArgs();
    uint64_t hash = space_.rootHash();
    void* args[] = {&s, &hash};
    launch(addRoot_, 1, 1, args);
    const uint32_t one = 1;
    check(d_.cuMemcpyHtoD(counters_ + offsetof(Counters, size), &one, 4), "storing the first state");
    size_ = 1;
    rehash(1);
    return true;
}

bool DeviceStateSet::beginLayer(size_t width) {
    const size_t built = size_ - nextBase_;
    if (width && withEstimates_ && built > width) return cut(width);
    std::swap(layerKeys_, nextKeys_);
    std::swap(layerCapacity_, nextCapacity_);
    layerBase_ = nextBase_;
    nextBase_ = size_;
    layerSize_ = built;
    layerCut_ = false;
    return true;
}

// The layer just built, cut to its `width` best states (beginLayer), which
// become the layer: keys packed into the layer window, store indices beside.
bool DeviceStateSet::cut(size_t width) {
    uint32_t count = static_cast<uint32_t>(size_ - nextBase_);
    uint32_t ties = 0;
    uint32_t best = threshold(count, width, &ties);
    uint32_t end = tieEnd(count, best, ties);

    CudaContextScope scope(context_);
    check(d_.cuStreamSynchronize(stream_), "waiting for the device");
    // The old layer's window and indices go before the new ones are made
    // (tieEnd made the per-block counts' room).
    const size_t blocks = (count + kCountBlock - 1) / kCountBlock;
    if (layerCapacity_ < width) {
        if (layerKeys_) check(d_.cuMemFree(layerKeys_), "freeing device memory");
        layerKeys_ = 0;
        layerCapacity_ = 0;
    }
    if (layerStatesCapacity_ < width) {
        if (layerStates_) check(d_.cuMemFree(layerStates_), "freeing device memory");
        layerStates_ = 0;
        layerStatesCapacity_ = 0;
    }
    const size_t more = (layerCapacity_ ? 0 : windowBytes(width)) + (layerStatesCapacity_ ? 0 : width * 4);
    if (bytes() + more > memoryLimit_) return false;
    if (!layerKeys_) {
        if (d_.cuMemAlloc(&layerKeys_, windowBytes(width))) return false;
        layerCapacity_ = width;
    }
    if (!layerStates_) {
        if (d_.cuMemAlloc(&layerStates_, width * 4)) return false;
        layerStatesCapacity_ = width;
    }

    KernelArgs s = kernelArgs();
    CuDevicePtr estimates = nextEstimates();
    CuDevicePtr noCounters = 0;
    uint32_t blockCount = static_cast<uint32_t>(blocks);
    void* countArgs[] = {&estimates, &count, &best, &end, &cutCounts_};
    launch(keptCount_, blocks * kCountBlock, kCountBlock, countArgs);
    void* scanArgs[] = {&cutCounts_, &blockCount, &noCounters};
    launch(scan_, kCountBlock, kCountBlock, scanArgs);
    void* packArgs[] = {&s, &count, &best, &end, &cutCounts_, &layerKeys_, &layerStates_};
    launch(pack_, blocks * kCountBlock, kCountBlock, packArgs);
    check(d_.cuStreamSynchronize(stream_), "cutting a beam layer");
    dropped_ += count - width;
    layerSize_ = width;
    layerCut_ = true;
    layerBase_ = nextBase_;
    nextBase_ = size_;
    return true;
}

// The estimate `width` states of the `count` just built reach (the width-th
// smallest), and in *ties how many of those with exactly it are kept.
uint32_t DeviceStateSet::threshold(uint32_t count, size_t width, uint32_t* ties) {
    CudaContextScope scope(context_);
    CuDevicePtr estimates = nextEstimates();
    std::vector<uint32_t> bins(kBins);
    // The high 16 bits, then the low ones within the high bin that holds the width-th.
    size_t below = 0;
    uint32_t value = 0;
    for (uint32_t high : {kBins, 0u}) {
        check(d_.cuMemsetD32Async(bins_, 0, kBins, stream_), "clearing the beam's histogram");
        uint32_t select = high == kBins ? kBins : value >> 16;
        void* args[] = {&estimates, &count, &select, &bins_};
        launch(histogram_, count, kBlock, args);
        check(d_.cuStreamSynchronize(stream_), "cutting a beam layer");
        check(d_.cuMemcpyDtoH(bins.data(), bins_, kBins * 4), "reading the beam's histogram");
        uint32_t bin = 0;
        while (below + bins[bin] < width) below += bins[bin++];
        value = high == kBins ? bin << 16 : value | bin;
        if (high != kBins) *ties = static_cast<uint32_t>(width - below);
    }
    return value;
}

// The position before which the first `ties` states whose estimate is
// `threshold` lie (all of them: count).
uint32_t DeviceStateSet::tieEnd(uint32_t count, uint32_t threshold, uint32_t ties) {
    CudaContextScope scope(context_);
    const size_t blocks = (count + kCountBlock - 1) / kCountBlock;
    if (cutCountsCapacity_ < blocks) {
        if (cutCounts_) check(d_.cuMemFree(cutCounts_), "freeing device memory");
        cutCounts_ = 0;
        cutCountsCapacity_ = 0;
        check(d_.cuMemAlloc(&cutCounts_, blocks * 4), "allocating device memory for search");
        cutCountsCapacity_ = blocks;
    }
    CuDevicePtr estimates = nextEstimates();
    void* args[] = {&estimates, &count, &threshold, &cutCounts_};
    launch(tieCount_, blocks * kCountBlock, kCountBlock, args);
    check(d_.cuStreamSynchronize(stream_), "cutting a beam layer");
    std::vector<uint32_t> perBlock(blocks);
    check(d_.cuMemcpyDtoH(perBlock.data(), cutCounts_, blocks * 4), "reading the beam's counts");
    size_t before = 0, block = 0;
    while (block < blocks && before + perBlock[block] < ties) before += perBlock[block++];
    if (block == blocks) return count;
    const size_t first = block * kCountBlock;
    std::vector<uint32_t> values(std::min<size_t>(kCountBlock, count - first));
    check(d_.cuMemcpyDtoH(values.data(), estimates + first * 4, values.size() * 4), "reading the beam's estimates");
    for (size_t i = 0; i < values.size(); ++i) {
        if (values[i] == threshold && ++before == ties) return static_cast<uint32_t>(first + i + 1);
    }
    return count;
}

size_t DeviceStateSet::room(size_t wanted) {
    const size_t inputs = space_.inputs().size();
    if (size_ + wanted * inputs > capacity_) grow(size_ + wanted * inputs, size_ + inputs);
    const size_t building = size_ - nextBase_;
    if (building + wanted * inputs > nextCapacity_) growWindow(building + wanted * inputs, building + inputs);
    if (size_ >= capacity_ || building >= nextCapacity_) return 0;
    // Most children are known states, so a batch may have more children than
    // the store has room (the append kernel reports an overflow), but never
    // more than the table's free slots: a probe must find an empty one.
    const size_t freeSlots = (size_t{1} << tableBits_) - size_ - 1;
    return std::min(wanted, freeSlots / inputs);
}

DeviceStateSet::Outcome DeviceStateSet::expand(size_t first, size_t count) {
    const size_t inputs = space_.inputs().size();
    if (count > space_.maxBatch() || first + count > layerSize_ ||
        size_ + count * inputs >= (size_t{1} << tableBits_)) {
        throw std::logic_error("DeviceStateSet::expand: states outside the layer, or more than room() allows");
    }
    CudaContextScope scope(context_);
    space_.expandResident(reinterpret_cast<const void*>(layerKeys_ + first * words_ * 8), count, withEstimates_);
    KernelArgs s = kernelArgs();
    CuDevicePtr children = reinterpret_cast<CuDevicePtr>(space_.deviceChildren());
    CuDevicePtr flags = reinterpret_cast<CuDevicePtr>(space_.deviceFlags());
    CuDevicePtr hashes = reinterpret_cast<CuDevicePtr>(space_.deviceHashes());
    uint32_t n = static_cast<uint32_t>(count * inputs);
    uint32_t inputCount = static_cast<uint32_t>(inputs);
    CuDevicePtr estimates = withEstimates_ ? reinterpret_cast<CuDevicePtr>(space_.deviceEstimates()) : 0;
    uint32_t firstParent = static_cast<uint32_t>(layerCut_ ? first : layerBase_ + first);
    uint32_t blocks = (n + kCountBlock - 1) / kCountBlock;
    void* insertArgs[] = {&s, &children, &flags, &hashes, &n, &inputCount, &firstParent, &slotOf_, &childPrints_, &counters_};
    launch(insert_, n, kBlock, insertArgs);
    void* countArgs[] = {&table_, &slotOf_, &n, &blockCounts_};
    launch(count_, size_t{blocks} * kCountBlock, kCountBlock, countArgs);
    void* scanArgs[] = {&blockCounts_, &blocks, &counters_};
    launch(scan_, kCountBlock, kCountBlock, scanArgs);
    void* appendArgs[] = {&s,  &children,   &childPrints_, &slotOf_,      &estimates,
                          &n,  &inputCount, &firstParent,  &blockCounts_, &counters_};
    launch(append_, size_t{blocks} * kCountBlock, kCountBlock, appendArgs);
    check(d_.cuStreamSynchronize(stream_), "expanding states on the device");
    Counters c{};
    check(d_.cuMemcpyDtoH(&c, counters_, sizeof c), "reading search's counters");
    if (c.invalid) throw std::runtime_error("the plugin refused to expand a state");
    // New states past either end were left out (an overflow, which stops the search).
    size_ = std::min<size_t>({c.size, capacity_, nextBase_ + nextCapacity_});
    Outcome o;
    o.full = c.overflow != 0;
    o.timedOut = c.timedOut != 0;
    if (c.won != kNoWin) {
        o.won = true;
        o.parent = static_cast<uint32_t>(c.won >> 8);
        o.input = static_cast<int>(c.won & 0xff);
    }
    return o;
}

std::vector<int> DeviceStateSet::path(uint32_t state) const {
    CudaContextScope scope(context_);
    std::vector<int> inputs;
    for (;;) {
        const size_t biased = size_t{state} + (size_t{1} << kFirstChunkBits);
        const int top = 63 - __builtin_clzll(biased);
        const size_t offset = biased - (size_t{1} << top);
        const size_t chunk = 3 * static_cast<size_t>(top - kFirstChunkBits);
        uint32_t parent = 0;
        uint8_t input = 0;
        check(d_.cuMemcpyDtoH(&parent, chunks_[chunk + 1] + 4 * offset, 4), "reading a solution");
        if (parent == StateStore::kNoParent) break;
        check(d_.cuMemcpyDtoH(&input, chunks_[chunk + 2] + offset, 1), "reading a solution");
        inputs.push_back(input);
        state = parent;
    }
    std::reverse(inputs.begin(), inputs.end());
    return inputs;
}

}  // namespace psc::search
