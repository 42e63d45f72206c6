#include <catch2/catch.hpp>

#include "TestGames.h"
#include "ir/IrDump.h"

using namespace psc;
using psc::test::GameParts;

namespace {

ir::Game compileOk(const GameParts& p) {
    CompileResult r = test::compileParts(p);
    INFO(test::gameText(p));
    for (const auto& d : r.diagnostics.all()) INFO(d.message);
    REQUIRE(r.status == CompileStatus::Ok);
    return *r.game;
}

std::vector<std::string> ruleTexts(const ir::Game& g, const std::vector<ir::RuleGroup>& groups) {
    std::vector<std::string> out;
    for (const auto& group : groups) {
        for (const auto& rule : group.rules) out.push_back(ir::ruleText(g, rule));
    }
    return out;
}

int idOf(const ir::Game& g, const std::string& name) {
    for (const auto& o : g.objects) {
        if (o.name == name && !o.ghost) return o.id;
    }
    return -1;
}

}  // namespace

TEST_CASE("object ids follow the collision layers", "[passes]") {
    ir::Game g = compileOk(GameParts{});
    CHECK(idOf(g, "background") == 0);
    CHECK(idOf(g, "target") == 1);
    CHECK(idOf(g, "player") == 2);
    CHECK(idOf(g, "wall") == 3);
    CHECK(idOf(g, "crate") == 4);
    CHECK(g.layerCount == 3);
}

TEST_CASE("an object listed twice leaves a ghost id", "[passes]") {
    GameParts p;
    p.layers = "Background\nCrate\nTarget\nPlayer, Wall, Crate\n";
    CompileResult r = test::compileParts(p);
    REQUIRE(r.game);
    CHECK(r.diagnostics.errorCount() == 0);  // only a warning
    const ir::Game& g = *r.game;
    CHECK(g.objectCount == 6);
    CHECK(g.objects[1].ghost);
    CHECK(g.objects[1].liveId == 5);
    CHECK(idOf(g, "crate") == 5);
    CHECK(g.objects[5].layer == 3);
}

TEST_CASE("a push rule becomes four single-direction rules, up and left flipped", "[passes]") {
    GameParts p;
    p.rules = "[ > Player | Crate ] -> [ > Player | > Crate ]\n";
    ir::Game g = compileOk(p);
    CHECK(ruleTexts(g, g.rules) == std::vector<std::string>{
                                       "down [ crate | up player ] -> [ up crate | up player ]",
                                       "down [ down player | crate ] -> [ down player | down crate ]",
                                       "right [ crate | left player ] -> [ left crate | left player ]",
                                       "right [ right player | crate ] -> [ right player | right crate ]"});
}

TEST_CASE("duplicates of single-cell rules merge across directions, keeping the last copy", "[passes]") {
    GameParts p;
    p.rules = "[ perpendicular Player ] -> [ perpendicular Player ]\n";
    ir::Game g = compileOk(p);
    auto rules = ruleTexts(g, g.rules);
    REQUIRE(rules.size() == 4);
    CHECK(rules[0].rfind("down ", 0) == 0);
    CHECK(rules[1].rfind("down ", 0) == 0);
    CHECK(rules[2].rfind("right ", 0) == 0);
    CHECK(rules[3].rfind("right ", 0) == 0);
}

TEST_CASE("spawned objects become stationary unless the cell mentions their layer", "[passes]") {
    GameParts p;
    p.rules = "[ Target ] -> [ Target Crate ]\n";
    ir::Game g = compileOk(p);
    const auto& rep = *g.rules[0].rules[0].rows[0][0].replacement;
    CHECK(rep.movementsClear.field(2) == 31u);

    GameParts q;
    q.rules = "[ Target no Crate ] -> [ Target Crate ]\n";
    ir::Game h = compileOk(q);
    const auto& rep2 = *h.rules[0].rules[0].rows[0][0].replacement;
    CHECK(rep2.movementsClear.field(2) == 0u);
}

TEST_CASE("multi-layer properties are expanded, single-layer ones stay", "[passes]") {
    GameParts p;
    p.legend += "Solid = Wall or Crate\nAny = Target or Crate\n";
    p.rules = "[ Player | Solid ] -> [ Player | Solid ]\n[ Player | Any ] -> [ Player | Any ]\n";
    ir::Game g = compileOk(p);
    REQUIRE(g.rules.size() == 2);
    // Solid (one layer) stays as an "any of" test: one rule per direction, no split.
    CHECK(g.rules[0].rules.size() == 4);
    CHECK(g.rules[0].rules[0].rows[0][1].anyOf.size() + g.rules[0].rules[0].rows[0][0].anyOf.size() == 1);
    // Any (two layers) is split per member.
    CHECK(g.rules[1].rules.size() == 8);
}

