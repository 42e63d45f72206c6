// --emit ast: the parsed game, section by section, as text or JSON.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "ast/Ast.h"

namespace psc::ast {

std::string dumpText(const Game& game);
nlohmann::ordered_json dumpJson(const Game& game);

}  // namespace psc::ast
