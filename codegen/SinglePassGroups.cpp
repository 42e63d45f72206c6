#include "SinglePassGroups.h"

#include "RuleParts.h"

namespace psc::codegen {

namespace {

// Whether a cell that matched `cell` surely no longer does once `effect`
// has written it: an object or movement bit it requires is gone, or every
// object of one of its any-of sets is.
bool clearsWhatItRequires(const ir::CellPattern& cell, const ReplacementEffect& effect) {
    if (effect.objectsCleared.intersects(cell.present) || effect.movementsCleared.intersects(cell.movementsPresent)) return true;
    for (const BitSet& any : cell.anyOf) {
        if (any.any() && any.subsetOf(effect.objectsCleared)) return true;
    }
    return false;
}

}  // namespace

bool passesOnce(const ir::Game& g, const ir::RuleGroup& group, bool layersExclusive) {
    if (group.random) return false;
    const size_t objects = static_cast<size_t>(g.objectCount);
    const size_t movements = static_cast<size_t>(5 * g.layerCount);
    BitSet requiredObjects(objects), ruledOutObjects(objects), requiredMovements(movements), ruledOutMovements(movements);
    BitSet setObjects(objects), clearedObjects(objects), setMovements(movements), clearedMovements(movements);
    for (const ir::Rule& rule : group.rules) {
        if (rule.rigid || rule.random) return false;
        bool writes = false;
        bool undoesItsMatch = false;
        for (size_t rowIndex = 0; rowIndex < rule.rows.size(); ++rowIndex) {
            for (const ir::CellPattern& cell : rule.rows[rowIndex]) {
                if (cell.ellipsis) continue;
                requiredObjects |= cell.present;
                for (const BitSet& any : cell.anyOf) requiredObjects |= any;
                ruledOutObjects |= cell.missing;
                requiredMovements |= cell.movementsPresent;
                ruledOutMovements |= cell.movementsMissing;
                if (!rule.hasReplacements || !cell.replacement) continue;
                const ir::Replacement& r = *cell.replacement;
                if (r.randomEntity.any() || r.randomDirMask.any()) return false;
                // Where the cell is known to hold an object, putting it there writes nothing.
                const std::optional<CellFacts> facts = knownFacts(g, rule, rowIndex, cell, layersExclusive);
                const ReplacementEffect effect = effectOf(r, facts ? &*facts : nullptr);
                setObjects |= effect.objectsSet;
                clearedObjects |= effect.objectsCleared;
                setMovements |= effect.movementsSet;
                clearedMovements |= effect.movementsCleared;
                writes = writes || effect.objectsSet.any() || effect.objectsCleared.any() || effect.movementsSet.any() ||
                         effect.movementsCleared.any();
                undoesItsMatch = undoesItsMatch || clearsWhatItRequires(cell, effect);
            }
        }
        if (writes && !undoesItsMatch) return false;
    }
    return !setObjects.intersects(requiredObjects) && !setObjects.intersects(ruledOutObjects) &&
           !clearedObjects.intersects(ruledOutObjects) && !setMovements.intersects(requiredMovements) &&
           !setMovements.intersects(ruledOutMovements) && !clearedMovements.intersects(ruledOutMovements);
}

}  // namespace psc::codegen
