#include "passes/LoopPoints.h"

namespace psc::passes {
namespace {

std::map<int, int> loopPointsOf(CompileState& st, const std::vector<ir::RuleGroup>& groups) {
    std::map<int, int> points;
    for (size_t j = 0; j + 1 < st.loops.size(); j += 2) {
        const int start = st.loops[j].first;
        const int end = st.loops[j + 1].first;
        int first = -1;
        for (size_t g = 0; g < groups.size(); ++g) {
            const int firstLine = groups[g].rules.front().line;
            const int lastLine = groups[g].rules.back().line;
            if ((firstLine <= start && start <= lastLine) || (firstLine <= end && end <= lastLine)) {
                st.diag.error(start, "a loop marker falls inside a rule group");
            }
            if (end < firstLine) break;
            if (start <= firstLine && firstLine <= end) {
                if (first == -1) first = static_cast<int>(g);
                auto previous = points.find(static_cast<int>(g) - 1);
                if (g > 0 && previous != points.end() && previous->second == first) points.erase(previous);
                points[static_cast<int>(g)] = first;
            }
        }
    }
    return points;
}

}  // namespace

void findLoopPoints(CompileState& st) {
    for (size_t i = 0; i < st.loops.size(); ++i) {
        const auto& [line, kind] = st.loops[i];
        if (i % 2 == 0 && kind == -1) st.diag.error(line, "ENDLOOP without a STARTLOOP");
        if (i % 2 == 1 && kind == 1) st.diag.error(line, "STARTLOOP inside a loop (loops cannot nest)");
    }
    if (st.loops.size() % 2 != 0) {
        st.diag.error(st.loops.back().first, "STARTLOOP without an ENDLOOP");
        st.loops.emplace_back(st.loops.back().first, -1);
    }
    st.ir.loopPoints = loopPointsOf(st, st.ir.rules);
    st.ir.lateLoopPoints = loopPointsOf(st, st.ir.lateRules);
}

}  // namespace psc::passes
