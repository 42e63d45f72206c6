// ---- psc template: core types -------------------------------------------
// Bitboards, the RC4 random stream, and the state of one environment.  This
// text is part of every generated game source; it follows the game's
// constants (namespace psc_game) and precedes its rules.  It compiles as C++17
// for the CPU and, unchanged, under NVRTC/nvcc for CUDA.
//
// Cells are numbered column-major with one guard row per column:
// position = x * (H + 1) + y.  Guard positions hold nothing, so a run of cells
// that leaves the level meets a guard (or the end of the board) and never
// matches; scanning positions in increasing order visits cells in the
// reference engine's own order (x-major, then y).

// PSC_INLINE marks small helpers and the hot path; PSC_COLD marks the rare
// events (level loads, restarts, undo), compiled once, out of line.
//
// On the GPU, code generation picks one of three state layouts per game
// (PSC_STATE_IN_REGISTERS and PSC_STATE_IN_GROUPS, set above; --gpu-state
// shared is the memory layout with the stepping kernel's copy in shared
// memory, PSC_STATE_IN_SHARED):
//  - registers (small games): the generated rules (PSC_RULE), groups
//    (PSC_GROUP) and layer helpers (PSC_LAYER) are inlined into one body per
//    kernel, so that the environment's boards are registers;
//  - groups: the environment lives in local memory, and each rule group is
//    compiled once, out of line, with its rules and layer helpers inlined into
//    it: it works on a copy of the environment that ptxas keeps in registers,
//    and writes back only what changed (PSC_GROUP_WORKING_COPY).  With
//    PSC_GROUP_SPANS a unit's consecutive groups of a phase are inlined into
//    one function (PSC_SPAN) on one copy instead.  Compile time grows with
//    the largest unit, not with the game;
//  - memory (large games): rules, layer helpers and the turn (PSC_TURN) are
//    compiled once each, out of line, over an environment in local memory,
//    which keeps code size and compile time linear in the game.
// A CPU compiler keeps large rule sets fast without forced inlining and
// compiles them much faster.
//
// Compile units: NVRTC may compile the CUDA code of a memory-layout game as
// PSC_COMPILE_UNITS programs at once, each with PSC_UNIT set, as relocatable
// code then linked (runtime/CudaCompiler.cpp); the system compiler compiles
// a large game's plugin likewise, as objects of some units each (the bits of
// PSC_UNIT_MASK) at once, one per core (runtime/PluginBuilder.cpp).  Unit 0
// defines the kernels and the plugin's host side, units 1.. some of the rules
// and groups each (PSC_COMPILES_UNIT(k)), and the last, PSC_TURN_UNIT, the
// turn (on the CPU the turn is inlined where it is used): these are the only
// functions one unit calls in another (PSC_RULE, PSC_GROUP, PSC_TURN).  Every other function is inline: a unit compiles only
// those it uses, and copies in several units link as one.  Compiled as one
// program (PSC_UNIT not set), the source defines everything.
#if defined(PSC_UNIT)
#define PSC_COMPILES_UNIT(k) ((k) == PSC_UNIT)
#elif defined(PSC_UNIT_MASK)
#define PSC_COMPILES_UNIT(k) (((PSC_UNIT_MASK) >> (k)) & 1)
#else
#define PSC_COMPILES_UNIT(k) 1
#endif
#if defined(__CUDACC__) || defined(__CUDACC_RTC__)
#define PSC_DEVICE __device__
#define PSC_INLINE __forceinline__
#define PSC_COLD inline __noinline__
// A span of rule groups (the groups layout), called from the turn's unit.
#define PSC_SPAN __noinline__
// PSC_RULE_APART: a rule of a group the groups layout keeps out of line (a
// random group too large to compile inlined in time, which cannot be split).
#if PSC_STATE_IN_REGISTERS
#define PSC_RULE __forceinline__
#define PSC_RULE_APART __forceinline__
#define PSC_GROUP __forceinline__
#define PSC_LAYER __forceinline__
#define PSC_TURN __forceinline__
#elif PSC_STATE_IN_GROUPS && defined(PSC_UNIT) && PSC_UNIT > 0 && PSC_UNIT <= PSC_GROUP_UNITS
// A unit of the groups layout's groups on a copy: each group a function, or
// (PSC_GROUP_SPANS) inlined into the unit's spans, which hold the copy.
#define PSC_RULE __forceinline__
#define PSC_RULE_APART __noinline__
#if PSC_GROUP_SPANS
#define PSC_GROUP __forceinline__
#else
#define PSC_GROUP __noinline__
#endif
#define PSC_LAYER __forceinline__
#define PSC_TURN inline __noinline__
#define PSC_GROUP_COPIES_STATE 1
#else
// The memory layout: each group a function with its rules inlined (a group
// and its rules share a compile unit), but for the groups too large to
// compile so in time, which call their rules (PSC_RULE_APART;
// kInlinedGroupWeight, codegen/CppSource.cpp).
#define PSC_RULE __forceinline__
#define PSC_RULE_APART __noinline__
#define PSC_GROUP __noinline__
#define PSC_LAYER inline __noinline__
#define PSC_TURN inline __noinline__
#endif
#if !defined(PSC_GROUP_COPIES_STATE)
#define PSC_GROUP_COPIES_STATE 0
#endif
#if !PSC_STATE_IN_REGISTERS && defined(PSC_UNIT) && defined(PSC_TURN_UNIT) && PSC_TURN_UNIT > 0
// The turn (PSC_TURN) has a unit of its own, which it keeps out of unit 0,
// whose kernels were the slowest unit to compile: defined there, called
// from unit 0.
#undef PSC_TURN
#define PSC_TURN __noinline__
#define PSC_DEFINES_TURN (PSC_UNIT == PSC_TURN_UNIT)
// The level changes the turn's commands make (restart, the next level) are
// called from unit 0's kernels too: defined there once, not compiled again
// with the turn (a fifth of the turn unit's NVRTC time).
#define PSC_LEVEL_CHANGE __noinline__
#define PSC_DEFINES_LEVEL_CHANGES (PSC_UNIT == 0)
#endif
#if PSC_STATE_IN_REGISTERS && defined(PSC_UNIT)
// The registers layout in two units, compiled at once: unit 0 the stepping
// kernel, unit 1 the other kernels and the level changes the stepping kernel
// calls out of line, which took a third of a small game's NVRTC time.
#define PSC_LEVEL_CHANGE __noinline__
#define PSC_DEFINES_LEVEL_CHANGES (PSC_UNIT == 1)
#define PSC_DEFINES_RUN_KERNEL (PSC_UNIT == 0)
#define PSC_DEFINES_OTHER_KERNELS (PSC_UNIT == 1)
#endif
#define PSC_INPUT PSC_INLINE
#define PSC_TABLE __device__ const
// Loops over objects, layers and a board's words are unrolled for boards of
// a few words (PSC_UNROLL_BOARD_WORDS, set above), whose state then fits in
// registers; larger boards live in local memory, and unrolled loops would only
// grow the code, and NVRTC's time, with the level's area.
#if PSC_UNROLL_BOARD_WORDS
#define PSC_UNROLL _Pragma("unroll")
#else
#define PSC_UNROLL _Pragma("unroll 1")
#endif
// Loops over all the state's objects or layers are unrolled only where the
// state is in registers (a board picked by a run-time index would leave the
// registers); over local memory they stay loops, which keeps the turn's code,
// and its compile time, small.
#if PSC_STATE_IN_REGISTERS || PSC_GROUP_COPIES_STATE
#define PSC_UNROLL_STATE PSC_UNROLL
#else
#define PSC_UNROLL_STATE _Pragma("unroll 1")
#endif
// Keeps a rule group's passes a loop (the memory layout's groups,
// codegen/RuleCode.cpp): NVVM unrolled a small group's loop of up to 200
// passes, and ptxas took 0.4-1.2 s over each such group of atlas (its rules
// inlined) against 20-50 ms looped.
#define PSC_PASSES _Pragma("unroll 1")
// Movement over whole boards moves a collision layer's objects in a loop over
// a table of them in the memory layout: atlas's turn unit took half the
// NVRTC time with its 18-object layer's moves written out, and its steps run
// 9 % faster looped (one H200).  The groups layout keeps them written out
// (kettle and takeheart stepped 5-6 % slower looped), as registers must.
#if !PSC_STATE_IN_REGISTERS && !PSC_STATE_IN_GROUPS
#define PSC_LAYER_MOVES_ROLLED 1
#else
#define PSC_LAYER_MOVES_ROLLED 0
#endif
// A match whose rows each match once writes its cells as board operations
// at their one-bit boards instead of at positions (codegen/RuleCode.cpp's
// one-match paths of rules of several rows, and direction sets) in the
// registers layout: slidings, whose move counter's two-row rules and ball
// swaps' four-row ones run each step, stepped 1.46x as fast, notsnake 1.01x
// (one H200).  Over local memory (cm_0243 0.94x, limerick 0.97x) and on
// the CPU (slidings 0.95x) positions stay.
#if !defined(PSC_MASK_WRITES)
#define PSC_MASK_WRITES PSC_STATE_IN_REGISTERS
#endif
#else
#define PSC_DEVICE
// Forced inlining when optimising (unoptimised builds of very large games
// compile much faster without it).
#if defined(__OPTIMIZE__)
#define PSC_INLINE inline __attribute__((always_inline))
#else
#define PSC_INLINE inline
#endif
// `inline` where a function is compiled in every compile unit (the host
// side of large games is compiled in parallel units, as the CUDA code is).
#define PSC_COLD inline __attribute__((noinline))
#define PSC_RULE
#define PSC_RULE_APART
#define PSC_GROUP
#define PSC_SPAN
#define PSC_GROUP_COPIES_STATE 0
#define PSC_LAYER inline
#define PSC_TURN PSC_INLINE
// One copy of an input's processing, called wherever the host steps (every
// stepping loop and the search's expansion) instead of inlined into each:
// large games' plugins compile about a tenth faster (atlas), and the call
// costs nothing next to a turn.
#define PSC_INPUT inline __attribute__((noinline))
#define PSC_TABLE static const
#define PSC_UNROLL
#define PSC_UNROLL_STATE
#define PSC_PASSES
// Tests build the GPU memory layout's form on the CPU with -DPSC_LAYER_MOVES_ROLLED=1,
// and the registers layout's writes with -DPSC_MASK_WRITES=1.
#if !defined(PSC_LAYER_MOVES_ROLLED)
#define PSC_LAYER_MOVES_ROLLED 0
#endif
#if !defined(PSC_MASK_WRITES)
#define PSC_MASK_WRITES 0
#endif
#endif

