// EncodeRules: turns each expanded rule's cells into masks.
//
// A left-hand cell becomes a pattern (objects present and missing, "any of"
// sets for single-layer properties, movements present and missing); the
// right-hand cell at the same place becomes a replacement (objects cleared
// and set, movements cleared and set, layers whose movement is reset, random
// objects and random directions).  Adding an object clears its layer; a
// layer the rule empties loses its movement.  Rules that can never match
// ("X no X") and rules with an ellipsis at a row's edge are dropped; rules
// with two requirements on one layer are marked for GroupRules to drop.
// (Reference: compiler.js rulesToMask.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void encodeRules(CompileState& state);

// The movement bits a modifier word stands for (0 for none).
int directionMask(const std::string& word);

}  // namespace psc::passes
