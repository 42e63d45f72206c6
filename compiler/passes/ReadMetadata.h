// ReadMetadata: the prelude as the compiler keeps it (the last value of each
// key; flickscreen and zoomscreen read as WxH, dropped when malformed), and
// the text and background colours checked.
// (Reference: compiler.js twiddleMetaData, formatHomePage.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void readMetadata(CompileState& state);

}  // namespace psc::passes
