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

TEST_CASE("sound reads can reload a cell's movements with two moving layers and three move sounds", "[codegen]") {
    auto canReload = [](const std::string& rules, const std::string& sounds) {
        GameParts p = ownLayers(rules);
        p.sounds = sounds;
        CompileResult r = test::compileParts(p);
        INFO(test::gameText(p));
        REQUIRE(r.status == CompileStatus::Ok);
        return codegen::soundReadsCanReload(*r.game);
    };
    const std::string push = "[ > Player | Crate ] -> [ > Player | > Crate ]\n";
    const std::string three = "Player move 1234\nCrate move 5678\nCrate move up 999\n";
    CHECK(canReload(push, three));
    CHECK_FALSE(canReload(push, "Player move 1234\nCrate move 5678\n"));
    // Only the player's layer moves: its reads never restore another layer's.
    CHECK_FALSE(canReload("", three));
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
        CHECK(updates[0].layerOrObject == test::objectId(g, "crate"));
        CHECK(updates[0].keepOrValue == 0);
        CHECK(updates[1].layerOrObject == test::objectId(g, "wall"));
        CHECK(updates[1].keepOrValue == 1);
    }
    SECTION("a layer that holds only what its replacement puts there is not written") {
        FirstCell f = firstCellOf("[ Target Crate ] -> [ Target up Crate ]\n");
        const ir::Game& g = *f.result.game;
        const ir::Replacement& r = *f.cell().replacement;
        const codegen::CellFacts facts = codegen::cellFacts(g, f.cell());
        CHECK_FALSE(codegen::objectUpdates(g, r.set, r.clear).empty());
        CHECK(codegen::objectUpdates(g, r.set, r.clear, &facts).empty());
    }
    SECTION("an object ruled out by 'no' is not cleared") {
        FirstCell f = firstCellOf("[ Target no Crate no Wall ] -> [ Target ]\n");
        const ir::Game& g = *f.result.game;
        const ir::Replacement& r = *f.cell().replacement;
        const codegen::CellFacts facts = codegen::cellFacts(g, f.cell());
        for (const auto& u : codegen::objectUpdates(g, r.set, r.clear, &facts)) {
            CHECK(u.layerOrObject != test::objectId(g, "crate"));
            CHECK(u.layerOrObject != test::objectId(g, "wall"));
        }
    }
    SECTION("a movement the pattern requires is not set again, nor its layer's other directions cleared") {
        FirstCell f = firstCellOf("[ > Player ] -> [ > Player ]\n");
        const ir::Game& g = *f.result.game;
        const codegen::CellFacts facts = codegen::cellFacts(g, f.cell());
        const auto all = codegen::movementUpdates(g, *f.cell().replacement, std::nullopt);
        REQUIRE(all.size() == 1);
        CHECK(all[0].set != 0u);
        CHECK((all[0].clear | all[0].set) == 31u);
        CHECK(codegen::movementUpdates(g, *f.cell().replacement, std::nullopt, &facts).empty());
    }
    SECTION("a movement the pattern requires is replaced by another without clearing the rest") {
        const auto [all, needed] = movementWritesOf("[ up Player ] -> [ down Player ]\n");
        CHECK(needed.set == all.set);
        CHECK(needed.clear == 1u);  // up, the one direction the layer can hold
        CHECK(all.clear != needed.clear);
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
    // Row 0 writes the layer row 1 rests on, but never at row 1's cell: a
    // cell holds a player or a wall, not both, and a match's rows hold at once.
    CHECK(secondRowHolds("[ Player ] [ Wall ] -> [ ] [ Wall ]\n"));
    CHECK(secondRowHolds("[ Crate ] [ no Crate ] -> [ ] [ up Crate ]\n"));
}

TEST_CASE("cells exclude each other where one requires what the other rules out", "[codegen]") {
    CompileResult r = test::compileParts(ownLayers(
        "right [ Player | Wall | Crate | no Crate | stationary Crate | up Crate | Target ] -> [ Player | Wall | Crate | | Crate | Crate | Target ]\n"));
    REQUIRE(r.status == CompileStatus::Ok);
    const ir::Game& g = *r.game;
    const std::vector<ir::CellPattern>& cells = r.game->rules[0].rules[0].rows[0];
    REQUIRE(cells.size() == 7);
    CHECK(codegen::cellsExclude(g, cells[0], cells[1]));        // one layer holds the player and the wall
    CHECK(codegen::cellsExclude(g, cells[2], cells[3]));        // a crate, and no crate
    CHECK(codegen::cellsExclude(g, cells[4], cells[5]));        // a still crate, and a moving one
    CHECK_FALSE(codegen::cellsExclude(g, cells[2], cells[6]));  // a crate may lie on a target
    CHECK_FALSE(codegen::cellsExclude(g, cells[0], cells[2]));  // layers of their own: both may be there
}

TEST_CASE("a cell still matches after a write that sets nothing it rules out and clears nothing it needs", "[codegen]") {
    // Rule `rules`'s first cell writes; does its second cell, had it lain there, still match?
    auto secondStillMatches = [](const std::string& rules) {
        CompileResult r = test::compileParts(ownLayers(rules));
        INFO(rules);
        REQUIRE(r.status == CompileStatus::Ok);
        const ir::Game& g = *r.game;
        const std::vector<ir::CellPattern>& cells = g.rules[0].rules[0].rows[0];
        REQUIRE(cells.size() == 2);
        const codegen::CellFacts facts = codegen::cellFacts(g, cells[0]);
        return codegen::stillMatchesAfter(cells[1], codegen::effectOf(*cells[0].replacement, &facts));
    };
    // Pushing a chain: the write gives the next crate the movement it needs.
    CHECK(secondStillMatches("down [ Crate | up Crate ] -> [ up Crate | up Crate ]\n"));
    // Another direction clears the one the other cell needs.
    CHECK_FALSE(secondStillMatches("down [ Crate | up Crate ] -> [ down Crate | up Crate ]\n"));
    // A movement where the other cell wants its crate still.
    CHECK_FALSE(secondStillMatches("down [ Crate | stationary Crate ] -> [ up Crate | stationary Crate ]\n"));
    // Removing the crate the other cell needs; putting one where it must have none.
    CHECK_FALSE(secondStillMatches("down [ Crate | Crate ] -> [ | Crate ]\n"));
    CHECK_FALSE(secondStillMatches("down [ Target | no Crate ] -> [ Target Crate | no Crate ]\n"));
    // A target on a target's cell, or a crate cleared where none may be, changes nothing it tests.
    CHECK(secondStillMatches("down [ Crate | Target ] -> [ Crate Target | Target ]\n"));
    CHECK(secondStillMatches("down [ Crate | no Crate ] -> [ | no Crate ]\n"));
}
