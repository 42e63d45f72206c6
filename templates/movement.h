// ---- psc template: movement resolution ------------------------------------
// Moves objects as their layers' movements say, cell by cell in the
// reference's index order and layer by layer, repeating until a pass moves
// nothing (or, on the GPU where that gives the same, over whole boards at
// once); then checks rigid claims against the movements left over and
// clears all movements.  Returns true when a rigid group was newly banned
// (the turn then starts over).  (Reference: engine.js resolveMovements,
// repositionEntitiesAtCell, repositionEntitiesOnLayer.)

namespace psc_game {

// layerOccupied, soundReads, moveLayerObjects, layerCells and moveLayerWhere
// are generated per game (constant object ids per layer), as is
// kSoundReadsCanReload.  soundReads counts the movement-sound declarations of
// a layer that name an object present in the cell: the reference re-reads
// the cell's movements once per such declaration into a ring of three
// buffers, so every third read reloads the movement being resolved (see
// docs/architecture.md, "engine quirks").

// Tries to move layer `layer` of the cell at p by `field` (one direction bit);
// adds the sound reads it makes to *reads.
PSC_DEVICE PSC_INLINE bool moveLayer(Env& e, int p, int layer, int field, int* reads) {
    int dx = 0;
    int dy = 0;
    switch (field) {
        case 1: dy = -1; break;
        case 2: dy = 1; break;
        case 4: dx = -1; break;
        case 8: dx = 1; break;
        case 3: case 15: case 16: break;
        default: return false;  // the reference throws on other combinations
    }
    const int column = columnOf(e);
    const int x = p / column;
    const int y = p % column;
    if ((x == 0 && dx < 0) || (x == widthOf(e) - 1 && dx > 0) || (y == 0 && dy < 0) || (y == heightOf(e) - 1 && dy > 0)) {
        return false;
    }
    const int target = p + dy + dx * column;
    if (field != 16 && layerOccupied(e, layer, target)) return false;
    *reads += soundReads(e, layer, p);
    moveLayerObjects(e, layer, p, target);
    return true;
}

PSC_DEVICE PSC_INLINE u8 movementField(const Env& e, int layer, int p) {
    u8 f = 0;
    PSC_UNROLL for (int k = 0; k < 5; ++k) f |= static_cast<u8>(e.mov[5 * layer + k].test(p)) << k;
    return f;
}

PSC_DEVICE PSC_INLINE bool repositionCell(Env& e, int p) {
    u8 stored[kLayers];
    u8 fields[kLayers];
    PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) stored[L] = fields[L] = layerCanMove(L) ? movementField(e, L, p) : 0;
    bool moved = false;
    int reads = 0;
    PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) {
        const int f = fields[L];
        if (f == 0) continue;
        const int before = reads;
        if (moveLayer(e, p, L, f, &reads)) {
            if (reads / 3 > before / 3) {
                PSC_UNROLL_STATE for (int k = 0; k < kLayers; ++k) fields[k] = stored[k];
            }
            fields[L] = static_cast<u8>(fields[L] & ~f);
            moved = true;
        }
    }
    // Moving only clears bits of a layer's field: write back those.
    PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) {
        const int cleared = stored[L] & ~fields[L];
        if (cleared == 0) continue;
        PSC_UNROLL for (int k = 0; k < 5; ++k) {
            if ((cleared >> k) & 1) e.mov[5 * L + k].clear(p);
        }
    }
    return moved;
}

PSC_DEVICE PSC_INLINE Board movingCells(const Env& e) {
    Board any = Board::zero();
    PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) {
        if (!layerCanMove(L)) continue;
        PSC_UNROLL for (int k = 0; k < 5; ++k) any = any | e.mov[5 * L + k];
    }
    return any;
}

