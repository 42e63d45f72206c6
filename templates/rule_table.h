// ---- psc template: rules read from a table -------------------------------
// The compact rule form (codegen/RuleTable.h), chosen for games whose rules
// as straight-line code would take the compilers minutes: each rule is a
// record of kRuleData, and these functions do, record by record, exactly what
// the straight-line form's functions do (codegen/RuleCode.cpp): the same
// boards, the same scan order, the same re-checks, changes and random draws,
// so both forms step bit for bit alike.  Slower per rule, but its code does
// not grow with the game.  Included after the game's tables (kRuleData,
// kLayerObjects, kRuleIndex, kRuleNeeds, kEarlyGroups, kLateGroups and their
// needs); the turn's applyEarlyRules and applyLateRules call tableApplyGroups.
//
// Records (offsets are indices into kRuleData):
//   rule: direction (0 down, 1 up, 2 right, 3 left), flags (1 replacements,
//         2 ellipses), commands, message (-1: none), rigid claim (0: none),
//         row count, then each row's offset (the presence bits of the
//         boards its every match needs are kRuleNeeds's, by kRuleIndex)
//   row:  cell count, first and second ellipsis (-1: none), each cell's
//         offset (-1: an ellipsis)
//   cell: replacement offset (-1: none), term count, terms (each a count of
//         boards that are ORed, then the boards), excluded count, boards;
//         a board b >= 0 is e.obj[b], b < 0 is e.mov[-b - 1]
//   replacement: candidate count (`random` objects; 0: none), the count and
//         the layers of `randomdir`, then one block per candidate (or one):
//         object updates (count; then kind 0 put layer L keep k, or kind 1
//         assign object id value v, three numbers each) and movement updates
//         (count; then layer, clear, set, random-direction flag); then the
//         rigid claim's layers (count, layers)

