// Duplicate detection for breadth-first and beam search on the GPU: the
// kernels of DeviceStateSet (DeviceStateSet.h says how they fit together),
// compiled by NVRTC once per machine and cached.  Game-independent: keys are
// `words` 64-bit words long.
//
// Every stored state is known by its 128-bit print (printOf): its key itself
// when the key has at most two words, else the plugin's 64-bit hash beside a
// second, independent one.  Only the layer being expanded and the one being
// built keep their keys (a window each).  Prints, parents and inputs live in
// chunks that double in size (chunkOf), so the store grows without copying.
//
// The table holds, per slot, a state's index in the store, or a child of the
// batch being inserted (kCandidate | its index among the children), or
// kEmpty, or kGone: a state that beam search dropped, which probes pass
// over, so that the state can be reached and stored again.  Equal children
// of one batch meet in one slot, where the smallest
// index wins (atomicMin), so the store receives each new state once, from
// the first parent and input that reach it, in the children's order: the
// same states, in the same order, as the host's store (search/StateStore.h).

typedef unsigned int u32;
typedef unsigned long long u64;

#define PSC_EMPTY 0xffffffffu
#define PSC_CANDIDATE 0x80000000u
#define PSC_GONE 0x7fffffffu      // no state index: the store holds fewer than 2^31 - 1
#define PSC_NO_PARENT 0xffffffffu // the first state's parent (StateStore::kNoParent)
#define PSC_DROPPED 0xfffffffeu   // a dropped state's parent: rehashing leaves it out
#define PSC_BINS 65536            // the beam cut's histogram: 16 bits of the estimate at a time
#define PSC_BLOCK 1024  // threads a block of the count and append kernels: one count per PSC_BLOCK children

// psc_expand's flags (runtime/psc_plugin.h).
#define PSC_WON 1u
#define PSC_UNCHANGED 2u
#define PSC_CUT_OFF 4u
#define PSC_INVALID 8u
#define PSC_TIMED_OUT 16u

#define PSC_FIRST_CHUNK_BITS 16

struct StateSet {
    // Chunk c holds states [2^16 (2^c - 1), 2^16 (2^(c+1) - 1)) (the last
    // maybe fewer) in three arrays, chunks[3c..3c+2]: their prints (two words
    // each), the states they were first reached from (u32) and by which input
    // (a byte: its index among the search's inputs).
    void* const* chunks;
    u32* table;              // 2^tableBits slots
    u64* nextKeys;           // the keys of states [nextBase, nextBase + nextCapacity): the layer being built
    u32* nextEstimates;      // beside them their distance estimates (beam search; else null)
    const u32* layerStates;  // the store index of each state of the layer being expanded (null: contiguous)
    u32 tableMask;
    u32 tableBits;
    u32 words;
    u32 capacity;
    u32 nextBase;
    u32 nextCapacity;
};

// What the host reads after each batch.
struct Counters {
    u64 won;        // (parent << 8 | input) of the first winning child, or all ones
    u32 size;       // states in the store
    u32 base;       // the store's size before the last batch's states
    u32 invalid;    // a child the plugin refused to expand
    u32 overflow;   // new states the store had no room for
    u32 timedOut;   // a child the expansion's deadline left out
};

// A state's chunk and its index there.
struct ChunkPlace {
    u32 chunk;
    u32 offset;
};

__device__ __forceinline__ ChunkPlace placeOf(u32 state) {
    const u32 biased = state + (1u << PSC_FIRST_CHUNK_BITS);
    const u32 top = 31 - __clz(biased);  // floor(log2(biased))
    return ChunkPlace{top - PSC_FIRST_CHUNK_BITS, biased - (1u << top)};
}

__device__ __forceinline__ u64* printAt(const StateSet& s, u32 state) {
    const ChunkPlace p = placeOf(state);
    return static_cast<u64*>(s.chunks[3 * p.chunk]) + 2 * static_cast<u64>(p.offset);
}

// A state's entry in one of its chunk's per-state arrays (1: parents, 2: inputs).
template <typename T>
__device__ __forceinline__ T* entryAt(const StateSet& s, u32 state, int array) {
    const ChunkPlace p = placeOf(state);
    return static_cast<T*>(s.chunks[3 * p.chunk + array]) + p.offset;
}

__device__ __forceinline__ u32* parentAt(const StateSet& s, u32 state) { return entryAt<u32>(s, state, 1); }

