#include <catch2/catch.hpp>

#include "DormantGroups.h"
#include "TestGames.h"

using namespace psc;
using psc::test::GameParts;

namespace {

// Walls that tile: WallSolo becomes WallH between two walls.
GameParts tiling(const std::string& moreRules) {
    GameParts p;
    p.objects = "Background\nblack\n\nPlayer\nblue\n\nWallSolo\ngray\n\nWallH\ndarkgray\n\nCrate\norange\n\nTarget\nyellow\n";
    p.legend = ". = Background\nP = Player\n# = WallSolo\n* = Crate\nO = Target\nWall = WallSolo or WallH\n";
    p.layers = "Background\nTarget\nPlayer, WallSolo, WallH, Crate\n";
    p.rules = "Horizontal [ Wall | WallSolo | Wall ] -> [ Wall | WallH | Wall ]\n" + moreRules;
    return p;
}

codegen::DormantGroups dormantOf(const GameParts& p) {
    CompileResult r = test::compileParts(p);
    INFO(test::gameText(p));
    REQUIRE(r.status == CompileStatus::Ok);
    return codegen::dormantGroups(*r.game);
}

}  // namespace

TEST_CASE("tiling rules go dormant; rules that read movement do not", "[codegen]") {
    const auto d = dormantOf(tiling("[ > Player | Crate ] -> [ > Player | > Crate ]\n"));
    CHECK(d.early == std::vector<bool>{true, false});
    CHECK(d.any());
}

TEST_CASE("a group that another rule can feed stays awake", "[codegen]") {
    // The late rule puts a WallSolo where a crate was: the tiling rule could match again.
    const auto d = dormantOf(tiling("[ > Player | Crate ] -> [ > Player | > Crate ]\nlate [ Crate Target ] -> [ WallSolo Target ]\n"));
    CHECK(d.early == std::vector<bool>{false, false});
    CHECK(d.late == std::vector<bool>{false});
}

TEST_CASE("a group that requires an object movement can bring stays awake", "[codegen]") {
    // The player moves into new cells: a player beside a WallSolo can appear.
    CHECK_FALSE(dormantOf(tiling("late right [ Player | WallSolo ] -> [ Player | WallH ]\n")).late.front());
    // Nothing moves a target.
    CHECK(dormantOf(tiling("late right [ Target | WallSolo ] -> [ Target | WallH ]\n")).late.front());
}

TEST_CASE("a group whose `no` object another rule or movement removes stays awake", "[codegen]") {
    // The player moves, so a cell with no player can appear anywhere.
    CHECK_FALSE(dormantOf(tiling("late [ WallSolo | no Player ] -> [ WallH | ]\n")).late.front());
    // Nothing adds or removes a crate: a cell without one stays without.
    CHECK(dormantOf(tiling("late [ WallSolo | no Crate ] -> [ WallH | ]\n")).late.front());
}

TEST_CASE("a group with a command, or one that can match without a change, stays awake", "[codegen]") {
    const auto withMessage = dormantOf(tiling("late [ Crate Target ] -> [ Crate ] message done\n"));
    CHECK(withMessage.early == std::vector<bool>{true});
    CHECK(withMessage.late == std::vector<bool>{false});
    // WallSolo may hold a target already: a match need not change the level.
    CHECK(dormantOf(tiling("late [ WallSolo ] -> [ WallSolo Target ]\n")).late == std::vector<bool>{false});
}

TEST_CASE("a game without such groups has none", "[codegen]") {
    GameParts p;
    p.rules = "[ > Player | Crate ] -> [ > Player | > Crate ]\n";
    CHECK_FALSE(dormantOf(p).any());
}
