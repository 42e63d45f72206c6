// RuleSplitting: the work list ExpandMovements and ExpandProperties split a
// rule with, and the bound on the rules it may make.
//
// The reference rescans a list until no rule in it splits, replacing a split
// rule by its copies appended at the end.  That is a queue whose unsplit
// rules keep the order they leave it in; a queue is also linear where the
// rescans and removals were quadratic in the copies.
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "passes/CompileState.h"

namespace psc::passes {

// Splitting rules' property and `moving` cells multiplies them: a row of
// twelve cells of a ten-member property is 10^12 rules, which the reference
// would grind on for ever.  The corpus' largest game has 38,313 rules after
// splitting; a game near this bound takes the front end 2 s (20 s under
// ASan, within the fuzzers' 30 s).
inline constexpr size_t kMaxExpandedRules = size_t{1} << 16;

// `split(rule, queue)` appends the rule's copies to the queue and says whether
// it split it.  `before`: the rules this pass made from earlier rules.
// Nothing, and an error, when the rules pass kMaxExpandedRules.
template <typename Expansion, typename Split>
std::optional<std::vector<Expansion>> splitRule(CompileState& st, Expansion first, size_t before, const char* what,
                                                Split split) {
    const int line = first.rule.line;
    std::vector<Expansion> done;
    std::deque<Expansion> queue;
    queue.push_back(std::move(first));
    while (!queue.empty()) {
        Expansion current = std::move(queue.front());
        queue.pop_front();
        if (!split(current, queue)) {
            done.push_back(std::move(current));
        } else if (before + done.size() + queue.size() > kMaxExpandedRules) {
            st.diag.error(line, std::string("splitting the rules' ") + what + " makes more than " +
                                    std::to_string(kMaxExpandedRules) + " rules, which psc does not support");
            st.invalid = true;
            return std::nullopt;
        }
    }
    return done;
}

}  // namespace psc::passes