// The store index of the layer's state `position` from the batch's first
// (firstParent: a store index where the layer is contiguous, else a position in it).
__device__ __forceinline__ u32 parentOf(const StateSet& s, u32 firstParent, u32 position) {
    return s.layerStates ? s.layerStates[firstParent + position] : firstParent + position;
}

__device__ __forceinline__ void recordParent(const StateSet& s, u32 state, u32 parent, unsigned char input) {
    *parentAt(s, state) = parent;
    *entryAt<unsigned char>(s, state, 2) = input;
}

__device__ __forceinline__ u64 mix64(u64 x) {
    x ^= x >> 33;
    x *= 0xFF51AFD7ED558CCDull;
    x ^= x >> 33;
    x *= 0xC4CEB9FE1A85EC53ull;
    x ^= x >> 33;
    return x;
}

// A key's print: the key itself when it fits in two words (states are then
// told apart exactly), else psc_expand's hash beside a second 64-bit hash of
// other constants and another mixing (a false match needs both to collide:
// about n^2 / 2^129 for n states, 10^-20 at 2^31).
__device__ __forceinline__ void printOf(const u64* key, u64 hash, u32 words, u64* print) {
    if (words <= 2) {
        print[0] = key[0];
        print[1] = words == 2 ? key[1] : 0;
        return;
    }
    u64 h = 0x6A09E667F3BCC909ull + words;
    for (u32 i = 0; i < words; ++i) h = mix64(h ^ (key[i] + 0x9E3779B97F4A7C15ull * (i + 1)));
    print[0] = hash;
    print[1] = h;
}

// The print's home slot, depending on every bit of it.
__device__ __forceinline__ u32 slotOfPrint(const u64* print, u32 bits) {
    return static_cast<u32>(mix64(print[0] ^ mix64(print[1] + 0x3C6EF372FE94F82Bull)) >> (64 - bits));
}

__device__ __forceinline__ bool sameKey(const u64* a, const u64* b, u32 words) {
    for (u32 i = 0; i < words; ++i) {
        if (a[i] != b[i]) return false;
    }
    return true;
}

// Among a block's PSC_BLOCK threads (all of them calling), how many before
// this one have `flag` set.
__device__ __forceinline__ u32 rankInBlock(bool flag) {
    __shared__ u32 warpCounts[PSC_BLOCK / 32];
    const u32 lane = threadIdx.x & 31;
    const u32 warp = threadIdx.x >> 5;
    const u32 ballot = __ballot_sync(0xffffffffu, flag);
    if (lane == 0) warpCounts[warp] = __popc(ballot);
    __syncthreads();
    u32 rank = __popc(ballot & ((1u << lane) - 1));
    for (u32 w = 0; w < warp; ++w) rank += warpCounts[w];
    return rank;
}

__device__ __forceinline__ bool isNew(const u32* table, const u32* slotOf, u32 child) {
    const u32 slot = slotOf[child];
    return slot != PSC_EMPTY && table[slot] == (PSC_CANDIDATE | child);
}

// One thread a child: records a win, or claims the child's slot unless an
// equal state is stored or an equal child with a smaller index claimed it.
// Children are compared with children by key, with stored states by print.
extern "C" __global__ void psc_set_insert(StateSet s, const u64* children, const unsigned char* flags, const u64* hashes,
                                          u32 count, u32 inputCount, u32 firstParent, u32* slotOf, u64* childPrints,
                                          Counters* counters) {
    const u32 child = blockIdx.x * blockDim.x + threadIdx.x;
    if (child >= count) return;
    slotOf[child] = PSC_EMPTY;
    const u32 f = flags[child];
    if (f & PSC_INVALID) {
        atomicOr(&counters->invalid, 1u);
        return;
    }
    if (f & PSC_TIMED_OUT) {
        atomicOr(&counters->timedOut, 1u);
        return;
    }
    if (f & PSC_WON) {
        atomicMin(&counters->won, (static_cast<u64>(parentOf(s, firstParent, child / inputCount)) << 8) | (child % inputCount));
        return;
    }
    if (f & (PSC_UNCHANGED | PSC_CUT_OFF)) return;  // kChildNotSearched (SearchRun.h)
    const u64* key = children + static_cast<u64>(child) * s.words;
    u64 print[2];
    printOf(key, hashes[child], s.words, print);
    childPrints[2 * static_cast<u64>(child)] = print[0];
    childPrints[2 * static_cast<u64>(child) + 1] = print[1];
    const u32 mine = PSC_CANDIDATE | child;
    // The host keeps the table at most about three quarters full, so the probe ends.
    for (u32 slot = slotOfPrint(print, s.tableBits);; slot = (slot + 1) & s.tableMask) {
        u32 held = __ldcg(s.table + slot);
        if (held == PSC_EMPTY) {
            held = atomicCAS(s.table + slot, PSC_EMPTY, mine);
            if (held == PSC_EMPTY) {
                slotOf[child] = slot;
                return;
            }
        }
        if (held & PSC_CANDIDATE) {
            if (sameKey(key, children + static_cast<u64>(held & ~PSC_CANDIDATE) * s.words, s.words)) {
                atomicMin(s.table + slot, mine);
                slotOf[child] = slot;
                return;
            }
        } else if (held != PSC_GONE) {
            const u64* stored = printAt(s, held);
            if (stored[0] == print[0] && stored[1] == print[1]) return;
        }
    }
}

