// Which objects a state key holds (templates/state_key.h): those an input can
// create, destroy or move.  An object no rule adds or removes, that is not a
// player, and that no rule sets moving, lies where the level put it in every
// state of the level, so the template environment holds it and keys leave it
// out (sokoban's walls, background and targets: a key holds only the player
// and the crates).
//
// And which of them search may take for one another (keyFolds): objects of
// one collision layer that nothing but their own creation tells apart, as
// limerick's horizontal and vertical body segments.  Every rule's cells, the
// win conditions, the player and the move sounds (which the reference's
// movement reads, item 39 of the semantics guide) name both or neither; so
// two states that differ only in which of them stands in some cells match
// the same rules at the same places, clear the same cells, set the same
// objects and win together, and stay so after any input.  psc_expand's
// children hold each such class's cells on its first member's board
// (foldKey): search stores one state where the level has many that behave
// alike (limerick level 9 at depth 28: 4.1 M states against 8.0 M).
#pragma once

#include <vector>

#include "ir/Ir.h"

namespace psc::codegen {

// Object ids, increasing.
std::vector<int> keyObjects(const ir::Game& game);

// For each of keyObjects' entries, the index of the entry its cells fold
// into: its own for the first object of a class (and for objects alike to
// no other), that first object's for the others.
std::vector<int> keyFolds(const ir::Game& game, const std::vector<int>& keyIds);

}  // namespace psc::codegen
