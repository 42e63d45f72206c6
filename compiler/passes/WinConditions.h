// WinConditions: `all|some|any|no X [on Y]` as masks.
//
// `any` is `some`.  A name is looked up as an object, synonym or property
// first (the cell needs any one of its objects) and then as an aggregate
// (the cell needs all of them).  Without `on`, the second mask is every
// object.  (Reference: compiler.js processWinConditions.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void buildWinConditions(CompileState& state);

}  // namespace psc::passes
