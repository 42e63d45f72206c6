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

namespace {

// The first rule's first cell, and the game it belongs to (kept alive by the result).
struct FirstCell {
    CompileResult result;
    const ir::CellPattern& cell() const { return result.game->rules[0].rules[0].rows[0][0]; }
};

FirstCell firstCellOf(const std::string& rules, CompileStatus expected = CompileStatus::Ok) {
    GameParts p;  // one layer holds Player, Wall and Crate
    p.rules = rules;
    FirstCell f{test::compileParts(p)};
    INFO(test::gameText(p));
    REQUIRE(f.result.status == expected);
    return f;
}

int objectId(const ir::Game& g, const std::string& name) {
    for (const auto& o : g.objects) {
        if (o.name == name && !o.ghost) return o.id;
    }
    FAIL("no object " << name);
    return -1;
}

// The first cell's one movement write without and with what its pattern says.
std::pair<codegen::MovementUpdate, codegen::MovementUpdate> movementWritesOf(const std::string& rules) {
    FirstCell f = firstCellOf(rules);
    const ir::Game& g = *f.result.game;
    const codegen::CellFacts facts = codegen::cellFacts(g, f.cell());
    const auto all = codegen::movementUpdates(g, *f.cell().replacement, std::nullopt);
    const auto needed = codegen::movementUpdates(g, *f.cell().replacement, std::nullopt, &facts);
    REQUIRE(all.size() == 1);
    REQUIRE(needed.size() == 1);
    return {all[0], needed[0]};
}

}  // namespace

TEST_CASE("a replacement leaves out the writes its cell's pattern makes no-ops", "[codegen]") {
    SECTION("a kept object and its layer are not written again; its movement is") {
        FirstCell f = firstCellOf("[ Crate ] -> [ up Crate ]\n");
        const ir::Game& g = *f.result.game;
        const ir::Replacement& r = *f.cell().replacement;
        REQUIRE(codegen::layersHoldOneObject(g));
        const codegen::CellFacts facts = codegen::cellFacts(g, f.cell());
        CHECK(codegen::objectUpdates(g, r.set, r.clear).size() == 1);  // the layer cleared but for the crate
        CHECK(codegen::objectUpdates(g, r.set, r.clear, &facts).empty());
        CHECK(codegen::movementUpdates(g, r, std::nullopt, &facts).size() == 1);
    }
    SECTION("replacing an object clears only that object, not its layer's others") {
        FirstCell f = firstCellOf("[ Crate ] -> [ Wall ]\n");
        const ir::Game& g = *f.result.game;
        const ir::Replacement& r = *f.cell().replacement;
        const codegen::CellFacts facts = codegen::cellFacts(g, f.cell());
        const std::vector<codegen::ObjectUpdate> updates = codegen::objectUpdates(g, r.set, r.clear, &facts);
        REQUIRE(updates.size() == 2);
        CHECK(updates[0].kind == codegen::ObjectUpdate::kAssign);
        CHECK(updates[0].layerOrObject == objectId(g, "crate"));
        CHECK(updates[0].keepOrValue == 0);
        CHECK(updates[1].layerOrObject == objectId(g, "wall"));
        CHECK(updates[1].keepOrValue == 1);
    }
    SECTION("an object ruled out by 'no' is not cleared") {
        FirstCell f = firstCellOf("[ Target no Crate no Wall ] -> [ Target ]\n");
        const ir::Game& g = *f.result.game;
        const ir::Replacement& r = *f.cell().replacement;
        const codegen::CellFacts facts = codegen::cellFacts(g, f.cell());
        for (const auto& u : codegen::objectUpdates(g, r.set, r.clear, &facts)) {
            CHECK(u.layerOrObject != objectId(g, "crate"));
            CHECK(u.layerOrObject != objectId(g, "wall"));
        }
    }
    SECTION("a movement the pattern requires is not set again") {
        const auto [all, needed] = movementWritesOf("[ > Player ] -> [ > Player ]\n");
        CHECK(all.set != 0u);
        CHECK(needed.set == 0u);
        CHECK(needed.clear == all.clear);
    }
    SECTION("movements the pattern rules out are not cleared") {
        const auto [all, needed] = movementWritesOf("[ stationary Player ] -> [ up Player ]\n");
        CHECK(all.clear != 0u);
        CHECK(needed.clear == 0u);
        CHECK(needed.set == all.set);
    }
}

TEST_CASE("a game whose replacement puts two objects on one layer keeps its full writes", "[codegen]") {
    CHECK(codegen::layersHoldOneObject(*firstCellOf("[ Target ] -> [ Target Crate ]\n").result.game));
    CHECK_FALSE(codegen::layersHoldOneObject(
        *firstCellOf("[ Target ] -> [ Target Crate Wall ]\n", CompileStatus::Playable).result.game));
}

TEST_CASE("a later row's cell knows itself unless an earlier row writes what it rests on", "[codegen]") {
    auto secondRowHolds = [](const std::string& rules) {
        CompileResult r = test::compileParts(ownLayers(rules));
        INFO(rules);
        REQUIRE(r.status == CompileStatus::Ok);
        const ir::Rule& rule = r.game->rules[0].rules[0];
        REQUIRE(rule.rows.size() == 2);
        CHECK(codegen::cellFactsHold(*r.game, rule, 0, rule.rows[0][0]));
        return codegen::cellFactsHold(*r.game, rule, 1, rule.rows[1][0]);
    };
    // Row 0 writes the player's layer; row 1 rests on the crate's.
    CHECK(secondRowHolds("[ Player ] [ Crate ] -> [ Player ] [ ]\n"));
    // Row 0 clears a crate, maybe the very one row 1 matched.
    CHECK_FALSE(secondRowHolds("[ Crate ] [ Crate ] -> [ ] [ up Crate ]\n"));
    // Row 0 gives the crate's layer a movement that row 1 rules out.
    CHECK_FALSE(secondRowHolds("[ Crate ] [ stationary Crate ] -> [ up Crate ] [ ]\n"));
}
