// CheckLayers: every declared object must be in some collision layer.
// (Reference: compiler.js checkObjectsAreLayered.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void checkLayers(CompileState& state);

}  // namespace psc::passes