TEST_CASE("groups, random groups, loops and rigid groups", "[passes]") {
    GameParts p;
    p.rules =
        "random [ Player ] -> [ Crate ]\n"
        "+ [ Crate ] -> [ Player ]\n"
        "startloop\n"
        "[ Wall ] -> [ Wall ]\n"
        "rigid [ > Crate ] -> [ > Crate ]\n"
        "endloop\n"
        "late [ Crate Target ] -> [ Target ]\n";
    CompileResult r = test::compileParts(p);
    REQUIRE(r.game);
    const ir::Game& g = *r.game;
    REQUIRE(g.rules.size() == 3);
    CHECK(g.rules[0].random);
    CHECK(g.rules[0].rules.size() == 2);
    CHECK(g.loopPoints == std::map<int, int>{{2, 1}});
    CHECK(g.rigidGroups == std::vector<bool>{false, false, true});
    CHECK(g.rigidGroupIndexToGroupIndex == std::vector<int>{2});
    CHECK(g.lateRules.size() == 1);
}

TEST_CASE("win conditions", "[passes]") {
    GameParts p;
    p.legend += "Both = Crate and Target\n";
    p.winConditions = "All Target on Crate\nAny Crate\nNo Both\nsome Target\n";
    ir::Game g = compileOk(p);
    REQUIRE(g.winConditions.size() == 4);
    CHECK(g.winConditions[0].quantifier == 1);
    CHECK_FALSE(g.winConditions[0].onEverything);
    CHECK(g.winConditions[1].quantifier == 0);
    CHECK(g.winConditions[1].onEverything);
    CHECK(g.winConditions[2].quantifier == -1);
    CHECK(g.winConditions[2].aggregate1);
}

TEST_CASE("levels are column-major object sets with the background filled in", "[passes]") {
    GameParts p;
    p.legend = "- = Background\n. = Target\nP = Player\n# = Wall\n* = Crate\nO = Target\n";
    p.levels = "#P\n.*\n";
    ir::Game g = compileOk(p);
    REQUIRE(g.levels.size() == 1);
    const ir::Level& l = g.levels[0];
    CHECK(l.width == 2);
    CHECK(l.height == 2);
    // cells[x * height + y]; every cell also gets the background.
    CHECK(l.cells[0].test(static_cast<size_t>(idOf(g, "wall"))));
    CHECK(l.cells[1].test(static_cast<size_t>(idOf(g, "target"))));
    CHECK(l.cells[2].test(static_cast<size_t>(idOf(g, "player"))));
    for (const auto& cell : l.cells) CHECK(cell.test(static_cast<size_t>(idOf(g, "background"))));
}

TEST_CASE("a short level row repeats its last glyph", "[passes]") {
    GameParts p;
    p.levels = "####\n#P\n####\n";
    CompileResult r = test::compileParts(p);
    REQUIRE(r.game);
    const ir::Level& l = r.game->levels[0];
    CHECK(l.cells[static_cast<size_t>(3 * l.height + 1)].test(static_cast<size_t>(idOf(*r.game, "player"))));
}

TEST_CASE("errors the reference reports", "[passes]") {
    GameParts noPlayer;
    noPlayer.objects = "Background\nblack\n\nWall\ngray\n\nCrate\norange\n\nTarget\nyellow\n";
    noPlayer.legend = ". = Background\n# = Wall\n* = Crate\nO = Target\n";
    noPlayer.layers = "Background\nTarget\nWall, Crate\n";
    noPlayer.levels = "#*O\n";
    CHECK(test::compileParts(noPlayer).status == CompileStatus::Playable);

    GameParts unknownName;
    unknownName.rules = "[ Ghost ] -> [ ]\n";
    CHECK(test::compileParts(unknownName).diagnostics.errorCount() > 0);

    GameParts noLayers;
    noLayers.layers = "";
    CHECK(test::compileParts(noLayers).status == CompileStatus::Invalid);

    GameParts noLevels;
    noLevels.levels = "";
    CHECK(test::compileParts(noLevels).diagnostics.errorCount() == 1);

    GameParts ambiguous;
    ambiguous.rules = "[ Player ] -> [ moving Player ]\n";
    CHECK(test::compileParts(ambiguous).status == CompileStatus::Invalid);
}