// Loops over a board's words.  Where they are unrolled (PSC_UNROLL_BOARD_WORDS),
// the preprocessor writes out one step a word (PSC_WORD_STEPS, which the
// generated code defines for its word count, codegen/CppSource.cpp): NVVM
// then has no loop to unroll in each of the thousands of board operations a
// stepping kernel inlines, which took a fifth of its compile time (slidings'
// stepping unit, docs/performance.md), and one CPU thread steps limerick's
// five-word boards 2.6x as fast.  On the GPU only where the generated code
// says so (PSC_GPU_WORDS_WRITTEN_OUT: elsewhere the kernels stepped slower).
// The body may return; it may not break or continue.
#define PSC_WORD_LOOP(i, n, ...) do { PSC_UNROLL for (int i = 0; i < (n); ++i) { __VA_ARGS__ } } while (0)
#if PSC_UNROLL_BOARD_WORDS && (!defined(__CUDACC__) || PSC_GPU_WORDS_WRITTEN_OUT)
#define PSC_WORD_STEP(k, n, i, ...) \
    if constexpr ((k) < (n)) {      \
        constexpr int i = (k);      \
        __VA_ARGS__                 \
    }
#define PSC_FOR_WORDS(i, n, ...) do { PSC_WORD_STEPS(n, i, __VA_ARGS__) } while (0)
#else
#define PSC_FOR_WORDS PSC_WORD_LOOP
#endif
// The loops over a rule's matched cells (PSC_FOR_VERTICAL, PSC_FOR_HORIZONTAL)
// stay loops on the GPU: with the words written out they became innermost
// loops, which NVVM unrolled into longer kernels.
#if defined(__CUDACC__) && PSC_GPU_WORDS_WRITTEN_OUT
#define PSC_CELL_LOOP _Pragma("unroll 1")
#else
#define PSC_CELL_LOOP
#endif
#if !defined(PSC_DEFINES_TURN)
#define PSC_DEFINES_TURN 1
#endif
#if !defined(PSC_LEVEL_CHANGE)
#define PSC_LEVEL_CHANGE PSC_COLD
#define PSC_DEFINES_LEVEL_CHANGES 1
#endif
// Every kernel is in unit 0, but for the registers layout's two units.
#if !defined(PSC_DEFINES_RUN_KERNEL)
#define PSC_DEFINES_RUN_KERNEL PSC_COMPILES_UNIT(0)
#define PSC_DEFINES_OTHER_KERNELS PSC_COMPILES_UNIT(0)
#endif
// The turn calls a rule group only while every board that all its rules
// need holds something (RuleCode's applyEarlyRules and applyLateRules): it
// saves the call and the boards' loads of the group's rules, which mostly
// match nothing (one H100: takeheart 3.3x, atlas 1.6x; one CPU thread:
// takeheart 2.1x, atlas 1.35x; docs/performance.md).  With the state in
// registers the code is one body, where the rules' own first test is as
// cheap: there the test is left out and the code stays as it was.
#if (defined(__CUDACC__) || defined(__CUDACC_RTC__)) && PSC_STATE_IN_REGISTERS
#define PSC_GROUP_NEEDS(present) true
#else
#define PSC_GROUP_NEEDS(present) (present)
#endif
// Likewise a group calls each of its rules only while the boards that rule
// needs hold something, where rules are out of line (the memory layout; the
// CPU decides for itself).
#if (defined(__CUDACC__) || defined(__CUDACC_RTC__)) && (PSC_STATE_IN_REGISTERS || PSC_GROUP_COPIES_STATE)
#define PSC_RULE_NEEDS(present) true
#else
#define PSC_RULE_NEEDS(present) (present)
#endif

