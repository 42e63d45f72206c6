#include <catch2/catch.hpp>

#include "DirectionVariants.h"
#include "RuleParts.h"
#include "TestGames.h"

using namespace psc;
using psc::test::GameParts;

namespace {

// The direction sets of the first rule group of a game whose crates have their own layer.
struct Sets {
    CompileResult result;
    std::vector<codegen::DirectionSet> sets;
};

Sets setsOf(const std::string& rules) {
    GameParts p;
    p.layers = "Background\nTarget\nPlayer, Wall\nCrate\n";
    p.rules = rules;
    Sets s{test::compileParts(p), {}};
    INFO(test::gameText(p));
    REQUIRE(s.result.status == CompileStatus::Ok);
    const ir::Game& game = *s.result.game;
    s.sets = codegen::directionSets(game, game.rules.at(0), codegen::layersHoldOneObject(game));
    return s;
}

}  // namespace

TEST_CASE("a moving rule's four direction copies form one set, up and left with their cells reversed", "[codegen]") {
    // Copies in the reference's order: up and left flipped to down and right
    // (cells [ No Crate | up Player ]), down and right as written.
    const Sets s = setsOf("[ > Player | No Crate ] -> [ Crate | Player ]\n");
    REQUIRE(s.sets.size() == 1);
    const codegen::DirectionSet& set = s.sets[0];
    CHECK(set.first == 0);
    CHECK(set.count == 4);
    using Rows = std::vector<std::vector<size_t>>;
    CHECK(set.cellOf == std::vector<Rows>{Rows{{0, 1}}, Rows{{1, 0}}, Rows{{0, 1}}, Rows{{1, 0}}});
    // Corresponding cells write alike: the player's cell of each copy clears the player.
    const ir::Game& game = *s.result.game;
    const bool exclusive = codegen::layersHoldOneObject(game);
    for (size_t v = 0; v < set.count; ++v) {
        const auto a = codegen::cellUpdates(game, game.rules[0].rules[0], 0, 1, exclusive);
        const auto b = codegen::cellUpdates(game, game.rules[0].rules[v], 0, set.cellOf[v][0][1], exclusive);
        CHECK(a.objects.size() == b.objects.size());
        CHECK(a.movements.size() == b.movements.size());
    }
}

TEST_CASE("copies that test no movement, or one direction alone, form no set", "[codegen]") {
    CHECK(setsOf("[ Crate | Target ] -> [ Target | Crate ]\n").sets.empty());
    CHECK(setsOf("right [ > Player | Crate ] -> [ > Player | > Crate ]\n").sets.empty());
}

TEST_CASE("copies with an ellipsis or a random draw form no set", "[codegen]") {
    CHECK(setsOf("[ > Player | ... | Crate ] -> [ > Player | ... | > Crate ]\n").sets.empty());
    CHECK(setsOf("[ > Player | Crate ] -> [ > Player | randomdir Crate ]\n").sets.empty());
}

TEST_CASE("the copies of two rules form two sets", "[codegen]") {
    const Sets s = setsOf("[ > Player | No Crate ] -> [ Crate | Player ]\n+ [ > Player | Crate ] -> [ | Player ]\n");
    REQUIRE(s.sets.size() == 2);
    CHECK(s.sets[0].first == 0);
    CHECK(s.sets[0].count == 4);
    CHECK(s.sets[1].first == 4);
    CHECK(s.sets[1].count == 4);
}

TEST_CASE("a rule's set presence names the objects and movements its replacements put", "[codegen]") {
    // Five objects; the crate's layer is 3, so its movement boards' presence
    // bits are 5 + 15 + k.
    const Sets moves = setsOf("[ > Player | No Crate ] -> [ Crate | Player ]\n");
    const ir::Game& game = *moves.result.game;
    auto bitOf = [&](const std::string& name) { return uint64_t{1} << test::objectId(game, name); };
    const bool exclusive = codegen::layersHoldOneObject(game);
    const int words = codegen::presenceWords(game);
    for (const ir::Rule& copy : game.rules[0].rules) {
        CHECK(codegen::setPresence(game, copy, words, exclusive)[0] == (bitOf("player") | bitOf("crate")));
    }
    // Up (flipped to down, its first copy) pushes the crate up: movement bit 0.
    const Sets pushes = setsOf("[ > Player | Crate ] -> [ > Player | > Crate ]\n");
    const ir::Game& pushGame = *pushes.result.game;
    CHECK(codegen::setPresence(pushGame, pushGame.rules[0].rules[0], codegen::presenceWords(pushGame),
                               codegen::layersHoldOneObject(pushGame))[0] == (uint64_t{1} << 20));
}