// The new states among each block's PSC_BLOCK children.
extern "C" __global__ void psc_set_count(const u32* table, const u32* slotOf, u32 count, u32* blockCounts) {
    const u32 child = blockIdx.x * PSC_BLOCK + threadIdx.x;
    const int fresh = child < count && isNew(table, slotOf, child);
    const int n = __syncthreads_count(fresh);
    if (threadIdx.x == 0) blockCounts[blockIdx.x] = static_cast<u32>(n);
}

// One block: the block counts become their exclusive prefix sums, and the
// store's size grows by their total (counters null: the beam cut's counts).
extern "C" __global__ void psc_set_scan(u32* blockCounts, u32 blocks, Counters* counters) {
    __shared__ u32 sums[PSC_BLOCK];
    const u32 t = threadIdx.x;
    const u32 per = (blocks + PSC_BLOCK - 1) / PSC_BLOCK;
    const u32 begin = min(t * per, blocks);
    const u32 end = min(begin + per, blocks);
    u32 own = 0;
    for (u32 i = begin; i < end; ++i) own += blockCounts[i];
    sums[t] = own;
    __syncthreads();
    for (u32 d = 1; d < PSC_BLOCK; d <<= 1) {
        const u32 add = t >= d ? sums[t - d] : 0;
        __syncthreads();
        sums[t] += add;
        __syncthreads();
    }
    u32 running = sums[t] - own;
    for (u32 i = begin; i < end; ++i) {
        const u32 n = blockCounts[i];
        blockCounts[i] = running;
        running += n;
    }
    if (t == PSC_BLOCK - 1 && counters) {
        counters->base = counters->size;
        counters->size += sums[t];
    }
}

// The new states, in the children's order, appended to the store (their
// keys to the window of the layer being built); their slots then hold their
// store indices.
extern "C" __global__ void psc_set_append(StateSet s, const u64* children, const u64* childPrints, const u32* slotOf,
                                          const int* estimates, u32 count, u32 inputCount, u32 firstParent,
                                          const u32* blockOffsets, Counters* counters) {
    const u32 child = blockIdx.x * PSC_BLOCK + threadIdx.x;
    const bool fresh = child < count && isNew(s.table, slotOf, child);
    const u32 rank = rankInBlock(fresh);
    if (!fresh) return;
    const u64 index = static_cast<u64>(counters->base) + blockOffsets[blockIdx.x] + rank;
    if (index >= s.capacity || index - s.nextBase >= s.nextCapacity) {
        atomicAdd(&counters->overflow, 1u);
        return;
    }
    const u64* key = children + static_cast<u64>(child) * s.words;
    u64* to = s.nextKeys + (index - s.nextBase) * s.words;
    for (u32 i = 0; i < s.words; ++i) to[i] = key[i];
    u64* print = printAt(s, static_cast<u32>(index));
    print[0] = childPrints[2 * static_cast<u64>(child)];
    print[1] = childPrints[2 * static_cast<u64>(child) + 1];
    recordParent(s, static_cast<u32>(index), parentOf(s, firstParent, child / inputCount),
                 static_cast<unsigned char>(child % inputCount));
    if (s.nextEstimates) s.nextEstimates[index - s.nextBase] = static_cast<u32>(estimates[child]);
    s.table[slotOf[child]] = static_cast<u32>(index);
}

// The first state, whose key the host put in the window (index 0): its print, and no parent.
extern "C" __global__ void psc_set_add_root(StateSet s, u64 hash) {
    printOf(s.nextKeys, hash, s.words, printAt(s, 0));
    recordParent(s, 0, PSC_NO_PARENT, 0);
}

