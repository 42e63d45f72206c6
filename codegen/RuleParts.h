// RuleParts: what a rule's replacements and commands do, as data.
//
// Both rule forms read these: RuleCode spells them as straight-line C++,
// RuleTable writes them into the table its interpreter walks
// (templates/rule_table.h).  Deriving them once keeps the two forms doing
// the same changes in the same order, which is what makes them bit-exact.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ir/Ir.h"

namespace psc::codegen {

// One change of a cell's objects: a collision layer cleared as a whole but
// for at most one object it keeps (`keep`, or -1), or one object set or
// cleared.
struct ObjectUpdate {
    enum Kind { kPutLayer, kAssign } kind;
    int layerOrObject;
    int keepOrValue;  // the object kept (-1: none), or the value assigned (0 or 1)
};
// What a cell pattern says of its cell while the match it is part of is
// applied (before any of that match's replacements touch the cell): the
// objects the cell may hold, those it holds, and movement bits it has or has
// not.  A collision layer holds one object a cell, so an object required, or
// a property of one layer, rules out the layer's other objects.
struct CellFacts {
    BitSet possible;
    BitSet present;
    BitSet movementsPresent;
    BitSet movementsMissing;
};
// Valid only where layersHoldOneObject(game) and cellFactsHold.
CellFacts cellFacts(const ir::Game& game, const ir::CellPattern& cell);
// Whether no position can match cells `a` and `b` at once: one requires an
// object or movement the other rules out.  Valid only where
// layersHoldOneObject(game).
bool cellsExclude(const ir::Game& game, const ir::CellPattern& a, const ir::CellPattern& b);
// Whether cell `cell` of row `row` still is as its pattern saw it when its
// replacement runs: a match applies its rows in order, and a row's cells lie
// at distinct positions, but an earlier row's cell may share its position
// unless their patterns exclude each other (a match's rows all hold before
// it writes); it holds where no earlier cell that may share it writes what
// the cell's facts rest on (the layers its pattern constrains, the objects it
// rules out, its movements).  Valid only where layersHoldOneObject(game).
bool cellFactsHold(const ir::Game& game, const ir::Rule& rule, size_t row, const ir::CellPattern& cell);
// Whether no cell ever holds two objects of one layer: levels cannot place
// two (a glyph keeps one object a layer), so only a replacement that sets two
// objects of one layer (an error the reference plays on with) can.
bool layersHoldOneObject(const ir::Game& game);
// The facts of cell `cell` of row `row` where they hold (cellFactsHold, and
// `layersExclusive`: layersHoldOneObject(game), computed once a game).
std::optional<CellFacts> knownFacts(const ir::Game& game, const ir::Rule& rule, size_t row, const ir::CellPattern& cell,
                                    bool layersExclusive);

// The bits a replacement sets and those it clears (a bit both cleared and
// set ends set); with `facts`, only objects it can change (as objectUpdates
// leaves out the others): not one the cell holds set again, nor one it
// cannot hold cleared.  Movements cleared include the layer fields the
// replacement clears whole.
struct ReplacementEffect {
    BitSet objectsSet;
    BitSet objectsCleared;
    BitSet movementsSet;
    BitSet movementsCleared;
};
ReplacementEffect effectOf(const ir::Replacement& r, const CellFacts* facts = nullptr);
// Whether cell pattern `c`, matched at a position, still matches there after
// a replacement with `effect` writes it: nothing it rules out is set, nothing
// it requires is cleared, and each of its any-of sets keeps a member or gains
// one.
bool stillMatchesAfter(const ir::CellPattern& c, const ReplacementEffect& effect);

// Layers cleared whole come first (in layer order), then single objects
// cleared, then set.  With `facts`, updates that cannot change the cell are
// left out: clearing an object it cannot hold, setting one it holds; a layer
// is cleared whole only where it may hold any of its objects.
std::vector<ObjectUpdate> objectUpdates(const ir::Game& game, const BitSet& set, const BitSet& clear,
                                        const CellFacts* facts = nullptr);

// One layer's movement field: bits `clear` cleared, `set` set (set wins),
// plus the bit of a direction drawn at random when `randomDirection`.
struct MovementUpdate {
    int layer;
    uint32_t clear;
    uint32_t set;
    bool randomDirection;
};
// `entityLayer`: the layer of a `random` object just placed, cleared whole.
// With `facts`, bits the cell has are not set again nor bits it lacks cleared.
std::vector<MovementUpdate> movementUpdates(const ir::Game& game, const ir::Replacement& r, std::optional<int> entityLayer,
                                            const CellFacts* facts = nullptr);

// Calls f(cell) for each cell pattern, in every rule, early and late.
template <typename F>
void forEachCell(const ir::Game& game, F f) {
    for (const auto* groups : {&game.rules, &game.lateRules}) {
        for (const auto& group : *groups) {
            for (const auto& rule : group.rules) {
                for (const auto& row : rule.rows) {
                    for (const auto& cell : row) f(cell);
                }
            }
        }
    }
}

// Calls f(cell) for each cell pattern with a replacement.
template <typename F>
void forEachReplacingCell(const ir::Game& game, F f) {
    forEachCell(game, [&](const ir::CellPattern& cell) {
        if (cell.replacement) f(cell);
    });
}

// The objects input moves: the player's, with the live ids of its ghosts.
BitSet inputMovedObjects(const ir::Game& game);
// Objects that a replacement setting movement on `layer` may set moving: the
// layer's objects the cell names (present, added or among a property's
// choices), or, when it names none, any object the layer can hold there.
BitSet movedObjects(const ir::Game& game, const ir::CellPattern& cell, int layer);
// Objects a replacement removes that can be in the cell at all: not ruled out
// by the pattern (`no X`, or another object of X's layer that must be there).
// Replacements list a whole layer's objects as removed when they add one.
BitSet removedObjects(const ir::Game& game, const ir::CellPattern& cell);

// The layers whose objects can move, a bit each: the player's (input) and
// those a replacement gives a movement or a random direction.  The other
// layers' movement boards stay empty, so movement resolution skips them
// (templates/movement.h).  Past 64 layers, every layer counts as moving.
uint64_t movingLayerBits(const ir::Game& game);
// Whether layer `layer` can move, given movingLayerBits (as the generated
// code's layerCanMove: every layer past the 64th counts as moving).
inline bool layerCanMove(uint64_t movingBits, size_t layer) { return layer >= 64 || ((movingBits >> layer) & 1); }

// Whether a cell's movement-sound reads can reach three while it moves two
// layers, which makes the reference reload the cell's movements mid-way
// (templates/movement.h): at least two moving layers and three
// movement-sound declarations on them.  Where it cannot, movement can be
// resolved over whole boards.
bool soundReadsCanReload(const ir::Game& game);

// A rigid rule's claim on the layers its replacement moves: the rigid
// group's index + 1 (0: the rule claims nothing) and those layers.
struct RigidClaim {
    int claim = 0;
    std::vector<int> layers;
};
RigidClaim rigidClaim(const ir::Game& game, const ir::Rule& rule, const ir::Replacement& r);
// The rigid group's index + 1 of a rigid rule, else 0.
int rigidGroupClaim(const ir::Game& game, const ir::Rule& rule);

// The layer of object `id` (a ghost object's live object's), or -1.
int layerOfObject(const ir::Game& game, int id);

// The rule's commands as templates/core.h's Command bits.
uint32_t commandBits(const ir::Rule& rule);

// Whether a row of the rule has an ellipsis.
bool hasEllipsis(const ir::Rule& rule);

// The text of the rule's (first) `message` command, or null.
const std::string* messageOf(const ir::Rule& rule);

// The index of the rule's `message` text in `messages` (ruleMessages), or -1.
int messageIndex(const ir::Rule& rule, const std::vector<std::string>& messages);

// The name of a group's function.
std::string groupName(const ir::RuleGroup& group, size_t index, bool late);

// The boards a rule's every match needs non-empty, as presence bits (object
// id, or the object count + the movement board's index; `words` 64-bit
// words): those of its cells' single-board terms.  While one is empty the
// rule cannot match, and its rows' boards need not be built.
// The 64-bit words of a game's presence bits: its objects, then 5 movement boards a layer.
int presenceWords(const ir::Game& game);
std::vector<uint64_t> neededPresence(const ir::Game& game, const ir::Rule& rule, int words);
// The boards every rule of a group needs: while one is empty the group changes nothing.
std::vector<uint64_t> groupNeededPresence(const ir::Game& game, const ir::RuleGroup& group, int words);

}  // namespace psc::codegen
