// The front end: PuzzleScript source → ir::Game, with the reference
// compiler's diagnostics and its verdict on the game.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "ast/Ast.h"
#include "ir/Ir.h"
#include "base/Diagnostics.h"

namespace psc {

// What the reference engine would do with the game.
enum class CompileStatus {
    Ok,           // no errors
    Playable,     // 1 to 5 errors; the reference still plays it
    Refused,      // more than 5 errors; the reference does not start it
    Invalid,      // a fatal error (no collision layers, unequal rule rows, ...)
    ParseGaveUp,  // more than 5 errors while parsing
    Aborted,      // the reference throws (too many messages, a legend cycle, ...)
};

const char* statusName(CompileStatus status);

struct CompileResult {
    CompileStatus status = CompileStatus::Ok;
    Diagnostics diagnostics;
    std::optional<ast::Game> ast;  // when parsing finished
    std::optional<ir::Game> game;  // when the reference would build a game (Ok, Playable, Refused)
    std::string abortReason;

    bool playable() const { return status == CompileStatus::Ok || status == CompileStatus::Playable; }
};

// Scans and parses only (for --emit ast).
CompileResult parseSource(std::string_view source);
// The whole front end.
CompileResult compileSource(std::string_view source);

}  // namespace psc
