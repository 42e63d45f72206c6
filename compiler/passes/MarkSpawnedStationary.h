// MarkSpawnedStationary: an object that a (non-late) rule adds to a cell,
// with no movement given, is made `stationary`, unless the left-hand cell
// already mentions it or anything on its layer (even under `no`).
// (Reference: compiler.js makeSpawnedObjectsStationary.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void markSpawnedStationary(CompileState& state);

}  // namespace psc::passes
