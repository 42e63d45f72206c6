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
    std::vector<GroupReads> earlyReads, lateReads;
    for (const auto& group : g.rules) {
        s.early.push_back(mayStopMattering(group));
        earlyReads.push_back(readsOf(group));
    }
    for (const auto& group : g.lateRules) {
        s.late.push_back(mayStopMattering(group));
        lateReads.push_back(readsOf(group));
    }
    // Objects the other groups and movement may add or remove (a dormant
    // group's writes and movements happen only when it matches); a group they
    // could wake joins the others, until none can be woken.
    const BitSet moving = inputMovedObjects(g);
    for (bool changed = true; changed && s.any();) {
        BitSet added = moving;
        BitSet removed = moving;
        auto addOthers = [&](const std::vector<ir::RuleGroup>& groups, const std::vector<bool>& dormant) {
            for (size_t i = 0; i < groups.size(); ++i) {
                if (dormant[i]) continue;
                for (const auto& rule : groups[i].rules) {
                    for (const auto& row : rule.rows) {
                        for (const auto& cell : row) {
                            if (!cell.replacement) continue;
                            const ir::Replacement& r = *cell.replacement;
                            for (int L = 0; L < g.layerCount; ++L) {
                                if (!r.movementsSet.field(L) && !r.randomDirMask.field(L)) continue;
                                const BitSet movers = movedObjects(g, cell, L);
                                added |= movers;
                                removed |= movers;
                            }
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
        auto drop = [&](const std::vector<GroupReads>& reads, std::vector<bool>& dormant) {
            for (size_t i = 0; i < reads.size(); ++i) {
                if (dormant[i] && (reads[i].present.intersects(added) || reads[i].missing.intersects(removed))) {
                    dormant[i] = false;
                    changed = true;
                }
            }
        };
        drop(earlyReads, s.early);
        drop(lateReads, s.late);
    }
    return s;
}

}  // namespace psc::codegen
