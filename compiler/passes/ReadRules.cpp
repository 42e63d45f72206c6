#include "passes/ReadRules.h"

#include "parse/RuleReader.h"

namespace psc::passes {

void readRules(CompileState& st) {
    parse::RuleReaderContext context{st.ast.ruleNames, [&](const std::string& n) { return st.isProperty(n); },
                                     st.ast.sounds};
    for (const ast::RuleLineSource& line : st.ast.rules) {
        auto rule = parse::readRuleLine(line, st.ruleLines, context, st.diag, &st.invalid);
        if (!rule) continue;
        switch (rule->kind) {
            case ast::RuleSyntax::Kind::StartLoop: st.loops.emplace_back(line.line, 1); break;
            case ast::RuleSyntax::Kind::EndLoop: st.loops.emplace_back(line.line, -1); break;
            case ast::RuleSyntax::Kind::Rule: st.ruleLines.push_back(std::move(*rule)); break;
        }
    }
}

}  // namespace psc::passes