namespace psc_game {

constexpr int kTableRuleFlagReplacements = 1;
constexpr int kTableRuleFlagEllipses = 2;
constexpr int kTableRuleRowCount = 5;  // a rule record's fields: its row count, then its rows' offsets
constexpr int kTableRuleRows = 6;

// Where a row's cells before its first ellipsis end.
PSC_DEVICE PSC_INLINE int tableRowPrefixEnd(const int* row) { return row[1] < 0 ? row[0] : row[1]; }

PSC_DEVICE PSC_INLINE const Board& tableBoard(const Env& e, int b) { return b >= 0 ? e.obj[b] : e.mov[-b - 1]; }

// The positions where a cell's pattern holds (RuleCode's patternBoard).
PSC_DEVICE PSC_COLD Board tableCellBoard(const Env& e, int cell) {
    const int* c = kRuleData + cell + 1;
    const int terms = *c++;
    Board b = e.inside;
    for (int k = 0; k < terms; ++k) {
        const int n = *c++;
        Board any = Board::zero();
        for (int i = 0; i < n; ++i) any = any | tableBoard(e, *c++);
        b = k == 0 ? any : b & any;
        if (!b.any()) return b;
    }
    const int excluded = *c++;
    if (excluded > 0) {
        Board x = Board::zero();
        for (int i = 0; i < excluded; ++i) x = x | tableBoard(e, *c++);
        b = andNot(b, x);
    }
    return b;
}

// Whether a cell's pattern holds at p on the current board (RuleCode's patternAt).
PSC_DEVICE PSC_COLD bool tableCellHolds(const Env& e, int cell, int p) {
    const int* c = kRuleData + cell + 1;
    const int terms = *c++;
    if (terms == 0 && !e.inside.test(p)) return false;
    for (int k = 0; k < terms; ++k) {
        const int n = *c++;
        bool any = false;
        for (int i = 0; i < n; ++i) any = tableBoard(e, *c++).test(p) || any;
        if (!any) return false;
    }
    const int excluded = *c++;
    for (int i = 0; i < excluded; ++i) {
        if (tableBoard(e, *c++).test(p)) return false;
    }
    return true;
}

PSC_DEVICE PSC_INLINE bool tablePutLayer(Env& e, int layer, int p, int keep) {
    bool ch = false;
    for (int i = kLayerObjectStart[layer]; i < kLayerObjectStart[layer + 1]; ++i) {
        ch |= e.obj[kLayerObjects[i]].assign(p, keep == kLayerObjects[i]);
    }
    return ch;
}

// Applies a replacement at p (RuleCode's emitReplacement); returns whether it changed anything.
PSC_DEVICE PSC_COLD bool tableReplace(Env& e, Turn& t, int rule, int replacement, int p) {
    (void)t;
    const int* r = kRuleData + replacement;
    const int candidates = *r++;
    int pick = 0;
    int draws[kLayers];
    const int randomDirections = *r++;
#if PSC_USES_RANDOM
    if (candidates > 0) pick = e.rng.below(candidates);
    for (int i = 0; i < randomDirections; ++i) draws[r[i]] = e.rng.below(4);
#else
    (void)draws;
#endif
    r += randomDirections;
    for (int block = 0; block < pick; ++block) {
        r += 1 + 3 * r[0];
        r += 1 + 4 * r[0];
    }
    bool ch = false;
    const int objectUpdates = *r++;
    for (int i = 0; i < objectUpdates; ++i, r += 3) {
        ch |= r[0] == 0 ? tablePutLayer(e, r[1], p, r[2]) : e.obj[r[1]].assign(p, r[2] != 0);
    }
    const int movementUpdates = *r++;
    for (int i = 0; i < movementUpdates; ++i, r += 4) {
        const u32 set = static_cast<u32>(r[2]) | (r[3] ? 1u << draws[r[0]] : 0u);
        ch |= putMovement(e, p, r[0], static_cast<u32>(r[1]), set);
    }
    for (int block = pick + 1; block < candidates; ++block) {
        r += 1 + 3 * r[0];
        r += 1 + 4 * r[0];
    }
#if PSC_HAS_RIGID
    const int claim = kRuleData[rule + 4];
    const int layers = *r++;
    if (claim != 0) {
        bool groupMissing = false;
        bool appliedMissing = false;
        for (int i = 0; i < layers; ++i) {
            for (int k = 0; k < 5; ++k) {
                if ((claim >> k) & 1) groupMissing = groupMissing || !t.rigidGroup[5 * r[i] + k].test(p);
            }
            appliedMissing = appliedMissing || !t.rigidApplied[r[i]].test(p);
        }
        if (groupMissing && appliedMissing) {
            for (int i = 0; i < layers; ++i) {
                for (int k = 0; k < 5; ++k) {
                    if ((claim >> k) & 1) t.rigidGroup[5 * r[i] + k].set(p);
                }
                t.rigidApplied[r[i]].set(p);
            }
            ch = true;
        }
    }
#else
    (void)rule;
#endif
    return ch;
}

PSC_DEVICE PSC_INLINE void tableQueueCommands(Env& e, int rule) {
    const u32 commands = static_cast<u32>(kRuleData[rule + 2]);
    if (commands == 0) return;
#if PSC_HAS_RULE_MESSAGES
    if (kRuleData[rule + 3] >= 0) {
        queueMessageRule(e, commands, kRuleData[rule + 3]);
        return;
    }
#endif
    e.queue = queueCommands(e.queue, commands);
}

// The lowest position of b at or after p, or -1.
PSC_DEVICE PSC_INLINE int tableNextSet(const Board& b, int p) {
    int i = p >> 6;
    if (i >= kWords) return -1;
    u64 word = b.word(i) & (~0ull << (p & 63));
    for (;;) {
        if (word) return i * 64 + lowestBit(word);
        if (++i >= kWords) return -1;
        word = b.word(i);
    }
}

// Where one row of a rule stands in the visit of its matches: its start s
// (from its board, in the rule's scan order) and its ellipses' gaps.  The
// visit reads the row's board (TableMatches::rowBoard) where it stands, a
// vertical one from the last start on and a horizontal one cell by cell
// along the level's rows, and keeps no board of its own: the rule-table
// stepping kernel's stack then stays within the driver's limit on the
// largest levels (boards of 724 words), and a horizontal row's cells cost
// less than the three whole-board operations a row took once the level is
// 16 or more rows tall.
struct TableRowVisit {
    int left;  // horizontal: starts not yet visited
    int x;     // horizontal: the column last visited, in level row y
    int y;
    int s;
    int gapLimit;
    int gap0;
    int gap1;
};

// A rule's matches, visited as the straight-line form's nested loops visit
// them: the last row outermost, each row's starts in scan order, then its
// gaps; cells after an ellipsis are tested on the boards of the rule's start.
struct TableMatches {
    int rule;
    int rows;
    int d;
    bool horizontal;
    Board rowBoard[kTableMaxRows];
    Board saved[kTableMaxSavedCells];  // cells after a first ellipsis, in row and cell order
    int savedAt[kTableMaxRows];        // each row's first saved cell
    TableRowVisit visit[kTableMaxRows];

