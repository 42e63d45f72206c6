// DirectionVariants: finds a rule's direction copies that can run as one code
// path, with the direction as data.
//
// ExpandDirections makes one rule per direction a source rule applies in
// (up and left flipped to down and right, their rows' cells reversed).  On a
// GPU, the environments of a warp whose inputs went different ways match
// different copies, and the warp runs the copies' replacements one after
// another with a few threads each (docs/performance.md, "which code runs
// with few threads").  Where consecutive copies of one source rule write the
// same objects at corresponding cells and differ only in the step between
// cells, the order of a row's cells and the movement bits they write, a
// single match of any copy can be applied by one code path that takes the
// copy's step, cell offsets and bits as values (RuleCode's emitDirectionSet).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "RuleParts.h"
#include "ir/Ir.h"

namespace psc::codegen {

// Consecutive rules of a group, [first, first + count), copies of one
// source rule.  Slot j of row r is cell j of the first copy's row r;
// cellOf[v][r][j] is the cell of copy v that corresponds to it (j, or its
// mirror where the copy's row is reversed).  Corresponding cells write the
// same object updates and update the same layers' movements.
struct DirectionSet {
    size_t first = 0;
    size_t count = 0;
    std::vector<std::vector<std::vector<size_t>>> cellOf;
};

// The sets of two or more copies in a group that is not random.  A copy
// qualifies with replacements, no ellipsis, no rigid claim and no random
// draw; `layersExclusive`: layersHoldOneObject(game).
std::vector<DirectionSet> directionSets(const ir::Game& game, const ir::RuleGroup& group, bool layersExclusive);

// The updates of cell `cell` of row `row` as RuleCode applies them one match
// at a time (its facts where they hold).
struct CellUpdates {
    std::vector<ObjectUpdate> objects;
    std::vector<MovementUpdate> movements;
};
CellUpdates cellUpdates(const ir::Game& game, const ir::Rule& rule, size_t row, size_t cell, bool layersExclusive);

// The boards a rule's replacements may set bits of, as presence bits
// (neededPresence's: object ids, then the movement boards; `words` 64-bit
// words).  A board the rule needs that none of these sets stays as it was.
std::vector<uint64_t> setPresence(const ir::Game& game, const ir::Rule& rule, int words, bool layersExclusive);

}  // namespace psc::codegen