// The stored states [0, size) entered into an empty table (a grown one, or
// the first state), but those beam search dropped.
extern "C" __global__ void psc_set_rehash(StateSet s, u32 size) {
    const u32 i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= size || *parentAt(s, i) == PSC_DROPPED) return;
    for (u32 slot = slotOfPrint(printAt(s, i), s.tableBits);; slot = (slot + 1) & s.tableMask) {
        if (atomicCAS(s.table + slot, PSC_EMPTY, i) == PSC_EMPTY) return;
    }
}

// ---- Beam search's cut --------------------------------------------------
// The layer just built, states [nextBase, nextBase + count), keeps the
// `width` with the smallest estimates, ties to the earlier state, in their
// order: the host finds the threshold estimate from two histograms (its high
// then its low 16 bits) and how many states of that estimate to keep, which
// come before a position `tieEnd` (from per-block counts); the kept states'
// keys are packed into the next layer's window beside their store indices,
// and the others dropped: their table slots become kGone and their parent
// kDropped, so that the store no longer knows them.

__device__ __forceinline__ bool kept(u32 estimate, u32 position, u32 threshold, u32 tieEnd) {
    return estimate < threshold || (estimate == threshold && position < tieEnd);
}

// Histogram of the estimates' high 16 bits (high == PSC_BINS), or of the low
// 16 bits of those whose high bits are `high`.
extern "C" __global__ void psc_beam_histogram(const u32* estimates, u32 count, u32 high, u32* bins) {
    const u32 i = blockIdx.x * blockDim.x + threadIdx.x;
    const bool in = i < count && (high == PSC_BINS || estimates[i] >> 16 == high);
    if (!in) return;
    const u32 bin = high == PSC_BINS ? estimates[i] >> 16 : estimates[i] & 0xffffu;
    // One atomic per distinct bin of a warp: estimates cluster.
    const u32 same = __match_any_sync(__activemask(), bin);
    if ((__ffs(same) - 1) == static_cast<int>(threadIdx.x & 31)) atomicAdd(bins + bin, __popc(same));
}

__device__ __forceinline__ void countInBlock(bool in, u32* blockCounts) {
    const int n = __syncthreads_count(in);
    if (threadIdx.x == 0) blockCounts[blockIdx.x] = static_cast<u32>(n);
}

// Per block of PSC_BLOCK states: how many have the threshold estimate.
extern "C" __global__ void psc_beam_count_ties(const u32* estimates, u32 count, u32 threshold, u32* blockCounts) {
    const u32 i = blockIdx.x * PSC_BLOCK + threadIdx.x;
    countInBlock(i < count && estimates[i] == threshold, blockCounts);
}

// Per block of PSC_BLOCK states: how many are kept.
extern "C" __global__ void psc_beam_count_kept(const u32* estimates, u32 count, u32 threshold, u32 tieEnd, u32* blockCounts) {
    const u32 i = blockIdx.x * PSC_BLOCK + threadIdx.x;
    countInBlock(i < count && kept(estimates[i], i, threshold, tieEnd), blockCounts);
}

// The kept states' keys to `layerKeys` and store indices to `layerStates`,
// in order (blockOffsets: psc_set_scan's prefix sums of psc_beam_count_kept's);
// the others dropped.
extern "C" __global__ void psc_beam_pack(StateSet s, u32 count, u32 threshold, u32 tieEnd, const u32* blockOffsets,
                                         u64* layerKeys, u32* layerStates) {
    const u32 i = blockIdx.x * PSC_BLOCK + threadIdx.x;
    const bool in = i < count;
    const bool keep = in && kept(s.nextEstimates[i], i, threshold, tieEnd);
    const u32 rank = rankInBlock(keep);
    if (!in) return;
    const u32 state = s.nextBase + i;
    if (keep) {
        const u64 to = blockOffsets[blockIdx.x] + rank;
        for (u32 k = 0; k < s.words; ++k) layerKeys[to * s.words + k] = s.nextKeys[static_cast<u64>(i) * s.words + k];
        layerStates[to] = state;
        return;
    }
    const u64* print = printAt(s, state);
    for (u32 slot = slotOfPrint(print, s.tableBits);; slot = (slot + 1) & s.tableMask) {
        if (s.table[slot] == state) {
            s.table[slot] = PSC_GONE;
            break;
        }
    }
    *parentAt(s, state) = PSC_DROPPED;
}
