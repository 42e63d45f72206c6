#include "passes/WinConditions.h"

namespace psc::passes {
namespace {

struct NameMask {
    BitSet mask;
    bool aggregate = false;
    bool everything = false;
};

std::optional<NameMask> lookup(CompileState& st, const std::string& name, int line) {
    if (const BitSet* m = st.objectMasks.find(name)) return NameMask{*m, false, false};
    if (const BitSet* m = st.aggregateMasks.find(name)) return NameMask{*m, true, false};
    st.diag.error(line, "unexpected \"" + name + "\" in a win condition");
    return std::nullopt;
}

}  // namespace

void buildWinConditions(CompileState& st) {
    for (const ast::WinConditionSource& src : st.ast.winConditions) {
        // The stored words end with the line number in the reference, so its
        // length tests count one more than the words.
        const std::vector<std::string>& w = src.words;
        const size_t length = w.size() + 1;
        const std::string q = w.empty() ? "" : w[0];
        int quantifier = q == "no" ? -1 : q == "all" ? 1 : 0;
        if (length <= 2) {
            st.diag.error(src.line, "malformed win condition; write it like \"No Fruit\", \"All Target on Crate\" or "
                                    "\"Some Gold on Chest\"");
            continue;
        }
        std::optional<NameMask> first = lookup(st, w[1], src.line);
        std::optional<NameMask> second;
        if (length == 5) second = lookup(st, w[3], src.line);
        else second = NameMask{BitSet(st.objectBits), false, true};
        if (!first || !second) continue;
        ir::WinCondition c;
        c.quantifier = quantifier;
        c.objects = first->mask;
        c.aggregate1 = first->aggregate;
        c.on = second->mask;
        c.onEverything = second->everything;
        c.aggregate2 = second->aggregate;
        c.line = src.line;
        st.ir.winConditions.push_back(std::move(c));
    }
}

}  // namespace psc::passes
