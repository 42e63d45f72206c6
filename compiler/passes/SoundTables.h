// SoundTables: the sound declarations the engine consults during a turn
// (movement, failed movement, creation and destruction, named events).
// Movement sounds matter to simulation through an engine quirk (see
// docs/architecture.md), so they are part of the IR.
// (Reference: compiler.js generateSoundData.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void buildSoundTables(CompileState& state);

}  // namespace psc::passes
