// BuildLevels: turns each LEVELS entry into a message or a grid of object
// sets (column-major, index x * height + y).
//
// Width is the first row's length; a shorter row repeats its own last
// glyph.  Cells with nothing on the background layer get the background
// objects of the first cell (in index order) that has any.
// (Reference: compiler.js levelsToArray, levelFromString; level.js
// calcBackgroundMask.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

// A limit of psc's (the reference has none): levels of more cells are rejected.
inline constexpr size_t kMaxLevelCells = size_t{1} << 20;

void buildLevels(CompileState& state);

}  // namespace psc::passes
