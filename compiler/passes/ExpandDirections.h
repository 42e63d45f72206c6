// ExpandDirections: one rule per direction it applies in, with relative
// directions made absolute, up/left rules flipped, and legend names spelled
// out.
//
// Direction copies come in the order listed (orthogonal: up, down, left,
// right).  `^ v < >` and parallel/perpendicular are resolved against the
// copy's own direction.  Then an up or left rule without an ellipsis becomes
// a down or right rule with every row reversed (so plain rules scan
// column-major).  Aggregates become their parts and synonyms their targets.
// (Reference: compiler.js rulesToArray, convertRelativeDirsToAbsolute,
// rewriteUpLeftRules, atomizeAggregates, rephraseSynonyms.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void expandDirections(CompileState& state);

}  // namespace psc::passes
