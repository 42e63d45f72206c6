#include "passes/SimplifyNoClauses.h"

#include <map>

namespace psc::passes {
namespace {

using js::toUpperAscii;

bool isNo(const ast::RuleCellItem& item) { return item.modifier.rfind("no", 0) == 0; }

std::string joinUpper(const std::vector<std::string>& names) {
    std::string out;
    for (size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + toUpperAscii(names[i]);
    return out;
}

void checkRightHandContradictions(CompileState& st, const ast::RuleSyntax& rule) {
    for (const auto& row : rule.rhs) {
        for (const auto& cell : row) {
            std::vector<std::string> present;
            BitSet presentMask(st.objectBits);
            for (const auto& item : cell) {
                if (isNo(item)) continue;
                if (const ObjectInfo* o = st.object(item.name)) {
                    present.push_back(item.name);
                    if (st.objectBits) presentMask.set(static_cast<size_t>(o->id.value_or(0)));
                }
            }
            for (const auto& item : cell) {
                if (!isNo(item)) continue;
                const BitSet* noMask = st.objectMasks.find(item.name);
                if (noMask && noMask->intersects(presentMask)) {
                    st.diag.error(rule.line, "a cell asks for NO " + toUpperAscii(item.name) + " and also for " +
                                                 joinUpper(present));
                }
            }
        }
    }
}

void dropRepeatedRightHandNo(ast::RuleSyntax& rule) {
    for (size_t j = 0; j < rule.rhs.size(); ++j) {
        for (size_t k = 0; k < rule.rhs[j].size(); ++k) {
            ast::RuleCell& cell = rule.rhs[j][k];
            if (j >= rule.lhs.size() || k >= rule.lhs[j].size()) continue;
            const ast::RuleCell& lhsCell = rule.lhs[j][k];
            // After a removal the reference's index steps over the next item.
            for (size_t l = 0; l < cell.size(); ++l) {
                if (!isNo(cell[l])) continue;
                for (const auto& left : lhsCell) {
                    if (isNo(left) && left.name == cell[l].name) {
                        cell.erase(cell.begin() + static_cast<long>(l));
                        break;
                    }
                }
            }
        }
    }
}

void dropRedundantLeftHandNo(CompileState& st, ast::RuleSyntax& rule) {
    const size_t layerBits = static_cast<size_t>(std::max(1, st.layerCount()));
    for (auto& row : rule.lhs) {
        for (auto& cell : row) {
            BitSet requiredLayers(layerBits);
            BitSet requiredObjects(st.objectBits);
            std::map<int, std::string> occupier;
            auto require = [&](std::optional<int> layer, std::optional<int> id, const std::string& by) {
                requiredLayers.set(static_cast<size_t>(layer.value_or(0)));
                if (st.objectBits) requiredObjects.set(static_cast<size_t>(id.value_or(0)));
                occupier[layer.value_or(0)] = by;
            };
            for (const auto& item : cell) {
                if (item.modifier == "no") continue;
                if (const std::optional<int>* layer = st.singleLayerProperties.find(item.name)) {
                    requiredLayers.set(static_cast<size_t>(layer->value_or(0)));
                    for (const auto& m : *st.properties.at(item.name)) {
                        if (const ObjectInfo* o = st.object(m); o && st.objectBits) {
                            requiredObjects.set(static_cast<size_t>(o->id.value_or(0)));
                        }
                    }
                    occupier[layer->value_or(0)] = item.name;
                } else if (const ObjectInfo* o = st.object(item.name)) {
                    require(o->layer, o->id, item.name);
                } else if (const Members* parts = st.aggregates.find(item.name)) {
                    for (const auto& part : **parts) {
                        if (const ObjectInfo* po = st.object(part)) require(po->layer, po->id, item.name);
                    }
                }
            }
            for (size_t l = 0; l < cell.size(); ++l) {
                if (!isNo(cell[l])) continue;
                const BitSet* noMask = st.objectMasks.find(cell[l].name);
                if (!noMask) continue;
                BitSet noLayers(layerBits);
                for (size_t m = 0; m < st.layerMasks.size(); ++m) {
                    if (st.layerMasks[m].intersects(*noMask)) noLayers.set(m);
                }
                if (noLayers.subsetOf(requiredLayers) && !noMask->intersects(requiredObjects)) {
                    std::vector<std::string> names;
                    std::string layers;
                    for (const auto& [layer, name] : occupier) {
                        if (layer < static_cast<int>(st.layerMasks.size())) {
                            names.push_back(name);
                            layers += (layers.empty() ? "" : ", ") + std::to_string(layer + 1);
                        }
                    }
                    st.diag.warning(rule.line, "NO " + toUpperAscii(cell[l].name) + " is redundant: " + joinUpper(names) +
                                                   " already fill its layers (" + layers + ")");
                    cell.erase(cell.begin() + static_cast<long>(l));
                    --l;
                }
            }
        }
    }
}

}  // namespace

void simplifyNoClauses(CompileState& st) {
    for (ast::RuleSyntax& rule : st.ruleLines) {
        checkRightHandContradictions(st, rule);
        dropRepeatedRightHandNo(rule);
        dropRedundantLeftHandNo(st, rule);
    }
}

}  // namespace psc::passes
