#include "RuleParts.h"

#include <fmt/format.h>

#include <algorithm>

namespace psc::codegen {

bool layersHoldOneObject(const ir::Game& g) {
    bool one = true;
    forEachReplacingCell(g, [&](const ir::CellPattern& cell) {
        for (const BitSet& layer : g.layerMasks) {
            BitSet here = cell.replacement->set;
            here &= layer;
            if (here.count() > 1) one = false;
        }
    });
    return one;
}

CellFacts cellFacts(const ir::Game& g, const ir::CellPattern& cell) {
    CellFacts f;
    f.possible = BitSet(static_cast<size_t>(g.objectCount));
    for (int id = 0; id < g.objectCount; ++id) f.possible.set(static_cast<size_t>(id));
    f.possible.clear(cell.missing);
    f.present = cell.present;
    auto confineLayer = [&](const BitSet& within) {
        for (const BitSet& layer : g.layerMasks) {
            if (!within.subsetOf(layer) || within.none()) continue;
            BitSet others = layer;
            others.clear(within);
            f.possible.clear(others);
        }
    };
    cell.present.forEach([&](size_t id) {
        BitSet one(static_cast<size_t>(g.objectCount));
        one.set(id);
        confineLayer(one);
    });
    for (const BitSet& any : cell.anyOf) confineLayer(any);
    f.movementsPresent = cell.movementsPresent;
    f.movementsMissing = cell.movementsMissing;
    // A layer moves one way at a time: seeding puts one direction on a
    // still layer, and a replacement clears the layer's five bits before it
    // sets one.  A required direction rules out the other four.
    for (int L = 0; L < g.layerCount; ++L) {
        const uint32_t required = cell.movementsPresent.field(L);
        if (required != 0u) f.movementsMissing.orField(L, 31u & ~required);
    }
    return f;
}

bool cellsExclude(const ir::Game& g, const ir::CellPattern& a, const ir::CellPattern& b) {
    const CellFacts fa = cellFacts(g, a);
    const CellFacts fb = cellFacts(g, b);
    auto requiresRuledOut = [](const CellFacts& x, const CellFacts& y) {
        BitSet ruledOut = x.present;
        ruledOut.clear(y.possible);
        return ruledOut.any() || x.movementsPresent.intersects(y.movementsMissing);
    };
    return requiresRuledOut(fa, fb) || requiresRuledOut(fb, fa);
}

bool cellFactsHold(const ir::Game& g, const ir::Rule& rule, size_t row, const ir::CellPattern& cell) {
    BitSet objectsRead = cell.missing;
    auto addLayersOf = [&](const BitSet& objects) {
        for (const BitSet& layer : g.layerMasks) {
            if (layer.intersects(objects)) objectsRead |= layer;
        }
    };
    addLayersOf(cell.present);
    for (const BitSet& any : cell.anyOf) addLayersOf(any);
    BitSet movementsRead = cell.movementsPresent;
    movementsRead |= cell.movementsMissing;
    for (size_t r = 0; r < row && r < rule.rows.size(); ++r) {
        for (const ir::CellPattern& earlier : rule.rows[r]) {
            if (!earlier.replacement || cellsExclude(g, earlier, cell)) continue;
            const ir::Replacement& w = *earlier.replacement;
            if (w.randomEntity.any() || w.randomDirMask.any()) return false;
            const ReplacementEffect effect = effectOf(w);
            if (effect.objectsSet.intersects(objectsRead) || effect.objectsCleared.intersects(objectsRead) ||
                effect.movementsSet.intersects(movementsRead) || effect.movementsCleared.intersects(movementsRead)) {
                return false;
            }
        }
    }
    return true;
}

std::optional<CellFacts> knownFacts(const ir::Game& g, const ir::Rule& rule, size_t row, const ir::CellPattern& cell,
                                    bool layersExclusive) {
    if (!layersExclusive || !cellFactsHold(g, rule, row, cell)) return std::nullopt;
    return cellFacts(g, cell);
}

ReplacementEffect effectOf(const ir::Replacement& r, const CellFacts* facts) {
    ReplacementEffect e{r.set, r.clear, r.movementsSet, r.movementsClear};
    if (facts) {
        e.objectsSet.clear(facts->present);
        e.objectsCleared &= facts->possible;
    }
    e.objectsCleared.clear(r.set);
    e.movementsCleared |= r.movementsLayerMask;
    e.movementsCleared.clear(r.movementsSet);
    return e;
}

bool stillMatchesAfter(const ir::CellPattern& c, const ReplacementEffect& effect) {
    if (effect.objectsSet.intersects(c.missing) || effect.objectsCleared.intersects(c.present) ||
        effect.movementsSet.intersects(c.movementsMissing) || effect.movementsCleared.intersects(c.movementsPresent)) {
        return false;
    }
    for (const BitSet& any : c.anyOf) {
        if (effect.objectsCleared.intersects(any) && !effect.objectsSet.intersects(any)) return false;
    }
    return true;
}

std::vector<ObjectUpdate> objectUpdates(const ir::Game& g, const BitSet& set, const BitSet& clearAsked,
                                        const CellFacts* facts) {
    std::vector<ObjectUpdate> out;
    BitSet handled(static_cast<size_t>(g.objectCount));
    BitSet clear = clearAsked;
    BitSet setNew = set;
    if (facts) {
        clear &= facts->possible;
        setNew.clear(facts->present);
    }
    for (size_t L = 0; L < g.layerMasks.size(); ++L) {
        const BitSet& layer = g.layerMasks[L];
        if (layer.none() || !layer.subsetOf(clear)) continue;
        BitSet setHere = set;
        setHere &= layer;
        if (setHere.count() > 1) continue;
        BitSet leaving = clear;
        leaving &= layer;
        leaving.clear(set);
        if (leaving.none() && !setNew.intersects(layer)) {
            // The layer already holds what the replacement puts there.
            handled |= layer;
            continue;
        }
        const std::vector<int> kept = setHere.bits();
        out.push_back({ObjectUpdate::kPutLayer, static_cast<int>(L), kept.empty() ? -1 : kept[0]});
        handled |= layer;
    }
    clear.forEach([&](size_t id) {
        if (!set.test(id) && !handled.test(id)) out.push_back({ObjectUpdate::kAssign, static_cast<int>(id), 0});
    });
    setNew.forEach([&](size_t id) {
        if (!handled.test(id)) out.push_back({ObjectUpdate::kAssign, static_cast<int>(id), 1});
    });
    return out;
}

std::vector<MovementUpdate> movementUpdates(const ir::Game& g, const ir::Replacement& r, std::optional<int> entityLayer,
                                            const CellFacts* facts) {
    std::vector<MovementUpdate> out;
    for (int L = 0; L < g.layerCount; ++L) {
        const bool randomDir = r.randomDirMask.test(static_cast<size_t>(5 * L));
        uint32_t set = r.movementsSet.field(L);
        uint32_t clear = r.movementsClear.field(L) | r.movementsLayerMask.field(L) | (entityLayer == L ? 31u : 0u);
        clear &= ~set;
        if (facts && !randomDir) {
            set &= ~facts->movementsPresent.field(L);
            clear &= ~facts->movementsMissing.field(L);
        }
        if (randomDir || set || clear) out.push_back({L, clear, set, randomDir});
    }
    return out;
}

BitSet inputMovedObjects(const ir::Game& g) {
    BitSet moved = g.playerMask;
    g.playerMask.forEach([&](size_t id) {
        if (const auto& live = g.objects[id].liveId) moved.set(static_cast<size_t>(*live));
    });
    return moved;
}

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

uint64_t movingLayerBits(const ir::Game& g) {
    uint64_t bits = 0;
    auto add = [&](int layer) {
        if (layer >= 0 && layer < 64) bits |= 1ull << layer;
    };
    g.playerMask.forEach([&](size_t id) { add(layerOfObject(g, static_cast<int>(id))); });
    forEachReplacingCell(g, [&](const ir::CellPattern& cell) {
        const ir::Replacement& r = *cell.replacement;
        for (int L = 0; L < g.layerCount; ++L) {
            if (r.movementsSet.field(L) || r.randomDirMask.test(static_cast<size_t>(5 * L))) add(L);
        }
    });
    if (g.layerCount > 64) bits = ~0ull;
    return bits;
}

bool soundReadsCanReload(const ir::Game& g) {
    const uint64_t moving = movingLayerBits(g);
    int movingLayers = 0;
    size_t reads = 0;
    for (size_t L = 0; L < static_cast<size_t>(g.layerCount); ++L) {
        if (!layerCanMove(moving, L)) continue;
        ++movingLayers;
        if (L < g.sounds.move.size()) reads += g.sounds.move[L].size();
    }
    return movingLayers >= 2 && reads >= 3;
}

int rigidGroupClaim(const ir::Game& g, const ir::Rule& rule) {
    if (!rule.rigid) return 0;
    auto it = g.groupNumberToRigidGroupIndex.find(rule.groupNumber);
    return it == g.groupNumberToRigidGroupIndex.end() ? 0 : it->second + 1;
}

RigidClaim rigidClaim(const ir::Game& g, const ir::Rule& rule, const ir::Replacement& r) {
    RigidClaim out;
    const int claim = rigidGroupClaim(g, rule);
    if (claim == 0) return out;
    for (int L = 0; L < g.layerCount; ++L) {
        if (r.movementsLayerMask.field(L)) out.layers.push_back(L);
    }
    if (!out.layers.empty()) out.claim = claim;
    return out;
}

int layerOfObject(const ir::Game& g, int id) {
    if (id < 0 || id >= g.objectCount) return -1;
    const ir::Object& o = g.objects[static_cast<size_t>(id)];
    if (o.layer) return *o.layer;
    if (o.liveId) return g.objects[static_cast<size_t>(*o.liveId)].layer.value_or(-1);
    return -1;
}

uint32_t commandBits(const ir::Rule& rule) {
    uint32_t bits = 0;
    for (const auto& c : rule.commands) {
        if (c.name == "cancel") bits |= 1u << 0;
        else if (c.name == "again") bits |= 1u << 1;
        else if (c.name == "win") bits |= 1u << 2;
        else if (c.name == "restart") bits |= 1u << 3;
        else if (c.name == "checkpoint") bits |= 1u << 4;
        else if (c.name == "message") bits |= 1u << 5;
        else if (c.name.rfind("sfx", 0) == 0) bits |= 1u << (6 + std::stoi(c.name.substr(3)));
    }
    return bits;
}

bool hasEllipsis(const ir::Rule& rule) {
    for (const auto& row : rule.rows) {
        for (const auto& c : row) {
            if (c.ellipsis) return true;
        }
    }
    return false;
}

const std::string* messageOf(const ir::Rule& rule) {
    for (const auto& c : rule.commands) {
        if (c.name == "message") return &c.message;
    }
    return nullptr;
}

int messageIndex(const ir::Rule& rule, const std::vector<std::string>& messages) {
    const std::string* message = messageOf(rule);
    if (!message) return -1;
    const auto at = std::find(messages.begin(), messages.end(), *message);
    return at == messages.end() ? -1 : static_cast<int>(at - messages.begin());
}

std::string groupName(const ir::RuleGroup& group, size_t index, bool late) {
    return fmt::format("{}group_{}_L{}", late ? "late_" : "", index, group.groupNumber);
}

int presenceWords(const ir::Game& game) {
    return (std::max(1, game.objectCount) + 5 * std::max(1, game.layerCount) + 63) / 64;
}

std::vector<uint64_t> neededPresence(const ir::Game& game, const ir::Rule& rule, int words) {
    const int objects = std::max(1, game.objectCount);
    std::vector<uint64_t> mask(static_cast<size_t>(words), 0);
    auto need = [&](int bit) { mask[static_cast<size_t>(bit / 64)] |= uint64_t{1} << (bit % 64); };
    for (const auto& row : rule.rows) {
        for (const auto& c : row) {
            if (c.ellipsis) continue;
            c.present.forEach([&](size_t id) { need(static_cast<int>(id)); });
            c.movementsPresent.forEach([&](size_t bit) { need(objects + static_cast<int>(bit)); });
        }
    }
    return mask;
}

std::vector<uint64_t> groupNeededPresence(const ir::Game& game, const ir::RuleGroup& group, int words) {
    std::vector<uint64_t> common(static_cast<size_t>(words), group.rules.empty() ? 0 : ~uint64_t{0});
    for (const auto& rule : group.rules) {
        const std::vector<uint64_t> needs = neededPresence(game, rule, words);
        for (size_t w = 0; w < needs.size(); ++w) common[w] &= needs[w];
    }
    return common;
}

}  // namespace psc::codegen