namespace psc_game {

typedef unsigned long long u64;
typedef unsigned int u32;
typedef unsigned short u16;
typedef unsigned char u8;

PSC_DEVICE PSC_INLINE int lowestBit(u64 x) {
#if defined(__CUDA_ARCH__)
    return __ffsll(static_cast<long long>(x)) - 1;
#else
    return __builtin_ctzll(x);
#endif
}

PSC_DEVICE PSC_INLINE int popcount(u64 x) {
#if defined(__CUDA_ARCH__)
    return __popcll(x);
#else
    return __builtin_popcountll(x);
#endif
}

// On the GPU a board indexed by a run-time word number would be moved to
// local memory; boards of a few words select the word with a chain of
// compares instead, which keeps them in registers.
#if defined(__CUDA_ARCH__) && PSC_STATE_IN_REGISTERS
constexpr bool kSelectWords = kWords > 1 && kWords <= 4;
#elif defined(__CUDA_ARCH__) && PSC_GROUP_COPIES_STATE
// A group's copy is only as large as the boards it touches.
constexpr bool kSelectWords = kWords > 1 && kWords <= 8;
#else
constexpr bool kSelectWords = false;
#endif

// One bit per cell position.
struct Board {
    u64 w[kWords];

#if defined(__CUDA_ARCH__) && !PSC_UNROLL_BOARD_WORDS
    // A large board is copied by a loop: the implicit copy would become one
    // load and one store per word at every copy (minutes of NVRTC time on a
    // 5,000-cell level).
    Board() = default;
    PSC_DEVICE PSC_INLINE Board(const Board& o) { *this = o; }
    PSC_DEVICE PSC_INLINE Board& operator=(const Board& o) {
        PSC_FOR_WORDS(i, kWords, w[i] = o.w[i];);
        return *this;
    }
#endif

