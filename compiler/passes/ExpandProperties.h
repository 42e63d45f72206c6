// ExpandProperties: replaces properties (names defined with OR) by their
// members where a rule needs it, one rule per member.
//
// `no P` becomes `no m1 no m2 ...`.  A property is split when its members
// span several layers or when the right-hand side uses it without the
// left-hand cell doing so; otherwise it stays and matches as "any of".  A
// property split in a single left-hand cell fixes its right-hand uses too;
// one left ambiguous on the right drops the rule with an error.  Splitting
// past kMaxExpandedRules rules (RuleSplitting.h) makes the game invalid.
// (Reference: compiler.js concretizePropertyRule.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void expandProperties(CompileState& state);

}  // namespace psc::passes
