// C++ identifiers for generated code, made from the game's own names.
#pragma once

#include <set>
#include <string>

#include "ir/Ir.h"

namespace psc::codegen {

// Letters, digits and '_' of a name (ASCII), or `fallback` when none remain.
std::string sanitize(const std::string& name, const std::string& fallback);
// e.g. "rule_L42_right_player_crate": line, direction, the objects the rule tests.
std::string ruleIdentifier(const ir::Game& game, const ir::Rule& rule, bool late);
// `base`, or base_2, base_3, ... if already used; records the result.
std::string uniqueIdentifier(const std::string& base, std::set<std::string>& used);

}  // namespace psc::codegen
