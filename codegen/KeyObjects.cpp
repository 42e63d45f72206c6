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

}  // namespace psc::codegen