    PSC_DEVICE PSC_INLINE static Board zero() {
        Board b;
        PSC_FOR_WORDS(i, kWords, b.w[i] = 0;);
        return b;
    }
    PSC_DEVICE PSC_INLINE bool any() const {
        u64 a = 0;
        PSC_FOR_WORDS(i, kWords, a |= w[i];);
        return a != 0;
    }
    PSC_DEVICE PSC_INLINE u64 word(int i) const {
        if (kWords == 1) return w[0];
        if (!kSelectWords) return w[i];
        u64 v = 0;
        PSC_FOR_WORDS(k, kWords, v = k == i ? w[k] : v;);
        return v;
    }
    // Applies f to word i.
    template <typename F>
    PSC_DEVICE PSC_INLINE void update(int i, F f) {
        if (kWords == 1) {
            w[0] = f(w[0]);
        } else if (!kSelectWords) {
            w[i] = f(w[i]);
        } else {
            PSC_FOR_WORDS(k, kWords, w[k] = k == i ? f(w[k]) : w[k];);
        }
    }
    PSC_DEVICE PSC_INLINE bool test(int p) const { return (word(p >> 6) >> (p & 63)) & 1u; }
    PSC_DEVICE PSC_INLINE void set(int p) {
        const u64 m = 1ull << (p & 63);
        update(p >> 6, [m](u64 v) { return v | m; });
    }
    PSC_DEVICE PSC_INLINE void clear(int p) {
        const u64 m = 1ull << (p & 63);
        update(p >> 6, [m](u64 v) { return v & ~m; });
    }
    // Sets bit p to v; returns whether it changed.  Always stores: storing
    // only a change branches, which ran kettle 5x and slidings 2x slower on
    // the GPU (docs/performance.md).
    PSC_DEVICE PSC_INLINE bool assign(int p, bool v) {
        const bool was = test(p);
        if (v) set(p);
        else clear(p);
        return was != v;
    }
    // Sets every position of `where` to v; returns whether any changed.
    PSC_DEVICE PSC_INLINE bool assignWhere(const Board& where, bool v) {
        u64 changed = 0;
        PSC_FOR_WORDS(i, kWords,
            const u64 next = v ? (w[i] | where.w[i]) : (w[i] & ~where.w[i]);
            changed |= next ^ w[i];
            w[i] = next;
        );
        return changed != 0;
    }
    // The lowest set position (the board must not be empty), and clearing it.
    PSC_DEVICE PSC_INLINE int lowest() const {
        PSC_FOR_WORDS(i, kWords - 1,
            if (w[i]) return i * 64 + lowestBit(w[i]);
        );
        return (kWords - 1) * 64 + lowestBit(w[kWords - 1]);
    }
    PSC_DEVICE PSC_INLINE void dropLowest() {
        bool done = false;
        PSC_FOR_WORDS(i, kWords,
            const bool here = !done && w[i] != 0;
            w[i] = here ? w[i] & (w[i] - 1) : w[i];
            done = done || here;
        );
    }
    PSC_DEVICE PSC_INLINE int count() const {
        int n = 0;
        PSC_FOR_WORDS(i, kWords, n += popcount(w[i]););
        return n;
    }
    PSC_DEVICE PSC_INLINE bool operator==(const Board& o) const {
        u64 d = 0;
        PSC_FOR_WORDS(i, kWords, d |= w[i] ^ o.w[i];);
        return d == 0;
    }
};

PSC_DEVICE PSC_INLINE Board operator&(const Board& a, const Board& b) {
    Board r;
    PSC_FOR_WORDS(i, kWords, r.w[i] = a.w[i] & b.w[i];);
    return r;
}
PSC_DEVICE PSC_INLINE Board operator|(const Board& a, const Board& b) {
    Board r;
    PSC_FOR_WORDS(i, kWords, r.w[i] = a.w[i] | b.w[i];);
    return r;
}
PSC_DEVICE PSC_INLINE Board andNot(const Board& a, const Board& b) {
    Board r;
    PSC_FOR_WORDS(i, kWords, r.w[i] = a.w[i] & ~b.w[i];);
    return r;
}
// b where `keep`, else empty, without a branch (a rule's direction copies
// pick the one that matched, codegen/DirectionVariants.h).
PSC_DEVICE PSC_INLINE Board onlyIf(const Board& b, bool keep) {
    const u64 mask = 0ull - static_cast<u64>(keep);
    Board r;
    PSC_FOR_WORDS(i, kWords, r.w[i] = b.w[i] & mask;);
    return r;
}
// Moves bit `from` of b to `to` (when set).
PSC_DEVICE PSC_INLINE void moveBit(Board& b, int from, int to) {
    const bool held = b.test(from);
    b.clear(from);
    if (held) b.set(to);
}

// The shifts' loops over words: on the GPU they stay loops (PSC_UNROLL) for
// NVVM to unroll, as written out it left the stepping kernels of three- and
// four-word boards 1-1.5 kB more stack (blocks, zenpuzzle, constellationz)
// for at most 0.1 s less compile time; on the CPU they are written out like
// the others (limerick 1.1x on one thread).
#if defined(__CUDACC__)
#define PSC_FOR_SHIFT_WORDS PSC_WORD_LOOP
#else
#define PSC_FOR_SHIFT_WORDS PSC_FOR_WORDS
#endif
// Bit p of the result is bit p + n of b (cells n positions further on).
PSC_DEVICE PSC_INLINE Board shiftDown(const Board& b, int n) {
    Board r;
    if (kWords == 1) {
        r.w[0] = n < 64 ? b.w[0] >> n : 0;
        return r;
    }
    const int words = n >> 6;
    const int bits = n & 63;
    PSC_FOR_SHIFT_WORDS(i, kWords,
        const u64 lo = i + words < kWords ? b.word(i + words) : 0;
        const u64 hi = i + words + 1 < kWords ? b.word(i + words + 1) : 0;
        r.w[i] = (lo >> bits) | (bits ? hi << (64 - bits) : 0);
    );
    return r;
}
// Bit p of the result is bit p - n of b.
PSC_DEVICE PSC_INLINE Board shiftUp(const Board& b, int n) {
    Board r;
    if (kWords == 1) {
        r.w[0] = n < 64 ? b.w[0] << n : 0;
        return r;
    }
    const int words = n >> 6;
    const int bits = n & 63;
    PSC_FOR_SHIFT_WORDS(i, kWords,
        const u64 hi = i - words >= 0 ? b.word(i - words) : 0;
        const u64 lo = i - words - 1 >= 0 ? b.word(i - words - 1) : 0;
        r.w[i] = (hi << bits) | (bits ? lo >> (64 - bits) : 0);
    );
    return r;
}
// Cells d positions apart in a row of a rule, d = +-1 (vertical) or +-(H+1):
// bit p of the result is bit p + d of b.
PSC_DEVICE PSC_INLINE Board shiftBy(const Board& b, int d) { return d >= 0 ? shiftDown(b, d) : shiftUp(b, -d); }

// shiftBy for N steps to a neighbouring cell, d = +-N or +-N(H+1).  Where
// boards have several words and N columns of every level built (H+1 cells
// each) are shorter than a word, each word of the result takes bits from the
// same word of b and the one beside it, chosen by d's sign without a
// branch, not from a word picked at run time.  The registers layout's code
// shifts by run-time steps (the rules' directions, the movement over
// boards): NVVM's time on its stepping kernel fell by a tenth or more
// (docs/performance.md).
template <int N = 1>
PSC_DEVICE PSC_INLINE Board shiftBySteps(const Board& b, int d) {
    if constexpr (kWords == 1 || N * (kMaxBuiltHeight + 1) >= 64) {
        return shiftBy(b, d);
    } else {
        Board r;
        const bool up = d < 0;
        const int bits = d & 63;  // up by n: the word below's top n bits, at 64 - n
        PSC_FOR_SHIFT_WORDS(i, kWords,
            const u64 below = i > 0 ? b.w[i - 1] : 0;
            const u64 above = i + 1 < kWords ? b.w[i + 1] : 0;
            const u64 lo = up ? below : b.w[i];
            const u64 hi = up ? b.w[i] : above;
            r.w[i] = (lo >> bits) | (bits ? hi << (64 - bits) : 0);
        );
        return r;
    }
}

// The bits of `b` at `moved[k]` go one step along `steps[k]`; `leaving` is
// the union of `moved` (most objects of a moving layer are not among them).
PSC_DEVICE PSC_INLINE void moveObjectWhere(Board& b, const Board (&moved)[4], const Board& leaving, const int (&steps)[4]) {
    if (!(b & leaving).any()) return;
    Board arriving = Board::zero();
    PSC_UNROLL for (int k = 0; k < 4; ++k) arriving = arriving | shiftBySteps(b & moved[k], -steps[k]);
    b = andNot(b, leaving) | arriving;
}

// The RC4-based generator of the reference engine, seeded from a string.
struct Rng {
    u8 s[256];
    u8 i;
    u8 j;

