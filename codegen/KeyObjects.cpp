#include "KeyObjects.h"

#include "RuleParts.h"

namespace psc::codegen {

std::vector<int> keyObjects(const ir::Game& g) {
    BitSet changing = inputMovedObjects(g);
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

namespace {

// The object sets through which the game tells objects apart: every set a
// cell pattern tests or a replacement clears, the win conditions' sets and
// the player's.  A replacement's added objects are not among them: which
// object a rule creates is what folding forgets.
std::vector<BitSet> distinguishingSets(const ir::Game& g) {
    std::vector<BitSet> sets = {g.playerMask};
    forEachCell(g, [&](const ir::CellPattern& cell) {
        sets.push_back(cell.present);
        sets.push_back(cell.missing);
        sets.insert(sets.end(), cell.anyOf.begin(), cell.anyOf.end());
        if (cell.replacement) sets.push_back(cell.replacement->clear);
    });
    for (const auto& w : g.winConditions) {
        sets.push_back(w.objects);
        sets.push_back(w.on);
    }
    return sets;
}

}  // namespace

std::vector<int> keyFolds(const ir::Game& g, const std::vector<int>& keyIds) {
    std::vector<int> into(keyIds.size());
    for (size_t k = 0; k < keyIds.size(); ++k) into[k] = static_cast<int>(k);
    // Two objects of one layer in one cell (a replacement's error the
    // reference plays on with) would be one after folding; aggregate players
    // are tested object by object.
    if (!layersHoldOneObject(g) || g.playerIsAggregate) return into;
    BitSet excluded;
    if (g.background) excluded.set(static_cast<size_t>(g.background->id));
    for (const auto& o : g.objects) {
        if (o.ghost) {
            excluded.set(static_cast<size_t>(o.id));
            if (o.liveId) excluded.set(static_cast<size_t>(*o.liveId));
        }
    }
    for (const auto& layer : g.sounds.move) {
        for (const auto& s : layer) excluded.set(static_cast<size_t>(s.objectId));
    }
    for (const auto& s : g.sounds.cantMove) excluded.set(static_cast<size_t>(s.objectId));
    const std::vector<BitSet> sets = distinguishingSets(g);
    auto alike = [&](size_t a, size_t b) {
        for (const BitSet& s : sets) {
            if (s.test(a) != s.test(b)) return false;
        }
        return true;
    };
    for (size_t k = 0; k < keyIds.size(); ++k) {
        const auto a = static_cast<size_t>(keyIds[k]);
        if (excluded.test(a) || !g.objects[a].layer) continue;
        for (size_t first = 0; first < k; ++first) {
            const auto b = static_cast<size_t>(keyIds[first]);
            if (into[first] != static_cast<int>(first) || excluded.test(b) || g.objects[b].layer != g.objects[a].layer) continue;
            if (alike(a, b)) {
                into[k] = static_cast<int>(first);
                break;
            }
        }
    }
    return into;
}

}  // namespace psc::codegen
