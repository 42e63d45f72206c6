// Which objects a state key holds (templates/state_key.h): those an input can
// create, destroy or move.  An object no rule adds or removes, that is not a
// player, and that no rule sets moving, lies where the level put it in every
// state of the level, so the template environment holds it and keys leave it
// out (sokoban's walls, background and targets: a key holds only the player
// and the crates).
#pragma once

#include <vector>

#include "ir/Ir.h"

namespace psc::codegen {

// Object ids, increasing.
std::vector<int> keyObjects(const ir::Game& game);

}  // namespace psc::codegen
