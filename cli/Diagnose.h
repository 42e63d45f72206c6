// Printing compile diagnostics as "file:line:col: error|warning: message".
#pragma once

#include <cstdio>
#include <string>

#include "Compiler.h"

namespace psc::cli {

void printDiagnostics(std::FILE* out, const std::string& path, const CompileResult& result);
// A one-line account of what the reference would do, when it does not play the game.
std::string verdict(const CompileResult& result);

}  // namespace psc::cli
