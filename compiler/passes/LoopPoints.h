// LoopPoints: pairs startloop/endloop markers and records, for each list of
// groups, the loop's last group → its first group.  A group belongs to a
// loop by its first rule's line.  Nested or unclosed loops are errors.
// (Reference: compiler.js generateLoopPoints, calculateLoopPoints.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void findLoopPoints(CompileState& state);

}  // namespace psc::passes
