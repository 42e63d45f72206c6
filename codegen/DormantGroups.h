// DormantGroups: rule groups that stop mattering once a turn leaves them
// unmatched, such as the wall-tiling rules many games run at a level's start.
//
// A group can go dormant when every rule of it (1) reads no movement, (2)
// changes its cells whenever it matches (it removes an object it requires or
// adds one it rules out), issues no command and is neither random nor rigid,
// and (3) no rule outside the dormant groups, and no movement, can add an
// object a dormant rule requires or remove one it rules out.  A match then
// needs something only the dormant groups could have done: after a turn in
// which none of them matched, none can match until the level is replaced (a
// level load, undo, restart, or a state set from outside), and the turn
// skips them (Env::dormant, templates/engine.h).  A skipped group is one that
// would have matched nothing: the level and every command stay the
// reference's.
#pragma once

#include <vector>

#include "ir/Ir.h"

namespace psc::codegen {

struct DormantGroups {
    std::vector<bool> early;  // by index into game.rules
    std::vector<bool> late;   // by index into game.lateRules
    bool any() const;
};

DormantGroups dormantGroups(const ir::Game& game);

}  // namespace psc::codegen