    // Key bytes: each UTF-16 code unit of the seed, big-endian, as few bytes as possible.
    PSC_DEVICE PSC_COLD void seed(const u16* units, int length) {
        for (int k = 0; k < 256; ++k) s[k] = static_cast<u8>(k);
        i = 0;
        j = 0;
        if (length == 0) return;  // an empty seed leaves the identity permutation
        u8 key[512];
        int keyLength = 0;
        for (int k = 0; k < length && keyLength < 510; ++k) {
            const u16 c = units[k];
            if (c > 0xFF) key[keyLength++] = static_cast<u8>(c >> 8);
            key[keyLength++] = static_cast<u8>(c & 0xFF);
        }
        int jj = 0;
        for (int k = 0; k < 256; ++k) {
            jj = (jj + s[k] + key[k % keyLength]) & 255;
            const u8 t = s[k];
            s[k] = s[jj];
            s[jj] = t;
        }
    }
    PSC_DEVICE PSC_INLINE u8 nextByte() {
        i = static_cast<u8>(i + 1);
        j = static_cast<u8>(j + s[i]);
        const u8 t = s[i];
        s[i] = s[j];
        s[j] = t;
        return s[static_cast<u8>(s[i] + s[j])];
    }
    // Seven bytes accumulated in a double, divided by 2^56 (the reference's
    // divisor 2^56-1 rounds to 2^56 as a double).
    PSC_DEVICE double uniform() {
        double out = 0;
        for (int k = 0; k < 7; ++k) {
            out *= 256.0;
            out += static_cast<double>(nextByte());
        }
        return out / 72057594037927936.0;
    }
    PSC_DEVICE PSC_INLINE int below(int n) { return static_cast<int>(uniform() * static_cast<double>(n)); }
};

// Commands queued by rules during a turn.
enum Command : u32 {
    kCmdCancel = 1u << 0,
    kCmdAgain = 1u << 1,
    kCmdWin = 1u << 2,
    kCmdRestart = 1u << 3,
    kCmdCheckpoint = 1u << 4,
    kCmdMessage = 1u << 5,
    kCmdSfxFirst = 6,  // sfx0..sfx10 are bits 6..16
};

// Screens, as the reference harness reports them.
enum Screen : u8 { kScreenLevel = 0, kScreenMessage = 1, kScreenTitle = 2 };

// A saved level buffer (undo entries, the restart target): objects only.
struct Snapshot {
    Board obj[kObjects];
};

// Only the layers in kMovingLayerBits ever hold a movement (the player's, and
// those rules move); movement loops skip the others' always-empty boards.
PSC_DEVICE PSC_INLINE constexpr bool layerCanMove(int layer) {
    return layer >= 64 || ((kMovingLayerBits >> layer) & 1u);
}

// One environment: the level buffer and everything the reference engine
// keeps between inputs.
struct Env {
    Board obj[kObjects];
    Board mov[kLayers * 5];  // movement of layer L toward direction k: mov[5 * L + k]
    Board inside;            // positions inside the level (not guards)
    Board rowStart;          // positions with y == 0 (for row-major scans)
    short width;
    short height;
    short entry;             // the level entry shown (message entries counted)
    u8 titleScreen;
    u8 textMode;
    u8 againing;
    u8 startExisted;         // the entry the environment started at exists
    u8 stopOnWin;            // episodes end at a win (no level change)
    u8 unavailable;          // play reached a level this plugin was built without
    u8 startCutOff;          // the last reset ran an again chain at the level's start that was cut off
    u8 startWon;             // the last reset's start (its again chain) won the level before any input
    u8 restarting;           // a restart is in progress (nested restarts are ignored)
    u8 dormant;              // no dormant group can match until the level is replaced (codegen/DormantGroups.h)
    u16 wins;                // levels won since the counter was last reset
    u32 queue;               // commands queued this turn
    // Episode control (the batch's settings and this environment's episode).
    int levelEntry;          // the entry the environment (re)starts at
    int episodeSteps;
    int maxEpisodeSteps;     // 0: no limit
    u8 autoReset;            // psc_auto_reset
    u8 needsReset;           // next-step auto-reset: the episode ended on the last step
    u8 againMode;            // psc_again_mode: whether a step settles `again` chains or runs one turn
#if PSC_HAS_RULE_MESSAGES
    short queuedMessage;     // the text of the `message` command queued this turn (kRuleMessages)
    short shownMessage;      // the message the reference's player would have shown this step, or -1
#endif
    Snapshot restartTarget;
#if PSC_USES_RANDOM
    Rng rng;
    u16 seed[kSeedUnits];    // the level seed (UTF-16 code units), reused at every level load
    u8 seedLength;
#endif
#if defined(__CUDA_ARCH__) && !PSC_UNROLL_BOARD_WORDS
    // Copied as one loop over its words: member-wise, with Board's own copy
    // a loop (above), it was one loop a board, and NVVM took 5-6 s over each
    // kernel that copies an environment of a large level (a 56-word level of
    // 68 objects, the development machine).  Boards that unroll keep the
    // implicit copy, which the registers layout needs to keep the state in
    // registers.
    Env() = default;
    PSC_DEVICE PSC_INLINE Env(const Env& o) { *this = o; }
    PSC_DEVICE PSC_INLINE Env& operator=(const Env& o) {
        static_assert(sizeof(Env) % sizeof(u64) == 0, "an environment is whole 64-bit words");
        u64* to = reinterpret_cast<u64*>(this);
        const u64* from = reinterpret_cast<const u64*>(&o);
        PSC_UNROLL for (unsigned i = 0; i < sizeof(Env) / sizeof(u64); ++i) to[i] = from[i];
        return *this;
    }
#endif
};

// With PSC_STATE_IN_SHARED the stepping kernel keeps each thread's copy of
// its environment in shared memory, this many bytes apart: an odd number of
// 8-byte words, so that a warp's threads reading the same field hit
// different banks.
constexpr unsigned kSharedEnvStride = static_cast<unsigned>(((sizeof(Env) + 7) / 8 | 1) * 8);

// Environments this large are stepped on the GPU where they lie in the
// batch: the driver reserves a thread's stack for every thread the GPU can
// hold (about 270,000 on an H100) and allows 512 kB at most.
constexpr bool kEnvInBatch = !PSC_STATE_IN_REGISTERS && !PSC_STATE_IN_SHARED && sizeof(Env) > 128 * 1024;

// Whether every GPU kernel steps its environment on the thread's stack (a
// copy there, templates/cuda_kernels.h; not in the batch, not in shared
// memory), where the turn's scratch lies too (TurnScratchSlot).  A function
// compiled in one unit and called from another gets references of unknown
// address space, which NVVM reads and writes through generic addresses;
// PSC_ON_STACK tells it that the reference is on the stack, so that it uses
// local loads and stores.
constexpr bool kStateOnStack = !PSC_STATE_IN_SHARED && !kEnvInBatch;
#if defined(__CUDA_ARCH__)
#define PSC_ON_STACK(x)                                          \
    do {                                                         \
        if constexpr (kStateOnStack) __builtin_assume(__isLocal(&(x))); \
    } while (0)
#else
#define PSC_ON_STACK(x) ((void)(x))
#endif

// What a turn keeps while it runs (the reference's turn-local variables).
struct Turn {
#if PSC_HAS_RIGID
    Board rigidGroup[kLayers * 5];  // per layer, the claiming rigid group's index + 1, bit by bit
    Board rigidApplied[kLayers];    // per layer, claimed by a rigid rule
#endif
    u64 banned;  // banned rigid groups, by rigid index (bit 63: a ban that names no group)
    u8 dormantGroupMatched;  // a group that can go dormant matched this turn
};

// A rule group's working copy (the groups layout): the group runs on copies
// of the environment and the turn that ptxas keeps in registers, and writes
// back what changed when it returns.  Rules change only the boards, the
// command queue, the queued message and the turn's rigid claims (a group that
// draws from the random stream, which rules index at run time, works in
// place); a field written back only where it differs lets the compiler drop
// the loads and stores of everything the group never touches.
template <typename T>
PSC_DEVICE PSC_INLINE void keepIfChanged(T& to, const T& from) {
    if (!(to == from)) to = from;
}

PSC_DEVICE PSC_INLINE void keepRuleChanges(Env& to, const Env& from) {
    PSC_UNROLL_STATE for (int o = 0; o < kObjects; ++o) keepIfChanged(to.obj[o], from.obj[o]);
    PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) {
        if (!layerCanMove(L)) continue;
        PSC_UNROLL for (int k = 0; k < 5; ++k) keepIfChanged(to.mov[5 * L + k], from.mov[5 * L + k]);
    }
    keepIfChanged(to.queue, from.queue);
#if PSC_HAS_RULE_MESSAGES
    keepIfChanged(to.queuedMessage, from.queuedMessage);
#endif
}

