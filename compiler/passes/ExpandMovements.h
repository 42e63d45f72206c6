// ExpandMovements: replaces ambiguous movement words (moving, orthogonal,
// horizontal, vertical, parallel, perpendicular) by concrete directions, one
// rule per choice, and infers the matching right-hand movements.
//
// The expansion is the reference's worklist, duplicates included (they are
// removed later, and which copy survives decides the rule order), so it is
// reproduced step for step rather than predicted (RuleSplitting.h).  A
// right-hand ambiguous movement that cannot be inferred makes the game
// invalid; so does splitting past kMaxExpandedRules rules.
// (Reference: compiler.js concretizeMovingRule.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void expandMovements(CompileState& state);

}  // namespace psc::passes
