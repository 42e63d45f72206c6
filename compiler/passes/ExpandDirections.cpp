#include "passes/ExpandDirections.h"

#include <algorithm>
#include <array>

namespace psc::passes {
namespace {

using js::toUpperAscii;

// Relative words, and what each means for a rule scanning right, up, down, left.
constexpr std::array<const char*, 6> kRelative = {"^", "v", "<", ">", "parallel", "perpendicular"};

const std::array<const char*, 6>* absoluteFor(const std::string& direction) {
    static const std::array<const char*, 6> right = {"up", "down", "left", "right", "horizontal_par", "vertical_perp"};
    static const std::array<const char*, 6> up = {"left", "right", "down", "up", "vertical_par", "horizontal_perp"};
    static const std::array<const char*, 6> down = {"right", "left", "up", "down", "vertical_par", "horizontal_perp"};
    static const std::array<const char*, 6> left = {"down", "up", "right", "left", "horizontal_par", "vertical_perp"};
    if (direction == "right") return &right;
    if (direction == "up") return &up;
    if (direction == "down") return &down;
    if (direction == "left") return &left;
    return nullptr;
}

void makeAbsolute(WorkRule& rule) {
    const auto* table = absoluteFor(rule.direction);
    for (auto* side : {&rule.lhs, &rule.rhs}) {
        for (auto& row : *side) {
            for (auto& cell : row) {
                for (auto& item : cell) {
                    auto it = std::find(kRelative.begin(), kRelative.end(), item.modifier);
                    if (it == kRelative.end()) continue;
                    if (!table) throw CompileAborted("a relative direction in a rule that applies to 'action'");
                    item.modifier = (*table)[static_cast<size_t>(it - kRelative.begin())];
                }
            }
        }
    }
}

bool hasEllipsis(const WorkRule& rule) {
    for (const auto& row : rule.lhs) {
        for (const auto& cell : row) {
            if (!cell.empty() && cell[0].name == "...") return true;
        }
    }
    return false;
}

void flipUpAndLeft(WorkRule& rule) {
    if (hasEllipsis(rule)) return;
    if (rule.direction == "up") rule.direction = "down";
    else if (rule.direction == "left") rule.direction = "right";
    else return;
    for (size_t i = 0; i < rule.lhs.size(); ++i) {
        std::reverse(rule.lhs[i].begin(), rule.lhs[i].end());
        if (i < rule.rhs.size()) std::reverse(rule.rhs[i].begin(), rule.rhs[i].end());
    }
}

void spellOutAggregates(CompileState& st, WorkRule& rule) {
    for (auto* side : {&rule.lhs, &rule.rhs}) {
        for (auto& row : *side) {
            for (auto& cell : row) {
                for (size_t i = 0; i < cell.size(); ++i) {
                    const Members* parts = st.aggregates.find(cell[i].name);
                    if (!parts) continue;
                    if (cell[i].modifier == "no") {
                        st.diag.error(rule.line, "NO cannot exclude the aggregate " + toUpperAscii(cell[i].name) +
                                                     " (defined with AND); only objects and properties");
                    }
                    const std::vector<std::string> equivalents = **parts;
                    const std::string modifier = cell[i].modifier;
                    cell[i].name = equivalents.empty() ? std::string() : equivalents[0];
                    for (size_t j = 1; j < equivalents.size(); ++j) cell.push_back({modifier, equivalents[j]});
                }
            }
        }
    }
}

void spellOutSynonyms(CompileState& st, WorkRule& rule) {
    auto rename = [&](ast::RuleCell& cell) {
        for (auto& item : cell) {
            if (const std::string* target = st.synonyms.find(item.name)) item.name = *target;
        }
    };
    for (size_t i = 0; i < rule.lhs.size(); ++i) {
        for (size_t j = 0; j < rule.lhs[i].size(); ++j) {
            rename(rule.lhs[i][j]);
            if (i < rule.rhs.size() && j < rule.rhs[i].size()) rename(rule.rhs[i][j]);
        }
    }
}

}  // namespace

void expandDirections(CompileState& st) {
    for (const ast::RuleSyntax& r : st.ruleLines) {
        for (const std::string& direction : r.directions) {
            WorkRule w;
            w.direction = direction;
            w.lhs = r.lhs;
            w.rhs = r.rhs;
            w.line = r.line;
            w.groupNumber = r.groupNumber;
            w.late = r.late;
            w.rigid = r.rigid;
            w.random = r.random;
            w.commands = r.commands;
            st.rules.push_back(std::move(w));
        }
    }
    for (WorkRule& rule : st.rules) {
        makeAbsolute(rule);
        flipUpAndLeft(rule);
        spellOutAggregates(st, rule);
        if (st.invalid) return;
        spellOutSynonyms(st, rule);
    }
}

}  // namespace psc::passes