PSC_DEVICE PSC_INLINE void keepRuleChanges(Turn& to, const Turn& from) {
#if PSC_HAS_RIGID
    PSC_UNROLL_STATE for (int m = 0; m < kLayers * 5; ++m) keepIfChanged(to.rigidGroup[m], from.rigidGroup[m]);
    PSC_UNROLL_STATE for (int l = 0; l < kLayers; ++l) keepIfChanged(to.rigidApplied[l], from.rigidApplied[l]);
#endif
    keepIfChanged(to.banned, from.banned);
}

struct GroupWorkingCopy {
    Env& env;
    Turn& turn;
    Env e;
    Turn t;
    PSC_DEVICE PSC_INLINE GroupWorkingCopy(Env& env_, Turn& turn_) : env(env_), turn(turn_), e(env_), t(turn_) {}
    PSC_DEVICE PSC_INLINE ~GroupWorkingCopy() {
        keepRuleChanges(env, e);
        keepRuleChanges(turn, t);
    }
};

// Opens a group function whose parameters are (Env& env, Turn& turn): its
// body works on `e` and `t`, copies or the originals.
#if PSC_GROUP_COPIES_STATE
#define PSC_GROUP_WORKING_COPY(env, turn)     \
    PSC_ON_STACK(env);                        \
    PSC_ON_STACK(turn);                       \
    GroupWorkingCopy working_(env, turn);     \
    Env& e = working_.e;                      \
    Turn& t = working_.t
