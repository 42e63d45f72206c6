// Inputs as letters, for --replay, --replay-file and --record: u l d r x as
// psc solve writes them (up, left, down, right, action), z undo, ! restart,
// . a realtime tick.  Case, spaces, newlines and lines starting with # are
// ignored when reading.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace psc::play {

char inputLetter(int action);  // psc_action -> letter
// The actions of a script; nothing and *problem when a character is no input.
std::optional<std::vector<int>> parseInputScript(const std::string& text, std::string* problem);

}  // namespace psc::play
