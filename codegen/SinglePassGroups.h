// SinglePassGroups: rule groups whose loop ends after its first pass, so
// that the group's code runs its rules once instead of looping until a pass
// changes nothing.
//
// The reference passes over a group's rules until a pass changes nothing
// (at most 200 passes).  A pass that changed something is followed by
// another, which usually matches nothing: for `[ > Player ] -> [ Moved ]` it
// only finds that no player is moving any more.  A group skips that pass
// when (1) no rule of it writes what a rule of it reads, except that a write
// may clear an object or movement bit that every rule reading it requires
// present (so a write can only take matches away), and (2) every rule of it
// that writes clears, at one of its cells, an object or movement bit that
// cell requires (so an applied match no longer matches).  After the first
// pass, then, every match its rules had was applied or had stopped matching,
// none can have appeared, and the second pass would match nothing: it would
// change no cell and queue no command.  Random and rigid groups, and rules
// that place a random object or movement, keep their loop.
#pragma once

#include "ir/Ir.h"

namespace psc::codegen {

// Whether `group`'s second pass can match nothing after a first pass.
// `layersExclusive`: layersHoldOneObject(game), which scans every rule of the
// game, so its callers take it once a game, not once a group.
bool passesOnce(const ir::Game& game, const ir::RuleGroup& group, bool layersExclusive);

}  // namespace psc::codegen
