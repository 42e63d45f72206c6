#include "passes/ExpandProperties.h"

#include <algorithm>
#include <set>

#include "passes/RuleSplitting.h"

namespace psc::passes {
namespace {

using js::toUpperAscii;

ast::RuleCell expandNoProperties(const CompileState& st, const ast::RuleCell& cell) {
    ast::RuleCell out;
    for (const auto& item : cell) {
        const Members* members = item.modifier == "no" ? st.properties.find(item.name) : nullptr;
        if (!members) {
            out.push_back(item);
            continue;
        }
        for (const auto& m : **members) out.push_back({"no", m});
    }
    return out;
}

// Property names in a cell, `random X` excluded.
std::vector<std::string> propertiesIn(const CompileState& st, const ast::RuleCell& cell) {
    std::vector<std::string> out;
    for (const auto& item : cell) {
        if (item.modifier != "random" && st.properties.has(item.name)) out.push_back(item.name);
    }
    return out;
}

void concretize(ast::RuleCell& cell, const std::string& property, const std::string& member) {
    for (auto& item : cell) {
        if (item.name == property && item.modifier != "random") item.name = member;
    }
}

struct Choice {
    std::string member;
    int count = 1;
};
struct Expansion {
    WorkRule rule;
    bool expanded = false;
    JsObject<Choice> choices;
};

// `before`: the rules split so far.  Nothing when the rules pass kMaxExpandedRules.
std::optional<std::vector<WorkRule>> expandRule(CompileState& st, WorkRule rule, size_t before) {
    for (size_t i = 0; i < rule.lhs.size(); ++i) {
        for (size_t j = 0; j < rule.lhs[i].size(); ++j) {
            rule.lhs[i][j] = expandNoProperties(st, rule.lhs[i][j]);
            if (!rule.rhs.empty()) rule.rhs[i][j] = expandNoProperties(st, rule.rhs[i][j]);
        }
    }
    std::set<std::string> ambiguous;
    for (size_t j = 0; j < rule.rhs.size(); ++j) {
        for (size_t k = 0; k < rule.rhs[j].size(); ++k) {
            auto left = propertiesIn(st, rule.lhs[j][k]);
            for (const auto& p : propertiesIn(st, rule.rhs[j][k])) {
                if (std::find(left.begin(), left.end(), p) == left.end()) ambiguous.insert(p);
            }
        }
    }
    const int line = rule.line;

    Expansion first;
    first.rule = std::move(rule);
    std::optional<std::vector<Expansion>> split = splitRule(
        st, std::move(first), before, "properties", [&](const Expansion& current, std::deque<Expansion>& queue) {
            for (size_t j = 0; j < current.rule.lhs.size(); ++j) {
                for (size_t k = 0; k < current.rule.lhs[j].size(); ++k) {
                    for (const std::string& property : propertiesIn(st, current.rule.lhs[j][k])) {
                        if (st.singleLayerProperties.has(property) && !ambiguous.count(property)) continue;
                        for (const std::string& member : *st.properties.at(property)) {
                            Expansion next = current;
                            next.expanded = true;
                            concretize(next.rule.lhs[j][k], property, member);
                            if (!next.rule.rhs.empty()) concretize(next.rule.rhs[j][k], property, member);
                            if (Choice* c = next.choices.find(property)) ++c->count;
                            else next.choices.set(property, Choice{member, 1});
                            queue.push_back(std::move(next));
                        }
                        return true;
                    }
                }
            }
            return false;
        });
    if (!split) return std::nullopt;
    std::vector<Expansion>& result = *split;

    for (Expansion& e : result) {
        if (!e.expanded) continue;
        for (const std::string& property : e.choices.keys()) {
            const Choice& c = e.choices.at(property);
            if (c.count != 1) continue;
            for (auto& row : e.rule.rhs) {
                for (auto& cell : row) concretize(cell, property, c.member);
            }
        }
    }

    std::string remaining;
    for (const Expansion& e : result) {
        for (const auto& row : e.rule.rhs) {
            for (const auto& cell : row) {
                for (const auto& p : propertiesIn(st, cell)) {
                    if (ambiguous.count(p)) remaining = p;
                }
            }
        }
    }
    if (!remaining.empty()) {
        st.diag.error(line, "the right-hand property " + toUpperAscii(remaining) +
                                " cannot be inferred from the left-hand side (each property on the right needs the "
                                "same property in the same cell on the left, or a single use of it on the left)");
        return std::vector<WorkRule>{};
    }
    std::vector<WorkRule> out;
    for (Expansion& e : result) out.push_back(std::move(e.rule));
    return out;
}

}  // namespace

void expandProperties(CompileState& st) {
    std::vector<WorkRule> expanded;
    for (WorkRule& rule : st.rules) {
        std::optional<std::vector<WorkRule>> copies = expandRule(st, std::move(rule), expanded.size());
        if (!copies) break;
        for (auto& c : *copies) expanded.push_back(std::move(c));
    }
    st.rules = std::move(expanded);
}

}  // namespace psc::passes
