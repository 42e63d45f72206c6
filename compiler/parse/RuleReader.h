// RuleReader: one stored rule line → ast::RuleSyntax, using the rule grammar.
//
// The grammar splits the line into tokens and separates the prefix from the
// body; the reader then applies the reference's acceptance rules token by
// token: which mistakes are errors, which only warn, and which drop the rule.
// The only ANTLR code in psc lives behind this header.
#pragma once

#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "ast/Ast.h"
#include "base/Diagnostics.h"

namespace psc::parse {

struct RuleReaderContext {
    const std::set<std::string>& names;              // names rules may mention
    std::function<bool(const std::string&)> isProperty;
    const std::vector<ast::SoundDecl>& sounds;        // for undefined sfxN warnings
};

// Reads one rule line.  `previous` holds the rules read so far (a '+' joins
// the last one's group).  Returns nothing when the line yields no rule.
// Sets *invalid when the reference would reject the whole game.
std::optional<ast::RuleSyntax> readRuleLine(const ast::RuleLineSource& source,
                                            const std::vector<ast::RuleSyntax>& previous,
                                            const RuleReaderContext& context, Diagnostics& diagnostics,
                                            bool* invalid);

// The tokens the grammar produces for a rule line (for tests and --emit).
std::vector<std::string> ruleTokens(const std::u16string& text);

}  // namespace psc::parse
