// ---- psc template: state keys ----------------------------------------------
// A state key is everything that decides an environment's future between two
// inputs, packed into kKeyWords 64-bit words, so that two environments with
// equal keys behave identically under every sequence of inputs (undo aside:
// the undo history is not in the key).  Search (search/) deduplicates on
// keys, and expands them in batches: decode a key over a template
// environment, apply one input, encode the child.
//
// What goes in, and why:
//  - word 0: the entry shown and the screen flags (title screen, message
//    shown, an `again` left pending by a cut-off chain, a level left out of
//    the plugin reached);
//  - the boards of the objects an input can create, destroy or move
//    (kKeyObjects, codegen/KeyObjects.h): the others never leave the places
//    the level gave them, which the template holds;
//  - those objects in the restart target, only if a rule can `checkpoint`
//    (without one it is always the level's first state, as in the template);
//  - the movement boards, only if late rules can leave random movements
//    behind a turn (kMovementsCanLinger; otherwise they are empty between inputs);
//  - the RC4 stream's state, only for games that use random: the same board
//    with another stream position draws other random choices.
// Search's form of a key (foldKey, below) has the cells of objects that only
// their creation tells apart on one of them (codegen/KeyObjects.h).
// Not in the key, taken from the template environment: the level's size, the
// seed (used only by level loads, which search never reaches: a won child
// stays on its level), the episode counters and the batch's settings.
// Positions outside the level and guard rows are always zero, so the boards'
// words are canonical as they are.