#else
#define PSC_GROUP_WORKING_COPY(env, turn) PSC_GROUP_IN_PLACE(env, turn)
#endif
// A group that works on the state where it lies.
#define PSC_GROUP_IN_PLACE(env, turn) \
    PSC_ON_STACK(env);                \
    PSC_ON_STACK(turn);               \
    Env& e = env;                     \
    Turn& t = turn

// A turn's largest locals: its Turn, the level as the turn found it, and
// with rigid bodies the movements its retries start from.
struct TurnScratch {
    Turn turn;
    Snapshot bak;
    u8 dormantBefore;  // Env::dormant as the turn found it, restored with bak
#if PSC_HAS_RIGID
    Board startMov[kLayers * 5];
#endif
};

// Turns nest: an input's turn wins, the next level's start turn restarts,
// the restarted start turn runs (a restart while restarting is ignored and
// a start turn never wins).  runtime/CudaCompiler.h bounds the stack by it.
constexpr int kMaxTurnNesting = 3;

// What one environment keeps outside Env: its undo history, whose depth is
// chosen per batch (zero disables undo), and, for an environment in the
// batch on the GPU (kEnvInBatch), the TurnScratch of each nested turn, which
// on the stack would be a level's worth of objects several times over.
struct UndoStack {
    Snapshot* entries;
    int capacity;
    int count;
    int head;  // index of the oldest entry
    TurnScratch* scratch;  // kMaxTurnNesting of them, or null (a turn's scratch on its stack)
    int scratchDepth;      // turns running
    // psc_expand's deadline: when an again chain stops, on deadlineClock
    // (templates/engine.h); 0: never.
    unsigned long long deadline;
};

