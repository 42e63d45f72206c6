// BuildMasks: the object set of every name (objects, synonyms, properties,
// aggregates), the player mask and one mask per collision layer.
//
// Synonyms and properties are resolved in source-line order, so a property
// may use a synonym defined above it.  An object that is in no collision
// layer has no id; like the reference, its mask falls back to bit 0.
// (Reference: compiler.js generateMasks.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void buildMasks(CompileState& state);

}  // namespace psc::passes
