#include "KeyObjects.h"

#include "RuleParts.h"

namespace psc::codegen {

namespace {

// Objects that a replacement setting movement on `layer` may set moving: the
// layer's objects the cell names (present, added or among a property's
// choices), or, when it names none, any object the layer can hold there.
BitSet movedObjects(const ir::Game& g, const ir::CellPattern& cell, int layer) {
    const BitSet& onLayer = g.layerMasks[static_cast<size_t>(layer)];
    BitSet named = cell.present;
    named |= cell.replacement->set;
    for (const BitSet& choice : cell.anyOf) named |= choice;
    named &= onLayer;
    if (named.any()) return named;
    BitSet any = onLayer;
    any.clear(cell.missing);
    return any;
}

// Objects a replacement removes that can be in the cell at all: not ruled out
// by the pattern (`no X`, or another object of X's layer that must be there).
// Replacements list a whole layer's objects as removed when they add one.
BitSet removedObjects(const ir::Game& g, const ir::CellPattern& cell) {
    BitSet removed;
    cell.replacement->clear.forEach([&](size_t id) {
        if (cell.missing.test(id)) return;
        const std::optional<int>& layer = g.objects[id].layer;
        if (layer) {
            BitSet others = g.layerMasks[static_cast<size_t>(*layer)];
            others.reset(id);
            if (cell.present.intersects(others)) return;
            for (const BitSet& choice : cell.anyOf) {
                if (choice.subsetOf(others)) return;
            }
        }
        removed.set(id);
    });
    return removed;
}

}  // namespace

std::vector<int> keyObjects(const ir::Game& g) {
    BitSet changing = g.playerMask;
    g.playerMask.forEach([&](size_t id) {
        if (const auto& live = g.objects[id].liveId) changing.set(static_cast<size_t>(*live));
    });
    forEachReplacingCell(g, [&](const ir::CellPattern& cell) {
        const ir::Replacement& r = *cell.replacement;
        changing |= removedObjects(g, cell);
        changing |= r.set;
        changing |= r.randomEntity;
        for (int L = 0; L < g.layerCount; ++L) {
            if (r.movementsSet.field(L) || r.randomDirMask.field(L)) changing |= movedObjects(g, cell, L);
        }
    });
    std::vector<int> ids;
    for (int id = 0; id < g.objectCount; ++id) {
        if (changing.test(static_cast<size_t>(id))) ids.push_back(id);
    }
    return ids;
}

}  // namespace psc::codegen
