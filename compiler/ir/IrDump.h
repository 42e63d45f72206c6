// --emit ir: the compiled game in readable text (rules in PuzzleScript-like
// notation with absolute directions), or as JSON (the reference layout plus
// every level's cells).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "ir/Ir.h"

namespace psc::ir {

std::string dumpText(const Game& game, const std::string& sourceName);
nlohmann::ordered_json dumpJson(const Game& game, const std::string& sourceSha1);

// One rule as text, e.g. "down [ crate | up player ] -> [ up crate | up player ]".
std::string ruleText(const Game& game, const Rule& rule);

}  // namespace psc::ir
