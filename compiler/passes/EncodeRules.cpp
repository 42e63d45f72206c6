#include "passes/EncodeRules.h"

namespace psc::passes {
namespace {

using js::toUpperAscii;

constexpr uint32_t kWholeField = 0x1f;

bool isEllipsisCell(const ast::RuleCell& cell) { return !cell.empty() && cell[0].modifier == "..."; }

std::string joinOverlap(const CompileState& st, const BitSet& a, const BitSet& b) {
    std::string out;
    for (int id = 0; id < st.ir.objectCount; ++id) {
        if (a.test(static_cast<size_t>(id)) && b.test(static_cast<size_t>(id))) {
            const std::string n = toUpperAscii(st.idNames[static_cast<size_t>(id)]);
            out += (out.empty() ? "" : ", ") + n + " NO " + n;
        }
    }
    return out;
}

class RuleEncoder {
public:
    RuleEncoder(CompileState& st, WorkRule& rule) : st_(st), rule_(rule) {}

    // Returns false when the rule is dropped.
    bool encode(std::vector<std::vector<ir::CellPattern>>* rows);

private:
    enum class CellResult { Ok, Ellipsis, DropRule };
    CellResult encodeLeft(size_t row, size_t col, ir::CellPattern* pattern, std::vector<std::string>* layersUsed);
    void encodeRight(size_t row, size_t col, ir::CellPattern* pattern, const std::vector<std::string>& layersUsedLeft);

    std::optional<int> layerIndex(const std::string& name) const {
        if (const ObjectInfo* o = st_.object(name)) return o->layer.value_or(0);
        if (const std::optional<int>* l = st_.singleLayerProperties.find(name)) return *l;
        return std::nullopt;
    }
    BitSet objectMask(const std::string& name) const {
        const BitSet* m = st_.objectMasks.find(name);
        return m ? *m : BitSet(st_.objectBits);
    }
    void error(const std::string& m) { st_.diag.error(rule_.line, m); }
    void warning(const std::string& m) { st_.diag.warning(rule_.line, m); }

