// Scanner: source text → ast::Game.
//
// PuzzleScript is read line by line by a stateful tokenizer: the current
// section, nested comments that may span lines, the object being declared,
// the legend or sound line being collected, and the level being built.  Its
// quirks decide whether the reference accepts a game (a comment-only line
// with trailing spaces is a blank line; a section word is consumed wherever
// it appears; comment nesting carries across lines), so this scanner
// reproduces that tokenizer's behaviour and diagnostics token for token.
// Rule lines are stored as text for the rule grammar.
#pragma once

#include <string_view>

#include "ast/Ast.h"
#include "base/Diagnostics.h"

namespace psc::parse {

// The reference gives up on a game once parsing has logged more than this
// many errors.
inline constexpr int kMaxParseErrors = 5;

// Thrown when parsing gives up (more than kMaxParseErrors errors).
struct ParseGaveUp {};

// Scans `source`; throws ParseGaveUp, or CompileAborted (too many messages,
// or a legend definition that refers to itself through a cycle).
ast::Game scanGame(std::string_view source, Diagnostics& diagnostics);

// Word lists shared with the rest of the front end.
bool isKeyword(const std::string& word);
bool isCommandWord(const std::string& word);
extern const char* const kSectionNames[7];

}  // namespace psc::parse