namespace psc_game {

constexpr int kKeyBoardWords = kKeyObjectCount * kWords;
constexpr int kKeyCheckpointWords = kHasCheckpoint ? kKeyObjectCount * kWords : 0;
constexpr int kKeyMovementWords = kMovementsCanLinger ? kLayers * 5 * kWords : 0;
#if PSC_USES_RANDOM
constexpr int kKeyRngWords = (256 + 2 + 7) / 8;
#else
constexpr int kKeyRngWords = 0;
#endif
constexpr int kKeyWords = 1 + kKeyBoardWords + kKeyCheckpointWords + kKeyMovementWords + kKeyRngWords;

// The header's bits: the entry (16) and the four screen flags below.
constexpr int kKeyHeaderBits = 20;

PSC_DEVICE PSC_INLINE u64 keyHeader(const Env& e) {
    return static_cast<u64>(static_cast<u16>(e.entry)) | static_cast<u64>(e.titleScreen) << 16 |
           static_cast<u64>(e.textMode) << 17 | static_cast<u64>(e.againing) << 18 | static_cast<u64>(e.unavailable) << 19;
}

// The entry a key's environment shows.
PSC_DEVICE PSC_INLINE int keyEntry(const u64* key) { return static_cast<short>(key[0] & 0xFFFFu); }

PSC_DEVICE inline void encodeKey(const Env& e, u64* key) {
    int at = 0;
    key[at++] = keyHeader(e);
    PSC_UNROLL_STATE for (int k = 0; k < kKeyObjectCount; ++k) {
        PSC_FOR_WORDS(w, kWords, key[at++] = e.obj[kKeyObjects[k]].w[w];);
    }
    if (kHasCheckpoint) {
        PSC_UNROLL_STATE for (int k = 0; k < kKeyObjectCount; ++k) {
            PSC_FOR_WORDS(w, kWords, key[at++] = e.restartTarget.obj[kKeyObjects[k]].w[w];);
        }
    }
    if (kMovementsCanLinger) {
        for (int m = 0; m < kLayers * 5; ++m) {
            for (int w = 0; w < kWords; ++w) key[at++] = e.mov[m].w[w];
        }
    }
#if PSC_USES_RANDOM
    for (int k = 0; k < kKeyRngWords; ++k) {
        u64 v = 0;
        for (int b = 0; b < 8; ++b) {
            const int byte = k * 8 + b;
            const u64 x = byte < 256 ? e.rng.s[byte] : byte == 256 ? e.rng.i : byte == 257 ? e.rng.j : 0;
            v |= x << (8 * b);
        }
        key[at++] = v;
    }
#endif
}

// Overwrites what the key holds; `e` must already be a copy of a template
// environment on the key's entry (its size, seed and restart target).
// Returns whether the key can be a state of that level: no header bits but
// those keyHeader writes, and no object or movement outside the template's
// cells (on a message entry, those of the level shown before it, if any).
// Rules and movement look at the cells next to a match, which the guard
// positions keep within a board's words; a position outside the level (a
// key made by hand) would reach past them, and an expansion plays a turn on
// every screen, title and messages included.  (Checked as
// the words are copied: sokoban's GPU expansion 1.7 % slower, where a check
// of its own, reading the key twice, cost 4 %: docs/results/h200-2026-12-03c/.)
PSC_DEVICE inline bool decodeKey(Env& e, const u64* key) {
    int at = 0;
    const u64 header = key[at++];
    u64 outside = 0;
    e.entry = static_cast<short>(header & 0xFFFFu);
    e.titleScreen = static_cast<u8>((header >> 16) & 1u);
    e.textMode = static_cast<u8>((header >> 17) & 1u);
    e.againing = static_cast<u8>((header >> 18) & 1u);
    e.unavailable = static_cast<u8>((header >> 19) & 1u);
    e.queue = 0;
    e.restarting = 0;
    e.wins = 0;
    e.dormant = 0;
    PSC_UNROLL_STATE for (int k = 0; k < kKeyObjectCount; ++k) {
        PSC_FOR_WORDS(w, kWords,
            const u64 v = key[at++];
            e.obj[kKeyObjects[k]].w[w] = v;
            outside |= v & ~e.inside.w[w];
        );
    }
    if (kHasCheckpoint) {
        for (int k = 0; k < kKeyObjectCount; ++k) {
            for (int w = 0; w < kWords; ++w) {
                const u64 v = key[at++];
                e.restartTarget.obj[kKeyObjects[k]].w[w] = v;
                outside |= v & ~e.inside.w[w];
            }
        }
    }
    if (kMovementsCanLinger) {
        for (int m = 0; m < kLayers * 5; ++m) {
            for (int w = 0; w < kWords; ++w) {
                const u64 v = key[at++];
                e.mov[m].w[w] = v;
                outside |= v & ~e.inside.w[w];
            }
        }
    } else {
        for (int m = 0; m < kLayers * 5; ++m) e.mov[m] = Board::zero();
    }
#if PSC_USES_RANDOM
    for (int k = 0; k < kKeyRngWords; ++k) {
        const u64 v = key[at++];
        for (int b = 0; b < 8; ++b) {
            const int byte = k * 8 + b;
            const u8 x = static_cast<u8>(v >> (8 * b));
            if (byte < 256) e.rng.s[byte] = x;
            else if (byte == 256) e.rng.i = x;
            else if (byte == 257) e.rng.j = x;
        }
    }
#endif
    return (header >> kKeyHeaderBits) == 0 && outside == 0;
}

// Search's form of a key (psc_expand's children, psc_canonical_keys): the
// cells of objects nothing but their creation tells apart on the first of
// them (kKeyFoldInto, codegen/KeyObjects.h), in the level and in the
// restart target.  Its decoded state behaves as the state folded.
PSC_DEVICE inline void foldKey(u64* key) {
    if constexpr (kKeyFolds) {
        for (int part = 0; part < (kHasCheckpoint ? 2 : 1); ++part) {
            u64* boards = key + 1 + part * kKeyBoardWords;
            for (int k = 0; k < kKeyObjectCount; ++k) {
                const int into = kKeyFoldInto[k];
                if (into == k) continue;
                for (int w = 0; w < kWords; ++w) {
                    boards[into * kWords + w] |= boards[k * kWords + w];
                    boards[k * kWords + w] = 0;
                }
            }
        }
    }
}

// A 64-bit hash of a key: four words at a time, each into a lane of its own,
// then the lanes mixed together and a final avalanche.  One chain of
// multiplies over every word made a CPU thread wait on each (about 300 cycles
// for limerick's 46-word keys, a seventh of its breadth-first search).
PSC_DEVICE PSC_INLINE u64 mixKeyWord(u64 h, u64 word) {
    h ^= word * 0x9E3779B97F4A7C15ull;
    return (h << 31 | h >> 33) * 0xBF58476D1CE4E5B9ull;
}

PSC_DEVICE PSC_INLINE u64 hashKey(const u64* key) {
    u64 a = 0x243F6A8885A308D3ull ^ static_cast<u64>(kKeyWords);
    u64 b = 0x13198A2E03707344ull;
    u64 c = 0xA4093822299F31D0ull;
    u64 d = 0x082EFA98EC4E6C89ull;
    int k = 0;
    PSC_UNROLL_STATE for (; k + 4 <= kKeyWords; k += 4) {
        a = mixKeyWord(a, key[k]);
        b = mixKeyWord(b, key[k + 1]);
        c = mixKeyWord(c, key[k + 2]);
        d = mixKeyWord(d, key[k + 3]);
    }
    PSC_UNROLL_STATE for (; k < kKeyWords; ++k) a = mixKeyWord(a, key[k]);
    u64 h = mixKeyWord(mixKeyWord(mixKeyWord(a, b), c), d);
    h ^= h >> 30;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 27;
    h *= 0x94D049BB133111EBull;
    h ^= h >> 31;
    return h;
}

// What one expansion reports besides the child's key.
enum ExpandFlag : u8 { kExpandWon = 1, kExpandUnchanged = 2, kExpandCutOff = 4, kExpandInvalid = 8, kExpandTimedOut = 16 };

// The GPU expands a key over a copy of the template on the thread's stack,
// which the driver reserves for every resident thread: environments stepped
// in the batch (templates/cuda_kernels.h) are too large for that.
constexpr bool kExpandTooLarge = !PSC_STATE_IN_REGISTERS && sizeof(Env) > 128 * 1024;

// The child of `parent` under `input`, in search's form (foldKey), decoded
// over the template `e` (which this overwrites); the level stays as it is
// when the input wins it.  With a deadline (on deadlineClock; 0: none), a
// child not started by then, or whose again chain it cut short, is no child:
// kExpandTimedOut, `child` unwritten or not one.  On the host, psc_expand
// tests whether to start a child (DeadlineWatch,
// runtime/plugin_host/ExpandDeadline.h: a read of the host's clock cost as
// much as a twentieth of a small child).  A parent that is no state of the
// level (decodeKey) is kExpandInvalid, `child` unwritten.
PSC_DEVICE inline u8 expandKey(Env& e, const u64* parent, int input, u64* child, unsigned long long deadline) {
#if defined(__CUDA_ARCH__)
    if (deadlinePassed(deadline)) return kExpandTimedOut;
#endif
    if (!decodeKey(e, parent)) return kExpandInvalid;
    e.stopOnWin = 1;
    e.needsReset = 0;
    e.againMode = kAgainSettle;  // a child is where the input's whole again chain leads
    UndoStack none = {nullptr, 0, 0, 0, nullptr, 0, deadline};
    const bool settled = applyInput(e, none, input);
    encodeKey(e, child);
    foldKey(child);
    // The words' differences or-ed, not a chain of && (a test and a branch a
    // word, 6 % of limerick's breadth-first search on the CPU): one pass the
    // compiler vectorizes.
    u64 differences = 0;
    PSC_UNROLL_STATE for (int k = 0; k < kKeyWords; ++k) differences |= child[k] ^ parent[k];
    const bool same = differences == 0;
    if (!settled && deadlinePassed(deadline)) return kExpandTimedOut;
    return static_cast<u8>((e.wins > 0 ? kExpandWon : 0) | (same ? kExpandUnchanged : 0) | (settled ? 0 : kExpandCutOff));
}

// ---- search's estimate of the inputs a state still needs (winDistance,
// generated after this text from the win conditions): how many cells break
// a `no` condition, and how far the objects of `all` and `some` conditions
// are from what they must be on.  Not a lower bound: one input can move many
// objects, or an object far.

// Manhattan distance from position p to the nearest position of `to` (not empty).
PSC_DEVICE inline int nearestDistance(const Env& e, int p, const Board& to) {
    const int column = columnOf(e);
    const int px = p / column;
    const int py = p % column;
    int best = 1 << 30;
    PSC_FOR_VERTICAL(to, q) {
        const int dx = q / column - px;
        const int dy = q % column - py;
        const int d = (dx < 0 ? -dx : dx) + (dy < 0 ? -dy : dy);
        best = d < best ? d : best;
    }
    return best;
}

// Cells measured against each other at most: past this, a condition counts cells.
constexpr int kMaxDistancePairs = 4096;

// `all a on b`: each a not on b, its distance to the nearest b.
PSC_DEVICE inline int distanceAllOn(const Env& e, const Board& a, const Board& b) {
    const Board off = andNot(a, b);
    const int n = off.count();
    if (n == 0) return 0;
    if (!b.any() || n * b.count() > kMaxDistancePairs) return n;
    int sum = 0;
    PSC_FOR_VERTICAL(off, p) sum += nearestDistance(e, p, b);
    return sum;
}

// `some a on b`: 0 when one is, else the distance of the closest pair.
PSC_DEVICE inline int distanceSomeOn(const Env& e, const Board& a, const Board& b) {
    if ((a & b).any()) return 0;
    if (!a.any() || !b.any() || a.count() * b.count() > kMaxDistancePairs) return 1;
    int best = 1 << 30;
    PSC_FOR_VERTICAL(a, p) {
        const int d = nearestDistance(e, p, b);
        best = d < best ? d : best;
    }
    return best;
}

}  // namespace psc_game
