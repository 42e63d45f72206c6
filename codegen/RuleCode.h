// RuleCode: emits each rule group as straight-line C++ over bitboards.
//
// A rule becomes a function that computes, for each cell row, the set of
// positions where the row matches (cell patterns as AND/ANDNOT of object and
// movement boards, shifted along the rule's direction), then visits the
// matches in the reference's scan order, re-checking every match after the
// first against the current board before applying its replacements.
// Random groups count their candidate matches, draw one and apply it.
// Masks are constants in the code; names come from the source line.
#pragma once

#include <string>
#include <vector>

#include "CodeWriter.h"
#include "ir/Ir.h"

namespace psc::codegen {

// Emits rule_* and group_* functions and applyEarlyRules/applyLateRules.
// With units > 1 (CUDA compile units, templates/core.h) each rule and group
// function is declared for all units and defined in one of units 1..units-1,
// balanced by code size.
void emitRules(CodeWriter& out, const ir::Game& game, int units = 1);

// The distinct texts of the rules' `message` commands, early rules then late
// ones in source order: psc_game_info.rule_messages, which step results index.
std::vector<std::string> ruleMessages(const ir::Game& game);

}  // namespace psc::codegen