// Movement resolved over whole boards, where that gives what the passes cell
// by cell give: each moving cell of a layer moves one way (or acts), no two
// target the same cell of their layer, and no cell moves two layers when
// sound reads could reload a cell's movements.  Each layer's moving cells
// then form chains, and a cell is freed only by its occupant moving on, so
// the passes move a chain whole when its head's target is empty and leave it
// whole otherwise; a cycle stays.  Returns false, having changed nothing,
// where it does not apply.
PSC_DEVICE PSC_INLINE bool resolveMovementsAtOnce(Env& e) {
    // Its dozen boards on the thread's stack: not for levels of thousands of
    // cells, whose boards already fill it (tests/correctness/cuda_large_levels.py).
    if constexpr (kWords > 32) {
        return false;
    } else {
        const int column = columnOf(e);
        const int steps[4] = {-1, 1, -column, column};  // up, down, left, right
        Board movingLayers = Board::zero();
        Board twoLayers = Board::zero();
        PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) {
            if (!layerCanMove(L)) continue;
            Board seen = Board::zero();
            Board twice = Board::zero();
            Board targets = Board::zero();
            PSC_UNROLL for (int k = 0; k < 5; ++k) {
                const Board m = e.mov[5 * L + k];
                twice = twice | (seen & m);
                seen = seen | m;
                if (k == 4) break;
                const Board target = shiftBySteps(m, -steps[k]) & e.inside;
                twice = twice | (targets & target);
                targets = targets | target;
            }
            if (twice.any()) return false;
            twoLayers = twoLayers | (movingLayers & seen);
            movingLayers = movingLayers | seen;
        }
        if (kSoundReadsCanReload && twoLayers.any()) return false;
        if (!movingLayers.any()) return true;  // rules stopped every movement (slidings' turns)
        PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) {
            if (!layerCanMove(L)) continue;
            Board moved[4] = {Board::zero(), Board::zero(), Board::zero(), Board::zero()};
            Board open = andNot(e.inside, layerCells(e, L));
            for (bool grew = true; grew;) {
                grew = false;
                PSC_UNROLL for (int k = 0; k < 4; ++k) {
                    const Board m = e.mov[5 * L + k] & shiftBySteps(open, steps[k]);
                    if (m == moved[k]) continue;
                    moved[k] = m;
                    open = open | m;
                    grew = true;
                }
            }
            moveLayerWhere(e, L, moved, moved[0] | moved[1] | moved[2] | moved[3], steps);
            PSC_UNROLL for (int k = 0; k < 4; ++k) e.mov[5 * L + k] = andNot(e.mov[5 * L + k], moved[k]);
            e.mov[5 * L + 4] = Board::zero();
        }
        return true;
    }
}

PSC_DEVICE PSC_INLINE bool resolveMovements(Env& e, Turn& t) {
    // A turn whose rules left no movement has nothing to move, ban or
    // clear: limerick's rules take every movement off its player, and an
    // `again` turn or dry run takes no input.  Over the GPU's local memory the
    // tests and the clearing below read a layer's five boards several times
    // and wrote them once (limerick 1.16x, kettle 1.04x, slidings 1.05x on
    // one H200).  With the state in registers they cost little and the test
    // costs registers (constellationz, whose every turn moves, 0.88x), so
    // there only games with `again` test; on one CPU thread the passes below
    // cost little too and the test did not pay (constellationz 0.93x).  The
    // CPU build of the GPU's movement that the tests use
    // (PSC_MOVE_OVER_BOARDS) tests as the GPU does.
#if defined(__CUDA_ARCH__) && PSC_STATE_IN_REGISTERS
    constexpr bool kTestForStillness = kHasAgainCommand;
#elif defined(__CUDA_ARCH__) || PSC_MOVE_OVER_BOARDS
    constexpr bool kTestForStillness = true;
#else
    constexpr bool kTestForStillness = false;
#endif
    if (kTestForStillness && !movingCells(e).any()) return false;
    // On the GPU the boards' straight-line code keeps a warp's environments
    // together where the passes cell by cell part them (kettle 3.9x, blocks
    // 6.1x, zenpuzzle 1.6x on one H200; slidings 0.98x), even for a lone
    // moving cell.  One CPU thread has no warp to keep: there the passes
    // cost less (kettle's CPU steps fell by 43 % over boards).  Tests build
    // the boards' way on the CPU with -DPSC_MOVE_OVER_BOARDS=1.
#if defined(__CUDA_ARCH__) || PSC_MOVE_OVER_BOARDS
    bool moved = !resolveMovementsAtOnce(e);
#else
    bool moved = true;
#endif
    while (moved) {
        moved = false;
        const Board cells = movingCells(e);
        for (int w = 0; w < kWords; ++w) {
            u64 bits = cells.word(w);
            while (bits) {
                const int p = w * 64 + lowestBit(bits);
                bits &= bits - 1;
                if (repositionCell(e, p)) moved = true;
            }
        }
    }
    bool banned = false;
#if PSC_HAS_RIGID
    const Board left = movingCells(e);
    for (int w = 0; w < kWords; ++w) {
        u64 bits = left.word(w);
        while (bits) {
            const int p = w * 64 + lowestBit(bits);
            bits &= bits - 1;
            PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) {
                if (!layerCanMove(L) || movementField(e, L, p) == 0 || !t.rigidApplied[L].test(p)) continue;
                int claim = 0;
                PSC_UNROLL for (int k = 0; k < 5; ++k) claim |= static_cast<int>(t.rigidGroup[5 * L + k].test(p)) << k;
                const int rigidIndex = claim - 1;
                const int bit = (rigidIndex >= 0 && rigidIndex < kRigidGroupCount) ? rigidIndex : 63;
                if (!((t.banned >> bit) & 1)) {
                    t.banned |= 1ull << bit;
                    banned = true;
                }
                break;
            }
        }
    }
#else
    (void)t;
#endif
    PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) {
        if (!layerCanMove(L)) continue;
        PSC_UNROLL for (int k = 0; k < 5; ++k) e.mov[5 * L + k] = Board::zero();
    }
    return banned;
}

}  // namespace psc_game
