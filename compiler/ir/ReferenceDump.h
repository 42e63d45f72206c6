// The IR in the format of the corpus' compiled-IR oracle
// (../shared/corpus/COMPILED.md): names, layer indices and direction words,
// laid out as the oracle's files are, so that psc's compile of a game can be
// compared with the reference compiler's, file against file.
#pragma once

#include <string>

#include "ir/Ir.h"
#include "base/JsonText.h"

namespace psc::ir {

json::Value referenceDump(const Game& game, const std::string& sourceSha1);
std::string referenceDumpText(const Game& game, const std::string& sourceSha1);

}  // namespace psc::ir
