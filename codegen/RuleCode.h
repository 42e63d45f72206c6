// RuleCode: emits each rule group as straight-line C++ over bitboards.
//
// A rule becomes a function that computes, for each cell row, the set of
// positions where the row matches (cell patterns as AND/ANDNOT of object and
// movement boards, shifted along the rule's direction), then visits the
// matches in the reference's scan order, re-checking every match after the
// first against the current board before applying its replacements.
// Random groups count their candidate matches, draw one and apply it.  A
// rule's direction copies that write alike also run as one function
// (DirectionVariants.h), so that a GPU warp applies any one's single match
// at once.
// Masks are constants in the code; names come from the source line.
#pragma once

#include <string>
#include <vector>

#include "CodeWriter.h"
#include "ir/Ir.h"

namespace psc::codegen {

// Where the CUDA code's rules go (CppSource decides; templates/core.h).
struct RuleUnits {
    // Compile units: with more than one, each rule and group function is
    // declared for all units and defined in one of units 1..units-1, spread
    // by code size.
    int units = 1;
    // The groups layout: a group goes to one of units 1..groupUnits with its
    // rules, which are inlined into it, and works on a copy of the state.
    // A group of more than partBytes of code passes over parts of its rules
    // instead, each a function on a copy.  A group `apart` (by group, early
    // then late) goes with its rules to the units after groupUnits, its rules
    // out of line.  A byte of an inlined group weighs copyWeight when pieces
    // are spread over units.  Without the groups layout (the memory layout),
    // a group not `apart` goes to a unit with its rules, inlined into it.
    bool groups = false;
    // Spans (the groups layout of a game without loops, rigid bodies or
    // random): units 1..groupUnits each take a run of consecutive groups,
    // early then late, and a unit's early groups and its late groups each
    // run as one function (a span) on one copy of the state, their rules
    // and groups inlined into it; the turn calls the spans in order.
    bool spans = false;
    int groupUnits = 0;
    size_t partBytes = 0;
    size_t copyWeight = 1;
    std::vector<bool> apart;
    // A rule's direction copies also as one function (DirectionVariants.h),
    // except in the groups layout.  Off where code is weighed for the
    // layout: the choice does not depend on them.
    bool directionSets = true;
    // The memory layout: its groups' passes kept a loop (PSC_PASSES,
    // templates/core.h).  Off where code is weighed, so that the layout and
    // its units are chosen on the same code with and without it.
    bool rolledPasses = false;
    // The path for one match a row of a rule of several rows (RuleCode's
    // emitOneMatchPath, compiled where PSC_MASK_WRITES is set).  Off where
    // code is weighed, so that the layout is chosen on the same code with
    // and without it.
    bool oneMatchPaths = true;
};

// Emits rule_* and group_* functions and applyEarlyRules/applyLateRules.
// groupBytes, when given, receives each group's code size with its rules
// (early then late).
void emitRules(CodeWriter& out, const ir::Game& game, const RuleUnits& units = {},
               std::vector<size_t>* groupBytes = nullptr);

// Whether the group draws from the random stream (a random group, or a
// rule that places a random object or direction).
bool groupUsesRandom(const ir::RuleGroup& group);

// The distinct texts of the rules' `message` commands, early rules then late
// ones in source order: psc_game_info.rule_messages, which step results index.
std::vector<std::string> ruleMessages(const ir::Game& game);

}  // namespace psc::codegen