    PSC_DEVICE PSC_INLINE int row(int r) const { return kRuleData[rule + kTableRuleRows + r]; }

    // Position of cell i of row r at its current start and gaps.
    PSC_DEVICE PSC_INLINE int position(int r, int i) const {
        const int* w = kRuleData + row(r);
        const TableRowVisit& v = visit[r];
        if (w[1] < 0 || i < w[1]) return v.s + d * i;
        if (w[2] < 0 || i < w[2]) return v.s + d * (v.gap0 + i - 1);
        return v.s + d * (v.gap0 + v.gap1 + i - 2);
    }

    // The boards of every row, from the board as it is now; false when a row
    // cannot match.  Most rules match nowhere, so a row stops at its first
    // cell whose board leaves no start, before any saved cell is computed.
    PSC_DEVICE PSC_COLD bool prepare(const Env& e, int ruleOffset) {
        rule = ruleOffset;
        rows = kRuleData[rule + kTableRuleRowCount];
        const int direction = kRuleData[rule];
        d = direction == 0 ? 1 : direction == 1 ? -1 : direction == 2 ? columnOf(e) : -columnOf(e);
        horizontal = direction >= 2;
        for (int r = 0; r < rows; ++r) {
            const int* w = kRuleData + row(r);
            const int prefixEnd = tableRowPrefixEnd(w);
            Board b = tableCellBoard(e, w[3]);
            for (int i = 1; i < prefixEnd && b.any(); ++i) b = b & shiftBy(tableCellBoard(e, w[3 + i]), i * d);
            if (!b.any()) return false;
            rowBoard[r] = b;
        }
        int savedCount = 0;
        for (int r = 0; r < rows; ++r) {
            const int* w = kRuleData + row(r);
            savedAt[r] = savedCount;
            for (int i = tableRowPrefixEnd(w); i < w[0]; ++i) {
                if (w[3 + i] >= 0) saved[savedCount++] = tableCellBoard(e, w[3 + i]);
            }
        }
        return true;
    }

    PSC_DEVICE PSC_INLINE bool nextStart(const Env& e, int r) {
        TableRowVisit& v = visit[r];
        if (!horizontal) {
            v.s = tableNextSet(rowBoard[r], v.s + 1);
            return v.s >= 0;
        }
        if (v.left == 0) return false;
        for (; v.y < heightOf(e); ++v.y, v.x = -1) {
            for (int x = v.x + 1; x < widthOf(e); ++x) {
                const int p = x * columnOf(e) + v.y;
                if (rowBoard[r].test(p)) {
                    v.x = x;
                    v.s = p;
                    --v.left;
                    return true;
                }
            }
        }
        return false;
    }

    // Whether the saved cells from `first` to `last` (exclusive) of row r hold at their positions.
    PSC_DEVICE PSC_INLINE bool savedCellsHold(int r, int first, int last) const {
        const int* w = kRuleData + row(r);
        int k = savedAt[r];
        for (int i = w[1]; i < first; ++i) k += w[3 + i] >= 0 ? 1 : 0;
        for (int i = first; i < last; ++i) {
            if (w[3 + i] < 0) continue;
            if (!saved[k++].test(position(r, i))) return false;
        }
        return true;
    }

