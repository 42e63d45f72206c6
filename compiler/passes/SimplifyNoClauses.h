// SimplifyNoClauses: checks and trims `no X` in rule cells.
//
// A right-hand cell that asks for X and `no X` is an error; a right-hand
// `no X` repeated from the left-hand cell is dropped; a left-hand `no X` is
// dropped (with a warning) when the cell's other requirements already fill
// every layer X could be on.  Behaviour does not change, but the rule text
// (and so duplicate removal) does.
// (Reference: compiler.js checkSuperfluousCoincidences.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void simplifyNoClauses(CompileState& state);

}  // namespace psc::passes
