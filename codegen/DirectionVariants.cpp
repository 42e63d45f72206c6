#include "DirectionVariants.h"

#include <algorithm>

namespace psc::codegen {
namespace {

// A copy that tests a movement: which copy matches then follows the input's
// direction, which differs between a warp's environments.  Copies that test
// none match by the level's layout, alike in a warp, and are left as they
// are (the function that joins them costs build time).
bool qualifies(const ir::Rule& rule) {
    if (!rule.hasReplacements || rule.rigid || hasEllipsis(rule)) return false;
    bool movement = false;
    for (const auto& row : rule.rows) {
        for (const auto& cell : row) {
            if (cell.replacement && (cell.replacement->randomEntity.any() || cell.replacement->randomDirMask.any())) return false;
            movement = movement || cell.movementsPresent.any();
        }
    }
    return movement;
}

bool sameShape(const ir::Rule& a, const ir::Rule& b) {
    if (a.line != b.line || a.rows.size() != b.rows.size()) return false;
    for (size_t r = 0; r < a.rows.size(); ++r) {
        if (a.rows[r].size() != b.rows[r].size()) return false;
    }
    return true;
}

// Same object updates, and movement updates of the same layers (their bits may differ).
bool sameWrites(const CellUpdates& a, const CellUpdates& b) {
    if (a.objects.size() != b.objects.size() || a.movements.size() != b.movements.size()) return false;
    for (size_t i = 0; i < a.objects.size(); ++i) {
        const ObjectUpdate& x = a.objects[i];
        const ObjectUpdate& y = b.objects[i];
        if (x.kind != y.kind || x.layerOrObject != y.layerOrObject || x.keepOrValue != y.keepOrValue) return false;
    }
    for (size_t i = 0; i < a.movements.size(); ++i) {
        if (a.movements[i].layer != b.movements[i].layer || a.movements[i].randomDirection ||
            b.movements[i].randomDirection) {
            return false;
        }
    }
    return true;
}

// Copy `copy`'s cells for the first copy's slots, row by row: in order or
// reversed, whichever writes alike; empty when neither does.
std::vector<std::vector<size_t>> correspondence(const ir::Game& game, const ir::Rule& first, const ir::Rule& copy,
                                                bool layersExclusive) {
    std::vector<std::vector<size_t>> cellOf;
    for (size_t r = 0; r < first.rows.size(); ++r) {
        const size_t n = first.rows[r].size();
        std::vector<CellUpdates> mine;
        std::vector<CellUpdates> theirs;
        for (size_t i = 0; i < n; ++i) {
            mine.push_back(cellUpdates(game, first, r, i, layersExclusive));
            theirs.push_back(cellUpdates(game, copy, r, i, layersExclusive));
        }
        bool forward = true;
        bool reversed = true;
        for (size_t i = 0; i < n; ++i) {
            forward = forward && sameWrites(mine[i], theirs[i]);
            reversed = reversed && sameWrites(mine[i], theirs[n - 1 - i]);
        }
        if (!forward && !reversed) return {};
        std::vector<size_t> row;
        for (size_t i = 0; i < n; ++i) row.push_back(forward ? i : n - 1 - i);
        cellOf.push_back(std::move(row));
    }
    return cellOf;
}

}  // namespace

CellUpdates cellUpdates(const ir::Game& game, const ir::Rule& rule, size_t row, size_t cell, bool layersExclusive) {
    const ir::CellPattern& c = rule.rows[row][cell];
    if (!c.replacement) return {};
    const std::optional<CellFacts> facts = knownFacts(game, rule, row, c, layersExclusive);
    const CellFacts* known = facts ? &*facts : nullptr;
    return {objectUpdates(game, c.replacement->set, c.replacement->clear, known),
            movementUpdates(game, *c.replacement, std::nullopt, known)};
}

std::vector<uint64_t> setPresence(const ir::Game& game, const ir::Rule& rule, int words, bool layersExclusive) {
    std::vector<uint64_t> bits(static_cast<size_t>(words), 0);
    auto set = [&](int bit) { bits[static_cast<size_t>(bit / 64)] |= uint64_t{1} << (bit % 64); };
    const int objects = std::max(1, game.objectCount);
    for (size_t r = 0; r < rule.rows.size(); ++r) {
        for (size_t i = 0; i < rule.rows[r].size(); ++i) {
            const CellUpdates u = cellUpdates(game, rule, r, i, layersExclusive);
            for (const ObjectUpdate& o : u.objects) {
                if (o.kind == ObjectUpdate::kAssign && o.keepOrValue) set(o.layerOrObject);
                if (o.kind == ObjectUpdate::kPutLayer && o.keepOrValue >= 0) set(o.keepOrValue);
            }
            for (const MovementUpdate& m : u.movements) {
                for (int k = 0; k < 5; ++k) {
                    if ((m.set >> k) & 1u) set(objects + 5 * m.layer + k);
                }
            }
        }
    }
    return bits;
}

std::vector<DirectionSet> directionSets(const ir::Game& game, const ir::RuleGroup& group, bool layersExclusive) {
    std::vector<DirectionSet> sets;
    if (group.random) return sets;
    const auto& rules = group.rules;
    size_t i = 0;
    while (i < rules.size()) {
        if (!qualifies(rules[i])) {
            ++i;
            continue;
        }
        DirectionSet set;
        set.first = i;
        set.count = 1;
        set.cellOf.push_back(correspondence(game, rules[i], rules[i], layersExclusive));
        while (i + set.count < rules.size()) {
            const ir::Rule& copy = rules[i + set.count];
            if (!qualifies(copy) || !sameShape(rules[i], copy)) break;
            auto cellOf = correspondence(game, rules[i], copy, layersExclusive);
            if (cellOf.empty()) break;
            set.cellOf.push_back(std::move(cellOf));
            ++set.count;
        }
        if (set.count >= 2) sets.push_back(std::move(set));
        i += set.count;
    }
    return sets;
}

}  // namespace psc::codegen
