// ResolveLegend: gives every object its id and collision layer, resolves
// colours and sprites, and builds the legend tables.
//
// Ids are handed out while walking COLLISIONLAYERS (layer 0 first, left to
// right), so they follow layer order, not OBJECTS order; an object listed
// twice takes an id per listing and keeps the last (the earlier ids become
// ghosts that still count).  Synonym chains are followed, properties and
// aggregates are flattened, single-layer properties are noted, the glyph
// table for level maps is built, and the background object is chosen.
// (Reference: compiler.js generateExtraMembers.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void resolveLegend(CompileState& state);

}  // namespace psc::passes
