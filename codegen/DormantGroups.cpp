#include "DormantGroups.h"

#include <algorithm>

#include "RuleParts.h"

namespace psc::codegen {

namespace {

// What a group's rules require present and absent.
struct GroupReads {
    BitSet present;
    BitSet missing;
};

// A cell's match always changes it: it removes an object it requires, or
// adds one it rules out.
bool alwaysChanges(const ir::CellPattern& cell) {
    const ir::Replacement& r = *cell.replacement;
    BitSet removedRequired = cell.present;
    removedRequired &= r.clear;
    removedRequired.clear(r.set);
    BitSet addedMissing = cell.missing;
    addedMissing &= r.set;
    return removedRequired.any() || addedMissing.any();
}

bool mayStopMattering(const ir::RuleGroup& group) {
    if (group.random) return false;
    return std::all_of(group.rules.begin(), group.rules.end(), [](const ir::Rule& rule) {
        if (rule.rigid || rule.random || !rule.commands.empty() || !rule.hasReplacements) return false;
        bool changes = false;
        for (const auto& row : rule.rows) {
            for (const auto& cell : row) {
                if (cell.movementsPresent.any() || cell.movementsMissing.any()) return false;
                if (cell.replacement && alwaysChanges(cell)) changes = true;
            }
        }
        return changes;
    });
}

GroupReads readsOf(const ir::RuleGroup& group) {
    GroupReads reads;
    for (const auto& rule : group.rules) {
        for (const auto& row : rule.rows) {
            for (const auto& cell : row) {
                reads.present |= cell.present;
                for (const BitSet& choice : cell.anyOf) reads.present |= choice;
                reads.missing |= cell.missing;
            }
        }
    }
    return reads;
}

}  // namespace

bool DormantGroups::any() const {
    return std::find(early.begin(), early.end(), true) != early.end() || std::find(late.begin(), late.end(), true) != late.end();
}

DormantGroups dormantGroups(const ir::Game& g) {
    DormantGroups s;
    for (const auto& group : g.rules) s.early.push_back(mayStopMattering(group));
    for (const auto& group : g.lateRules) s.late.push_back(mayStopMattering(group));
    // Objects the other groups and movement may add or remove; a group they
    // could wake joins the others, until none can be woken.
    BitSet moving = g.playerMask;
    g.playerMask.forEach([&](size_t id) {
        if (const auto& live = g.objects[id].liveId) moving.set(static_cast<size_t>(*live));
    });
    for (bool changed = true; changed && s.any();) {
        BitSet added = moving;
        BitSet removed = moving;
        auto addOthers = [&](const std::vector<ir::RuleGroup>& groups, const std::vector<bool>& dormant) {
            for (size_t i = 0; i < groups.size(); ++i) {
                for (const auto& rule : groups[i].rules) {
                    for (const auto& row : rule.rows) {
                        for (const auto& cell : row) {
                            if (!cell.replacement) continue;
                            const ir::Replacement& r = *cell.replacement;
                            for (int L = 0; L < g.layerCount; ++L) {
                                if (!r.movementsSet.field(L) && !r.randomDirMask.field(L)) continue;
                                // A dormant rule's movements, like its writes, happen only when it matches.
                                if (dormant[i]) continue;
                                const BitSet movers = movedObjects(g, cell, L);
                                added |= movers;
                                removed |= movers;
                            }
                            if (dormant[i]) continue;
                            added |= r.set;
                            added |= r.randomEntity;
                            removed |= removedObjects(g, cell);
                        }
                    }
                }
            }
        };
        addOthers(g.rules, s.early);
        addOthers(g.lateRules, s.late);
        changed = false;
        auto drop = [&](const std::vector<ir::RuleGroup>& groups, std::vector<bool>& dormant) {
            for (size_t i = 0; i < groups.size(); ++i) {
                if (!dormant[i]) continue;
                const GroupReads reads = readsOf(groups[i]);
                if (reads.present.intersects(added) || reads.missing.intersects(removed)) {
                    dormant[i] = false;
                    changed = true;
                }
            }
        };
        drop(g.rules, s.early);
        drop(g.lateRules, s.late);
    }
    return s;
}

}  // namespace psc::codegen