    // Moves row r to its next match (from its first when `fresh`); false when there is none.
    PSC_DEVICE PSC_COLD bool advance(const Env& e, int r, bool fresh) {
        const int* w = kRuleData + row(r);
        const int cells = w[0];
        const int ellipses = w[1] < 0 ? 0 : w[2] < 0 ? 1 : 2;
        TableRowVisit& v = visit[r];
        int stage = ellipses;
        if (fresh) {
            v.s = -1;
            if (horizontal) {
                v.left = rowBoard[r].count();
                v.x = -1;
                v.y = 0;
            }
            stage = 0;
        }
        for (;;) {
            if (stage == 0) {
                if (!nextStart(e, r)) return false;
                if (ellipses == 0) return true;
                const int length = cells - ellipses;
                const int x = v.s / columnOf(e);
                const int y = v.s % columnOf(e);
                const int direction = kRuleData[rule];
                v.gapLimit = direction == 0   ? heightOf(e) - (y + length) + 1
                             : direction == 1 ? y - length + 2
                             : direction == 2 ? widthOf(e) - (x + length) + 1
                                              : x - length + 2;
                v.gap0 = -1;
                stage = 1;
            }
            if (stage == 1) {
                ++v.gap0;
                if (v.gap0 >= v.gapLimit) {
                    stage = 0;
                    continue;
                }
                if (!savedCellsHold(r, w[1] + 1, ellipses == 2 ? w[2] : cells)) continue;
                if (ellipses == 1) return true;
                v.gap1 = -1;
                stage = 2;
            }
            ++v.gap1;
            if (!(v.gap0 + v.gap1 < v.gapLimit && v.gap1 < v.gapLimit)) {
                stage = 1;
                continue;
            }
            if (savedCellsHold(r, w[2] + 1, cells)) return true;
        }
    }

    // The next match of all rows (the first when `fresh`), as the nested loops go.
    PSC_DEVICE PSC_COLD bool next(const Env& e, bool fresh) {
        int r = fresh ? rows - 1 : 0;
        bool first = fresh;
        for (;;) {
            if (!advance(e, r, first)) {
                if (++r == rows) return false;
                first = false;
                continue;
            }
            if (r == 0) return true;
            --r;
            first = true;
        }
    }

    // Whether every cell of every row still holds on the current board.
    PSC_DEVICE PSC_COLD bool holds(const Env& e) const {
        for (int r = 0; r < rows; ++r) {
            const int* w = kRuleData + row(r);
            for (int i = 0; i < w[0]; ++i) {
                if (w[3 + i] >= 0 && !tableCellHolds(e, w[3 + i], position(r, i))) return false;
            }
        }
        return true;
    }

    PSC_DEVICE PSC_COLD bool apply(Env& e, Turn& t) const {
        bool changed = false;
        for (int r = 0; r < rows; ++r) {
            const int* w = kRuleData + row(r);
            for (int i = 0; i < w[0]; ++i) {
                const int cell = w[3 + i];
                if (cell >= 0 && kRuleData[cell] >= 0) changed |= tableReplace(e, t, rule, kRuleData[cell], position(r, i));
            }
        }
        return changed;
    }
};

// Which boards hold anything (bit b: e.obj[b]; bit kObjects + m: e.mov[m]).
// A rule needing an empty board matches nowhere and is skipped, and a group
// whose every rule needs it too; the bits are taken again whenever a rule
// changes the board.
constexpr int kTablePresenceBits = kObjects + 5 * kLayers;
static_assert((kTablePresenceBits + 63) / 64 == kTablePresenceWords, "the rule table's needs are presence words");
struct TablePresence {
    u64 w[kTablePresenceWords];

    PSC_DEVICE PSC_COLD void take(const Env& e) {
        for (int i = 0; i < kTablePresenceWords; ++i) w[i] = 0;
        for (int b = 0; b < kObjects; ++b) {
            if (e.obj[b].any()) w[b >> 6] |= u64{1} << (b & 63);
        }
        for (int m = 0; m < 5 * kLayers; ++m) {
            const int b = kObjects + m;
            if (e.mov[m].any()) w[b >> 6] |= u64{1} << (b & 63);
        }
    }

