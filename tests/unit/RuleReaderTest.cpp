#include <catch2/catch.hpp>

#include "parse/RuleReader.h"

using namespace psc;

namespace {

struct Reader {
    std::set<std::string> names{"player", "crate", "wall"};
    std::vector<ast::SoundDecl> sounds;
    std::vector<ast::RuleSyntax> previous;
    Diagnostics diagnostics;
    bool invalid = false;

    std::optional<ast::RuleSyntax> read(const std::u16string& text, int line = 10) {
        parse::RuleReaderContext context{names, [](const std::string&) { return false; }, sounds};
        auto r = parse::readRuleLine(ast::RuleLineSource{text, text, line}, previous, context, diagnostics, &invalid);
        if (r && r->kind == ast::RuleSyntax::Kind::Rule) previous.push_back(*r);
        return r;
    }
};

}  // namespace

TEST_CASE("rule lines are split like the reference splits them", "[rules]") {
    CHECK(parse::ruleTokens(u"+late[>player|crate]->[>player|>crate]again") ==
          std::vector<std::string>{"+", "late", "[", ">player", "|", "crate", "]", "->", "[", ">player", "|", ">crate",
                                   "]", "again"});
    CHECK(parse::ruleTokens(u"[ a+b ]") == std::vector<std::string>{"[", "a+b", "]"});
}

TEST_CASE("a rule's cells, directions and commands", "[rules]") {
    Reader r;
    auto rule = r.read(u"[ > player | crate ] -> [ > player | > crate ] sfx1 again");
    REQUIRE(rule);
    CHECK(rule->directions == std::vector<std::string>{"up", "down", "left", "right"});
    REQUIRE(rule->lhs.size() == 1);
    REQUIRE(rule->lhs[0].size() == 2);
    CHECK(rule->lhs[0][0] == ast::RuleCell{{">", "player"}});
    CHECK(rule->rhs[0][1] == ast::RuleCell{{">", "crate"}});
    REQUIRE(rule->commands.size() == 2);
    CHECK(rule->commands[1].name == "again");
    CHECK(r.diagnostics.errorCount() == 0);  // sfx1 undefined is only a warning
}

TEST_CASE("a rule that is not directional keeps one direction", "[rules]") {
    Reader r;
    CHECK(r.read(u"[ player ] -> [ crate ]")->directions == std::vector<std::string>{"up"});
    CHECK(r.read(u"horizontal [ player ] -> [ crate ]")->directions == std::vector<std::string>{"left"});
    CHECK(r.read(u"horizontal [ > player ] -> [ crate ]")->directions == std::vector<std::string>{"left", "right"});
}

TEST_CASE("'+' joins the previous rule's group", "[rules]") {
    Reader r;
    r.read(u"[ player ] -> [ crate ]", 5);
    auto joined = r.read(u"+ [ crate ] -> [ wall ]", 6);
    REQUIRE(joined);
    CHECK(joined->groupNumber == 5);
}

TEST_CASE("message text keeps its case and parentheses", "[rules]") {
    Reader r;
    std::u16string line = u"[ player ] -> [ player ] message Hello (there)";
    auto rule = r.read(line);
    REQUIRE(rule);
    REQUIRE(rule->commands.size() == 1);
    CHECK(rule->commands[0].message == "Hello (there)");
}

TEST_CASE("malformed rules: errors, warnings and dropped rules", "[rules]") {
    Reader r;
    CHECK(r.read(u"late [ > player ] -> [ player ]"));
    CHECK(r.diagnostics.errorCount() == 1);  // movements in late rules

    Reader w;
    CHECK_FALSE(w.read(u"[ player ] [ crate ] -> [ player ]"));  // row counts differ: rule dropped
    CHECK(w.diagnostics.errorCount() == 0);

    Reader x;
    x.read(u"[ player | crate ] -> [ player ]");
    CHECK(x.invalid);  // rows of unequal length make the game invalid

    Reader y;
    auto loop = y.read(u"startloop");
    REQUIRE(loop);
    CHECK(loop->kind == ast::RuleSyntax::Kind::StartLoop);
}
