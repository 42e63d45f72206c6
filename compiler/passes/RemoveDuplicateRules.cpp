#include "passes/RemoveDuplicateRules.h"

#include <unordered_set>

namespace psc::passes {
namespace {

void appendRows(std::string& key, const std::vector<ast::RuleRow>& rows) {
    for (const auto& row : rows) {
        key += "[ ";
        for (size_t i = 0; i < row.size(); ++i) {
            if (i > 0) key += "| ";
            for (const auto& item : row[i]) {
                if (item.modifier == "...") key += "... ";
                else key += item.modifier + " " + item.name + " ";
            }
        }
        key += "] ";
    }
}

std::string ruleKey(const WorkRule& rule) {
    std::string key = "(" + std::to_string(rule.line) + ") ";
    bool directed = false;
    for (const auto& row : rule.lhs) directed = directed || row.size() > 1;
    if (directed) key += rule.direction + " ";
    if (rule.rigid) key = "RIGID " + key + " ";
    if (rule.random) key = "RANDOM " + key + " ";
    if (rule.late) key = "LATE " + key + " ";
    appendRows(key, rule.lhs);
    key += "-> ";
    appendRows(key, rule.rhs);
    for (const auto& c : rule.commands) key += c.name == "message" ? "(message, " + c.message + ") " : c.name;
    return key;
}

}  // namespace

void removeDuplicateRules(CompileState& st) {
    std::vector<bool> keep(st.rules.size(), false);
    std::unordered_set<std::string> seen;
    int lastGroup = -1;
    for (size_t n = st.rules.size(); n-- > 0;) {
        WorkRule& rule = st.rules[n];
        rule.key = ruleKey(rule);
        if (rule.groupNumber != lastGroup) seen.clear();
        if (seen.insert(rule.key).second) keep[n] = true;
        lastGroup = rule.groupNumber;
    }
    std::vector<WorkRule> kept;
    for (size_t i = 0; i < st.rules.size(); ++i) {
        if (keep[i]) kept.push_back(std::move(st.rules[i]));
    }
    st.rules = std::move(kept);
}

}  // namespace psc::passes