    // Whether every board of `needs` (kTablePresenceWords words) holds something.
    PSC_DEVICE PSC_INLINE bool holdsAll(const u64* needs) const {
        u64 missing = 0;
        for (int i = 0; i < kTablePresenceWords; ++i) missing |= needs[i] & ~w[i];
        return missing == 0;
    }
};

// One rule of an ordinary group (RuleCode's tryApply).
PSC_DEVICE PSC_COLD bool tableApplyRule(Env& e, Turn& t, int rule) {
    TableMatches m;
    if (!m.prepare(e, rule)) return false;
    const int flags = kRuleData[rule + 1];
    if (!(flags & kTableRuleFlagReplacements)) {
        if ((flags & kTableRuleFlagEllipses) && !m.next(e, true)) return false;
        tableQueueCommands(e, rule);
        return false;
    }
    bool changed = false;
    bool first = true;
    for (bool more = m.next(e, true); more; more = m.next(e, false)) {
        if (!first && !m.holds(e)) continue;
        first = false;
        changed |= m.apply(e, t);
    }
    if (!first) tableQueueCommands(e, rule);
    return changed;
}

// The number of matches of rule kRuleIndex[i] (a random group's candidates).
PSC_DEVICE PSC_COLD long long tableCountMatches(const Env& e, const TablePresence& present, int i) {
    const int rule = kRuleIndex[i];
    TableMatches m;
    if (!present.holdsAll(kRuleNeeds + i * kTablePresenceWords) || !m.prepare(e, rule)) return 0;
    long long n = 0;
    if (!(kRuleData[rule + 1] & kTableRuleFlagEllipses)) {
        n = 1;
        for (int r = 0; r < m.rows; ++r) n *= static_cast<long long>(m.rowBoard[r].count());
        return n;
    }
    for (bool more = m.next(e, true); more; more = m.next(e, false)) ++n;
    return n;
}

// Applies a rule's n-th match (of a random group).
PSC_DEVICE PSC_COLD bool tableApplyNth(Env& e, Turn& t, int rule, long long n) {
    TableMatches m;
    if (!m.prepare(e, rule)) return false;
    bool changed = false;
    long long index = 0;
    for (bool more = m.next(e, true); more; more = m.next(e, false)) {
        if (index++ == n) {
            changed = m.apply(e, t);
            break;
        }
    }
    tableQueueCommands(e, rule);
    return changed;
}

// A group of rules kRuleIndex[first .. first + count): passes over its rules
// until one changes nothing, at most 200; a random group applies one match
// drawn from all its rules' matches.
PSC_DEVICE PSC_COLD bool tableApplyGroup(Env& e, Turn& t, TablePresence& present, int first, int count, bool random) {
    if (!random) {
        bool changed = false;
        for (int pass = 0; pass < 200; ++pass) {
            bool any = false;
            for (int i = first; i < first + count; ++i) {
                if (!present.holdsAll(kRuleNeeds + i * kTablePresenceWords) || !tableApplyRule(e, t, kRuleIndex[i])) continue;
                any = true;
                present.take(e);
            }
            if (!any) break;
            changed = true;
        }
        return changed;
    }
#if PSC_USES_RANDOM
    long long total = 0;
    for (int i = first; i < first + count; ++i) total += tableCountMatches(e, present, i);
    if (total == 0) return false;
    long long pick = static_cast<long long>(e.rng.uniform() * static_cast<double>(total));
    for (int i = first; i < first + count; ++i) {
        const long long matches = tableCountMatches(e, present, i);
        if (pick < matches) {
            const bool changed = tableApplyNth(e, t, kRuleIndex[i], pick);
            if (changed) present.take(e);
            return changed;
        }
        pick -= matches;
    }
#endif
    return false;
}

// The groups of kEarlyGroups or kLateGroups in order (RuleCode's
// applyEarlyRules and applyLateRules): five numbers a group, its first rule
// in kRuleIndex, its rule count, whether it is random, its rigid group (-1:
// none; a banned one is skipped) and the group its loop goes back to from it
// (-1: none), taken when a group since the last jump changed something.
// A group is skipped while a board that all its rules need is empty
// (groupNeeds, kTablePresenceWords words a group): none of them could match.
PSC_DEVICE PSC_COLD void tableApplyGroups(Env& e, Turn& t, const int* groups, const u64* groupNeeds, int count) {
    int i = 0;
    bool propagated = false;
    int jumps = 0;
    TablePresence present;
    present.take(e);
    while (i < count) {
        const int* g = groups + 5 * i;
        const bool banned = g[3] >= 0 && ((t.banned >> g[3]) & 1u) != 0;
        const bool ran = !banned && present.holdsAll(groupNeeds + kTablePresenceWords * i) &&
                         tableApplyGroup(e, t, present, g[0], g[1], g[2] != 0);
        propagated = ran || propagated;
        if (propagated && g[4] >= 0) {
            i = g[4];
            propagated = false;
            if (++jumps > 200) break;
            continue;
        }
        ++i;
    }
}

}  // namespace psc_game
