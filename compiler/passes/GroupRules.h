// GroupRules: gathers encoded rules into groups, in execution order, and
// finishes each rule.
//
// Normal and late rules form separate lists of groups ordered by group
// number (the source line of the group's first rule).  Rules marked by
// EncodeRules as needing two objects on one layer are dropped here; if that
// empties a source line, it is an error.  Each rule's per-row ellipsis count
// is recorded.  Groups containing a rigid rule get rigid indices.
// (Reference: compiler.js arrangeRulesByGroupNumber,
// ruleGroupDiscardOverlappingTest, collapseRules, generateRigidGroupList.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void groupRules(CompileState& state);

}  // namespace psc::passes