    CompileState& st_;
    WorkRule& rule_;
    BitSet objectLayersLeft_;
};

bool RuleEncoder::encode(std::vector<std::vector<ir::CellPattern>>* rows) {
    for (size_t r = 0; r < rule_.lhs.size(); ++r) {
        std::vector<ir::CellPattern> row;
        for (size_t c = 0; c < rule_.lhs[r].size(); ++c) {
            ir::CellPattern pattern;
            std::vector<std::string> layersUsed(static_cast<size_t>(st_.layerCount()));
            CellResult result = encodeLeft(r, c, &pattern, &layersUsed);
            if (result == CellResult::DropRule) return false;
            if (result == CellResult::Ok && !rule_.rhs.empty()) encodeRight(r, c, &pattern, layersUsed);
            row.push_back(std::move(pattern));
        }
        rows->push_back(std::move(row));
    }
    return !rule_.ellipsisAtEdge;
}

RuleEncoder::CellResult RuleEncoder::encodeLeft(size_t r, size_t c, ir::CellPattern* p,
                                                std::vector<std::string>* layersUsed) {
    const ast::RuleCell& cell = rule_.lhs[r][c];
    const size_t movementBits = static_cast<size_t>(5 * st_.layerCount());
    p->present = BitSet(st_.objectBits);
    p->missing = BitSet(st_.objectBits);
    p->movementsPresent = BitSet(movementBits);
    p->movementsMissing = BitSet(movementBits);
    objectLayersLeft_ = BitSet(movementBits);
    for (const auto& item : cell) {
        if (item.modifier == "...") {
            if (cell.size() != 1) {
                error("an ellipsis must be alone in its cell");
                return CellResult::DropRule;
            }
            if (c == 0 || c + 1 == rule_.lhs[r].size()) {
                error("an ellipsis at the start or end of a cell row is pointless");
                rule_.ellipsisAtEdge = true;
            }
            if (!rule_.rhs.empty()) {
                const ast::RuleCell& right = rule_.rhs[r][c];
                if (right.size() != 1 || right[0].modifier != "...") {
                    error("an ellipsis on the left needs one in the same place on the right");
                }
            }
            p->ellipsis = true;
            return CellResult::Ellipsis;
        }
        if (item.modifier == "random") {
            error("RANDOM can only appear on the right-hand side");
            continue;
        }
        std::optional<int> layer = layerIndex(item.name);
        if (!layer) {
            error(toUpperAscii(item.name) + " is in no collision layer");
            continue;
        }
        if (item.modifier == "no") {
            p->missing |= objectMask(item.name);
            continue;
        }
        std::string& used = (*layersUsed)[static_cast<size_t>(*layer)];
        if (!used.empty()) rule_.discard = std::make_pair(toUpperAscii(item.name), toUpperAscii(used));
        used = item.name;
        if (st_.object(item.name)) {
            p->present |= objectMask(item.name);
            objectLayersLeft_.orField(*layer, kWholeField);
        } else {
            p->anyOf.push_back(objectMask(item.name));
        }
        if (item.modifier == "stationary") p->movementsMissing.orField(*layer, kWholeField);
        else p->movementsPresent.orField(*layer, static_cast<uint32_t>(directionMask(item.modifier)));
    }
    if (p->present.any() && p->present.intersects(p->missing)) {
        warning("this rule asks for " + joinOverlap(st_, p->present, p->missing) +
                " in one cell, which can never match; the rule is removed");
        return CellResult::DropRule;
    }
    return CellResult::Ok;
}

void RuleEncoder::encodeRight(size_t r, size_t c, ir::CellPattern* p, const std::vector<std::string>& layersUsedLeft) {
    const ast::RuleCell& left = rule_.lhs[r][c];
    const ast::RuleCell& cell = rule_.rhs[r][c];
    if (isEllipsisCell(cell) && !isEllipsisCell(left)) {
        error("an ellipsis on the right needs one in the same place on the left");
    }
    for (const auto& item : cell) {
        if (item.modifier == "..." && cell.size() != 1) error("an ellipsis must be alone in its cell");
    }
    const size_t movementBits = static_cast<size_t>(5 * st_.layerCount());
    const size_t layers = static_cast<size_t>(st_.layerCount());
    std::vector<std::string> layersUsed(layers);
    std::vector<std::string> layersUsedRandom(layers);
    ir::Replacement rep{BitSet(st_.objectBits), BitSet(st_.objectBits), BitSet(movementBits), BitSet(movementBits),
                        BitSet(movementBits),   BitSet(st_.objectBits), BitSet(movementBits)};
    BitSet objectLayersRight(movementBits);

    for (const auto& item : cell) {
        if (item.modifier == "...") break;
        if (item.modifier == "random") {
            if (const BitSet* mask = st_.objectMasks.find(item.name)) {
                rep.randomEntity |= *mask;
                std::vector<std::string> values = {item.name};
                if (const Members* members = st_.properties.find(item.name)) values = **members;
                if (values.size() == 1) {
                    warning("RANDOM " + toUpperAscii(item.name) + " is a single object; random is meant for "
                            "properties (names defined with OR)");
                }
                for (const std::string& sub : values) {
                    const ObjectInfo* o = st_.object(sub);
                    if (!o || !o->layer) continue;
                    const std::string& existing = layersUsed[static_cast<size_t>(*o->layer)];
                    if (!existing.empty() && toUpperAscii(sub) != toUpperAscii(existing)) {
                        warning("this rule may spawn a random " + toUpperAscii(sub) + " where it also requires " +
                                toUpperAscii(existing) + " on the same layer");
                    }
                    layersUsedRandom[static_cast<size_t>(*o->layer)] = sub;
                }
            } else {
                error("cannot spawn a random " + toUpperAscii(item.name));
            }
            continue;
        }
        std::optional<int> layer = layerIndex(item.name);
        if (!layer) {
            error(toUpperAscii(item.name) + " is in no collision layer");
            continue;
        }
        const size_t L = static_cast<size_t>(*layer);
        if (item.modifier == "no") {
            rep.clear |= objectMask(item.name);
            continue;
        }
        const std::string& existing = !layersUsed[L].empty() ? layersUsed[L] : layersUsedRandom[L];
        if (!existing.empty() && !rule_.discard) {
            error("the rule puts " + toUpperAscii(item.name) + " and " + toUpperAscii(existing) +
                  " in one cell, but they share a collision layer");
        }
        layersUsed[L] = item.name;
        if (!item.modifier.empty()) rep.movementsLayerMask.orField(*layer, kWholeField);
        if (const ObjectInfo* o = st_.object(item.name)) {
            if (st_.objectBits) rep.set.set(static_cast<size_t>(o->id.value_or(0)));
            if (L < st_.layerMasks.size()) rep.clear |= st_.layerMasks[L];
            objectLayersRight.orField(*layer, kWholeField);
        }
        if (item.modifier == "stationary") rep.movementsClear.orField(*layer, kWholeField);
        else if (item.modifier == "randomdir") rep.randomDirMask.orField(*layer, static_cast<uint32_t>(directionMask("randomdir")));
        else rep.movementsSet.orField(*layer, static_cast<uint32_t>(directionMask(item.modifier)));
    }

    if (!p->present.subsetOf(rep.set)) rep.clear |= p->present;
    if (!p->movementsPresent.subsetOf(rep.movementsSet)) rep.movementsClear |= p->movementsPresent;
    for (size_t L = 0; L < layers; ++L) {
        if (!layersUsedLeft[L].empty() && layersUsed[L].empty()) {
            rep.clear |= st_.layerMasks[L];
            rep.movementsLayerMask.orField(static_cast<int>(L), kWholeField);
        }
    }
    BitSet vacated = objectLayersLeft_;
    vacated.clear(objectLayersRight);
    rep.movementsLayerMask |= vacated;

    bool changes = rep.clear.any() || rep.set.any() || rep.movementsClear.any() || rep.movementsSet.any() ||
                   rep.movementsLayerMask.any() || rep.randomEntity.any() || rep.randomDirMask.any();
    if (changes) p->replacement = std::move(rep);
}

}  // namespace

int directionMask(const std::string& word) {
    if (word == "up") return 1;
    if (word == "down") return 2;
    if (word == "left") return 4;
    if (word == "right") return 8;
    if (word == "moving") return 15;
    if (word == "no") return 3;
    if (word == "randomdir") return 5;
    if (word == "random") return 18;
    if (word == "action") return 16;
    return 0;
}

void encodeRules(CompileState& st) {
    for (WorkRule& rule : st.rules) {
        EncodedRule encoded;
        RuleEncoder encoder(st, rule);
        if (!encoder.encode(&encoded.rows)) continue;
        encoded.source = std::move(rule);
        st.encoded.push_back(std::move(encoded));
    }
    st.rules.clear();
}

}  // namespace psc::passes
