// ReadRules: reads every line of the RULES section with the rule grammar
// into ast::RuleSyntax (directions, cell rows, commands, '+' groups) and
// collects the startloop/endloop markers.
// (Reference: compiler.js processRuleString, first half of rulesToArray.)
#pragma once

#include "passes/CompileState.h"

namespace psc::passes {

void readRules(CompileState& state);

}  // namespace psc::passes
