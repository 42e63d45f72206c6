#include <catch2/catch.hpp>

#include "RuleParts.h"
#include "TestGames.h"

using namespace psc;
using psc::test::GameParts;

namespace {

uint64_t movingLayersOf(const GameParts& p) {
    CompileResult r = test::compileParts(p);
    INFO(test::gameText(p));
    REQUIRE(r.status == CompileStatus::Ok);
    return codegen::movingLayerBits(*r.game);
}

// Crate and Target each on their own layer: 0 Background, 1 Target, 2 Player and Wall, 3 Crate.
GameParts ownLayers(const std::string& rules) {
    GameParts p;
    p.layers = "Background\nTarget\nPlayer, Wall\nCrate\n";
    p.rules = rules;
    return p;
}

}  // namespace

TEST_CASE("without rules only the player's layer moves", "[codegen]") {
    CHECK(movingLayersOf(ownLayers("")) == 0b0100);
}

TEST_CASE("a layer moves when a replacement gives one of its objects a movement", "[codegen]") {
    CHECK(movingLayersOf(ownLayers("[ > Player | Crate ] -> [ > Player | > Crate ]\n")) == 0b1100);
    CHECK(movingLayersOf(ownLayers("[ Crate ] -> [ up Crate ]\n")) == 0b1100);
    CHECK(movingLayersOf(ownLayers("late [ Target ] -> [ randomdir Target ]\n")) == 0b0110);
}

TEST_CASE("matching, stopping or keeping a movement moves no new layer", "[codegen]") {
    // The crate's layer is tested for a movement and its movement cleared: nothing sets one.
    CHECK(movingLayersOf(ownLayers("[ > Crate ] -> [ Crate ]\n[ stationary Crate | Target ] -> [ Crate | Target ]\n")) == 0b0100);
}

TEST_CASE("a player on several layers moves all of them", "[codegen]") {
    GameParts p;
    p.objects = "Background\nblack\n\nHero\nblue\n\nWall\ngray\n\nCrate\norange\n\nTarget\nyellow\n";
    p.legend = ". = Background\nP = Hero\n# = Wall\n* = Crate\nO = Target\nPlayer = Hero or Crate\n";
    p.layers = "Background\nTarget\nHero, Wall\nCrate\n";
    CHECK(movingLayersOf(p) == 0b1100);
}