// Level size, constant when every level built has the same.
PSC_DEVICE PSC_INLINE int widthOf(const Env& e) { return kFixedWidth ? kFixedWidth : e.width; }
PSC_DEVICE PSC_INLINE int heightOf(const Env& e) { return kFixedHeight ? kFixedHeight : e.height; }
PSC_DEVICE PSC_INLINE int columnOf(const Env& e) { return heightOf(e) + 1; }  // positions per column
PSC_DEVICE PSC_INLINE int positionOf(const Env& e, int x, int y) { return x * columnOf(e) + y; }

// Sets movement bits `set` and clears bits `clear` (set wins) of layer
// `layer`'s field at p; returns whether anything changed.
PSC_DEVICE PSC_INLINE bool putMovement(Env& e, int p, int layer, u32 clear, u32 set) {
    bool ch = false;
    PSC_UNROLL for (int k = 0; k < 5; ++k) {
        if ((set >> k) & 1u) ch |= e.mov[5 * layer + k].assign(p, true);
        else if ((clear >> k) & 1u) ch |= e.mov[5 * layer + k].assign(p, false);
    }
    return ch;
}

// putMovement at every position of `where` at once.
PSC_DEVICE PSC_INLINE bool putMovementWhere(Env& e, const Board& where, int layer, u32 clear, u32 set) {
    bool ch = false;
    PSC_UNROLL for (int k = 0; k < 5; ++k) {
        if ((set >> k) & 1u) ch |= e.mov[5 * layer + k].assignWhere(where, true);
        else if ((clear >> k) & 1u) ch |= e.mov[5 * layer + k].assignWhere(where, false);
    }
    return ch;
}

// putMovement with bits chosen at run time (a rule's direction copies as
// one, codegen/DirectionVariants.h): no branch on them, so that threads that
// chose different bits stay together.  `touched`: the bits any choice sets
// or clears (a constant), the only boards written.
PSC_DEVICE PSC_INLINE bool putMovementChosen(Env& e, int p, int layer, u32 clear, u32 set, u32 touched) {
    bool ch = false;
    PSC_UNROLL for (int k = 0; k < 5; ++k) {
        if (!((touched >> k) & 1u)) continue;
        Board& b = e.mov[5 * layer + k];
        ch |= b.assign(p, ((set >> k) & 1u) || (!((clear >> k) & 1u) && b.test(p)));
    }
    return ch;
}

// putMovementChosen at every position of `where` at once.
PSC_DEVICE PSC_INLINE bool putMovementChosenWhere(Env& e, const Board& where, int layer, u32 clear, u32 set, u32 touched) {
    bool ch = false;
    PSC_UNROLL for (int k = 0; k < 5; ++k) {
        if (!((touched >> k) & 1u)) continue;
        Board& b = e.mov[5 * layer + k];
        if ((set >> k) & 1u) ch |= b.assignWhere(where, true);
        else if ((clear >> k) & 1u) ch |= b.assignWhere(where, false);
    }
    return ch;
}

// Loops over the set positions s of board m in the order a vertical rule
// scans (column-major: increasing position), and a horizontal rule scans
// (row-major: row by row, x increasing).  `continue` moves to the next position.
#define PSC_FOR_VERTICAL(m, s)                                                        \
    PSC_CELL_LOOP for (Board s##_rest = (m); s##_rest.any(); s##_rest.dropLowest())   \
        for (int s = s##_rest.lowest(), s##_once = 1; s##_once; s##_once = 0)
#define PSC_FOR_HORIZONTAL(e, m, s)                                                   \
    PSC_CELL_LOOP for (Board s##_rows = (m), s##_mask = (e).rowStart;                 \
                       s##_rows.any() && s##_mask.any();                              \
                       s##_rows = andNot(s##_rows, s##_mask), s##_mask = shiftUp(s##_mask, 1)) \
        PSC_FOR_VERTICAL(s##_rows & s##_mask, s)

}  // namespace psc_game
