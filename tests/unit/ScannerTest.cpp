#include <catch2/catch.hpp>

#include "TestGames.h"
#include "parse/Scanner.h"

using namespace psc;
using psc::test::GameParts;

namespace {

ast::Game scan(const std::string& text, Diagnostics& d) { return parse::scanGame(text, d); }

int levelCount(const ast::Game& g) {
    int n = 0;
    for (const auto& l : g.levels) n += (!l.isMessage && !l.rows.empty()) ? 1 : 0;
    return n;
}

}  // namespace

TEST_CASE("comments nest and span lines", "[scanner]") {
    GameParts p;
    p.prelude = "title Test (a (nested) comment\nstill inside) \n";
    Diagnostics d;
    ast::Game g = scan(test::gameText(p), d);
    CHECK(d.errorCount() == 0);
    REQUIRE(g.metadata.size() == 1);
    CHECK(g.metadata[0].value == "Test");
}

TEST_CASE("a comment-only line splits a level only with trailing whitespace", "[scanner]") {
    GameParts p;
    Diagnostics d1;
    p.levels = "#####\n(note)\n#P*O#\n";
    CHECK(levelCount(scan(test::gameText(p), d1)) == 1);
    Diagnostics d2;
    p.levels = "#####\n(note) \n#P*O#\n";
    CHECK(levelCount(scan(test::gameText(p), d2)) == 2);
}

TEST_CASE("objects take aliases from their name line and sprites of 5x5", "[scanner]") {
    GameParts p;
    p.objects = "Background\nblack\n\nPlayer P @\nblue white\n.000.\n.111.\n00000\n.000.\n.0.0.\n\nWall\ngray\n\nCrate\norange\n\nTarget\nyellow\n";
    p.legend = ". = Background\n# = Wall\n* = Crate\nO = Target\n";
    Diagnostics d;
    ast::Game g = scan(test::gameText(p), d);
    CHECK(d.errorCount() == 0);
    const ast::ObjectDecl* player = g.findObject("player");
    REQUIRE(player);
    CHECK(player->colors == std::vector<std::string>{"blue", "white"});
    CHECK(player->spriteRows.size() == 5);
    int aliases = 0;
    for (const auto& s : g.synonyms) aliases += (s.members[0] == "player") ? 1 : 0;
    CHECK(aliases == 2);
}

TEST_CASE("legend lines are synonyms, aggregates or properties", "[scanner]") {
    GameParts p;
    p.legend += "Block = Wall or Crate\nPair = Crate and Target\nThing = Block\n";
    Diagnostics d;
    ast::Game g = scan(test::gameText(p), d);
    CHECK(d.errorCount() == 0);
    REQUIRE(g.properties.size() == 1);
    CHECK(g.properties[0].members == std::vector<std::string>{"wall", "crate"});
    REQUIRE(g.aggregates.size() == 1);
    CHECK(g.aggregates[0].members == std::vector<std::string>{"crate", "target"});
}

TEST_CASE("legend mistakes are errors", "[scanner]") {
    Diagnostics d;
    GameParts p;
    p.legend += "Mixed = Wall or Crate and Target\n";
    scan(test::gameText(p), d);
    CHECK(d.errorCount() == 1);

    Diagnostics d2;
    GameParts q;
    q.legend += "# = Crate\n";  // redefinition
    scan(test::gameText(q), d2);
    CHECK(d2.errorCount() == 1);
}

TEST_CASE("message entries and level rows", "[scanner]") {
    GameParts p;
    p.levels = "message Hello (World)\n\n#####\n#P*O#\n#####\nmessage Bye\n";
    Diagnostics d;
    ast::Game g = scan(test::gameText(p), d);
    std::vector<const ast::LevelSource*> entries;
    for (const auto& l : g.levels) {
        if (l.isMessage || !l.rows.empty()) entries.push_back(&l);
    }
    REQUIRE(entries.size() == 3);
    CHECK(entries[0]->isMessage);
    CHECK(entries[0]->message == "Hello (World)");
    CHECK(entries[1]->rows.size() == 3);
    CHECK(entries[2]->message == "Bye");
}

TEST_CASE("section headings must come in order and stand alone", "[scanner]") {
    Diagnostics d;
    scan("OBJECTS foo\n", d);
    CHECK(d.errorCount() == 1);
    Diagnostics d2;
    scan("LEGEND\nOBJECTS\n", d2);
    CHECK(d2.errorCount() >= 1);
}

TEST_CASE("a section word inside a line is swallowed", "[scanner]") {
    GameParts p;
    p.legend += "x = levels\n";
    Diagnostics d;
    scan(test::gameText(p), d);
    CHECK(d.errorCount() == 1);  // "x =" is left with nothing on its right
}

TEST_CASE("parsing gives up after five errors", "[scanner]") {
    Diagnostics d;
    CHECK_THROWS_AS(scan("a\nb\nc\nd\ne\nf\ng\n", d), parse::ParseGaveUp);
    CHECK(d.errorCount() == 6);
}

TEST_CASE("rules are stored as text up to the first comment", "[scanner]") {
    GameParts p;
    p.rules = "[ > Player | Crate ] -> [ > Player | > Crate ] (push)\n";
    Diagnostics d;
    ast::Game g = scan(test::gameText(p), d);
    REQUIRE(g.rules.size() == 1);
    CHECK(g.rules[0].text == u"[ > player | crate ] -> [ > player | > crate ] ");
}

TEST_CASE("an unclosed comment is reported as a warning", "[scanner]") {
    GameParts p;
    p.levels += "\n(never closed\n";
    Diagnostics d;
    scan(test::gameText(p), d);
    CHECK(d.errorCount() == 0);
    REQUIRE_FALSE(d.all().empty());
    CHECK(d.all().back().severity == Severity::Warning);
}
