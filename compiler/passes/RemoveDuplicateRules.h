// RemoveDuplicateRules: expansion produces identical rules; within each run
// of rules of one group only the last copy of each is kept.
//
// Two rules are the same when their source line, flags, cells and commands
// match, and, if some left-hand row has more than one cell, their direction.
// (Reference: compiler.js cacheRuleStringRep, removeDuplicateRules.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void removeDuplicateRules(CompileState& state);

}  // namespace psc::passes
