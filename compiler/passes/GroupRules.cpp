#include "passes/GroupRules.h"

#include <map>

namespace psc::passes {
namespace {

// Drops rules that need two objects on one layer; an error if a source line loses all its rules.
void dropImpossibleRules(CompileState& st, std::vector<EncodedRule>& group) {
    std::vector<std::pair<std::string, std::string>> discards;
    for (size_t i = 0; i < group.size(); ++i) {
        if (!group[i].source.discard) continue;
        const int line = group[i].source.line;
        bool sameBefore = i > 0 && group[i - 1].source.line == line;
        bool sameAfter = i + 1 < group.size() && group[i + 1].source.line == line;
        auto discard = *group[i].source.discard;
        group.erase(group.begin() + static_cast<long>(i));
        if (std::find(discards.begin(), discards.end(), discard) == discards.end()) discards.push_back(discard);
        if (!(sameBefore || sameAfter) || group.empty()) {
            std::string others;
            for (size_t j = 1; j < discards.size() && j <= 3; ++j) {
                others += (j > 1 ? ", " : "") + discards[j].first + "/" + discards[j].second;
            }
            if (discards.size() > 4) others += " etc.";
            st.diag.error(line, discards[0].first + " and " + discards[0].second +
                                    " can never share a cell" + (others.empty() ? "" : " (nor " + others + ")") +
                                    ", so this rule can never apply");
        }
        --i;
    }
}

ir::Rule finishRule(CompileState& st, EncodedRule& encoded) {
    const WorkRule& w = encoded.source;
    ir::Rule rule;
    rule.line = w.line;
    rule.groupNumber = w.groupNumber;
    rule.late = w.late;
    rule.rigid = w.rigid;
    rule.random = w.random;
    rule.hasReplacements = !w.rhs.empty();
    rule.direction = w.direction == "up" ? ir::kUp : w.direction == "down" ? ir::kDown
                   : w.direction == "left" ? ir::kLeft : w.direction == "right" ? ir::kRight
                   : w.direction == "action" ? ir::kAction : 0;
    for (const auto& c : w.commands) rule.commands.push_back({c.name, c.message});
    for (auto& row : encoded.rows) {
        int ellipses = 0;
        for (size_t k = 0; k < row.size(); ++k) {
            if (!row[k].ellipsis) continue;
            ++ellipses;
            if (ellipses > 2) {
                st.diag.error(w.line, "a cell row can have at most two ellipses");
            } else if (k > 0 && row[k - 1].ellipsis) {
                st.diag.warning(w.line, "two ellipses in a row are the same as one");
            }
        }
        rule.ellipsisCount.push_back(ellipses);
        rule.rows.push_back(std::move(row));
    }
    return rule;
}

std::vector<ir::RuleGroup> collect(CompileState& st, std::map<int, std::vector<EncodedRule>>& byNumber) {
    std::vector<ir::RuleGroup> groups;
    for (auto& [number, rules] : byNumber) {
        dropImpossibleRules(st, rules);
        if (rules.empty()) continue;
        ir::RuleGroup group;
        group.groupNumber = rules.front().source.groupNumber;
        group.random = rules.front().source.random;
        for (auto& r : rules) group.rules.push_back(finishRule(st, r));
        groups.push_back(std::move(group));
    }
    return groups;
}

void assignRigidGroups(CompileState& st) {
    ir::Game& g = st.ir;
    for (size_t i = 0; i < g.rules.size(); ++i) {
        bool rigid = false;
        for (const auto& r : g.rules[i].rules) rigid = rigid || r.rigid;
        g.rigidGroups.push_back(rigid);
        if (!rigid) continue;
        int rigidIndex = static_cast<int>(g.rigidGroupIndexToGroupIndex.size());
        g.groupIndexToRigidGroupIndex[static_cast<int>(i)] = rigidIndex;
        g.groupNumberToRigidGroupIndex[g.rules[i].rules.front().groupNumber] = rigidIndex;
        g.rigidGroupIndexToGroupIndex.push_back(static_cast<int>(i));
    }
    if (g.rigidGroupIndexToGroupIndex.size() > 30) {
        const ir::RuleGroup& group = g.rules[static_cast<size_t>(g.rigidGroupIndexToGroupIndex[30])];
        st.diag.error(group.rules.front().line, "there can be at most 30 rule groups with rigid rules");
    }
    g.hasRigid = !g.groupIndexToRigidGroupIndex.empty();
}

}  // namespace

void groupRules(CompileState& st) {
    std::map<int, std::vector<EncodedRule>> normal;
    std::map<int, std::vector<EncodedRule>> late;
    for (auto& r : st.encoded) (r.source.late ? late : normal)[r.source.groupNumber].push_back(std::move(r));
    st.encoded.clear();
    st.ir.rules = collect(st, normal);
    st.ir.lateRules = collect(st, late);
    assignRigidGroups(st);
}

}  // namespace psc::passes
