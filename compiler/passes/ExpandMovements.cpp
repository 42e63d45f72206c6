#include "passes/ExpandMovements.h"

#include "passes/RuleSplitting.h"

namespace psc::passes {
namespace {

std::vector<std::string> concreteDirections(const std::string& word) {
    if (word == "horizontal" || word == "horizontal_par" || word == "horizontal_perp") return {"left", "right"};
    if (word == "vertical" || word == "vertical_par" || word == "vertical_perp") return {"up", "down"};
    if (word == "moving") return {"up", "down", "left", "right", "action"};
    if (word == "orthogonal") return {"up", "down", "left", "right"};
    if (word == "perpendicular") return {"^", "v"};
    if (word == "parallel") return {"<", ">"};
    return {};
}

bool isAmbiguous(const std::string& modifier) { return !concreteDirections(modifier).empty(); }

// The first (name, word) pair of a cell with an ambiguous movement word.
const ast::RuleCellItem* firstAmbiguous(const ast::RuleCell& cell) {
    for (const auto& item : cell) {
        if (isAmbiguous(item.modifier)) return &item;
    }
    return nullptr;
}

void concretize(ast::RuleCell& cell, const std::string& word, const std::string* name, const std::string& direction) {
    for (auto& item : cell) {
        if (item.modifier == word && (!name || item.name == *name)) item.modifier = direction;
    }
}

// What one expanded copy remembers about the choices made for it.
struct MovingChoice {
    std::string direction;
    int count = 1;
    std::string word;
    std::string name;
    size_t row = 0;
    size_t column = 0;
};
struct WordChoice {
    std::string direction;
    int count = 1;
    std::string word;
};
struct Expansion {
    WorkRule rule;
    bool expanded = false;  // has the choice tables (the reference's movingReplacement)
    JsObject<MovingChoice> byName;
    JsObject<WordChoice> byWord;
};

// `before`: the rules split so far.  Nothing when the rules pass kMaxExpandedRules.
std::optional<std::vector<WorkRule>> expandRule(CompileState& st, WorkRule rule, size_t before) {
    const int line = rule.line;
    Expansion first;
    first.rule = std::move(rule);
    std::optional<std::vector<Expansion>> split =
        splitRule(st, std::move(first), before, "movements", [](const Expansion& current, std::deque<Expansion>& queue) {
            bool splits = false;
            for (size_t j = 0; j < current.rule.lhs.size(); ++j) {
                for (size_t k = 0; k < current.rule.lhs[j].size(); ++k) {
                    const ast::RuleCellItem* ambiguous = firstAmbiguous(current.rule.lhs[j][k]);
                    if (!ambiguous) continue;
                    splits = true;
                    const std::string name = ambiguous->name;
                    const std::string word = ambiguous->modifier;
                    for (const std::string& direction : concreteDirections(word)) {
                        Expansion next = current;
                        next.expanded = true;
                        concretize(next.rule.lhs[j][k], word, &name, direction);
                        if (!next.rule.rhs.empty()) concretize(next.rule.rhs[j][k], word, &name, direction);
                        const std::string key = name + word;
                        if (MovingChoice* choice = next.byName.find(key)) {
                            if (j != choice->row || k != choice->column) ++choice->count;
                        } else {
                            next.byName.set(key, MovingChoice{direction, 1, word, name, j, k});
                        }
                        if (WordChoice* choice = next.byWord.find(word)) ++choice->count;
                        else next.byWord.set(word, WordChoice{direction, 1, word});
                        queue.push_back(std::move(next));
                    }
                }
            }
            return splits;
        });
    if (!split) return std::nullopt;
    std::vector<Expansion>& result = *split;

    for (Expansion& e : result) {
        if (!e.expanded) continue;
        for (const std::string& key : e.byName.keys()) {
            const MovingChoice& c = e.byName.at(key);
            if (c.count != 1) continue;
            for (auto& row : e.rule.rhs) {
                for (auto& cell : row) concretize(cell, c.word, &c.name, c.direction);
            }
        }
        JsObject<std::string> byWord;  // word -> direction, or "INVALID"
        for (const std::string& key : e.byWord.keys()) {
            const WordChoice& c = e.byWord.at(key);
            byWord.set(c.word, (byWord.has(c.word) || c.count != 1) ? "INVALID" : c.direction);
        }
        for (const std::string& word : byWord.keys()) {
            const std::string& direction = byWord.at(word);
            if (direction == "INVALID") continue;
            for (auto& row : e.rule.rhs) {
                for (auto& cell : row) concretize(cell, word, nullptr, direction);
            }
        }
    }

    std::vector<WorkRule> out;
    std::string remaining;
    for (Expansion& e : result) {
        if (remaining.empty()) {
            for (const auto& row : e.rule.rhs) {
                for (const auto& cell : row) {
                    if (const ast::RuleCellItem* a = firstAmbiguous(cell); a && remaining.empty()) remaining = a->modifier;
                }
            }
        }
        out.push_back(std::move(e.rule));
    }
    if (!remaining.empty()) {
        st.diag.error(line,
                      "the right-hand movement \"" + remaining + "\" cannot be inferred from the left-hand side (an "
                      "ambiguous movement on the right needs the same word on the same object on the left, or a "
                      "single use of that word on the left)");
        st.invalid = true;
    }
    return out;
}

}  // namespace

void expandMovements(CompileState& st) {
    std::vector<WorkRule> expanded;
    for (WorkRule& rule : st.rules) {
        std::optional<std::vector<WorkRule>> copies = expandRule(st, std::move(rule), expanded.size());
        if (!copies) break;
        for (auto& c : *copies) expanded.push_back(std::move(c));
    }
    st.rules = std::move(expanded);
}

}  // namespace psc::passes
