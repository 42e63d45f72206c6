#include <catch2/catch.hpp>

#include "RuleParts.h"
#include "SinglePassGroups.h"
#include "TestGames.h"

using namespace psc;
using psc::test::GameParts;

namespace {

// Whether each early group of a game with `rules` passes once.
std::vector<bool> passesOnceOf(const std::string& rules) {
    GameParts p;
    p.legend += "Obstacle = Wall or Crate\n";
    p.rules = rules;
    CompileResult r = test::compileParts(p);
    INFO(test::gameText(p));
    REQUIRE(r.status == CompileStatus::Ok);
    std::vector<bool> once;
    const bool layersExclusive = codegen::layersHoldOneObject(*r.game);
    for (const ir::RuleGroup& group : r.game->rules) once.push_back(codegen::passesOnce(*r.game, group, layersExclusive));
    return once;
}

}  // namespace

TEST_CASE("a rule that removes what it matched passes once", "[codegen]") {
    CHECK(passesOnceOf("[ > Player ] -> [ Player ]\n") == std::vector<bool>{true});
    CHECK(passesOnceOf("[ Player Target ] -> [ Player ]\n") == std::vector<bool>{true});
    // Both objects of the any-of set go, so the matched cell holds neither.
    CHECK(passesOnceOf("right [ Obstacle | Player ] -> [ | Player ]\n") == std::vector<bool>{true});
}

TEST_CASE("a rule that can match again after applying keeps its loop", "[codegen]") {
    // A crate slides one cell a pass: it needs as many passes as cells it slides.
    CHECK(passesOnceOf("right [ Crate | no Wall ] -> [ | Crate ]\n") == std::vector<bool>{false});
    // Adding a crate beside a crate feeds the next pass.
    CHECK(passesOnceOf("right [ Crate | no Crate ] -> [ Crate | Crate ]\n") == std::vector<bool>{false});
    // Its match still holds afterwards, so the next pass finds it again.
    CHECK(passesOnceOf("[ Crate ] -> [ Crate Target ]\n") == std::vector<bool>{false});
}

TEST_CASE("a later rule that removes what an earlier rule rules out keeps the loop", "[codegen]") {
    // Removing a target makes a crate that stood on it match the first rule in the next pass.
    CHECK(passesOnceOf("[ Crate no Target ] -> [ ]\n+ [ Target ] -> [ ]\n") == std::vector<bool>{false});
    // Without the `no`, removing targets can only take matches away.
    CHECK(passesOnceOf("[ Crate Target ] -> [ Target ]\n+ [ Target ] -> [ ]\n") == std::vector<bool>{true});
}

TEST_CASE("random and rigid groups keep their loop", "[codegen]") {
    CHECK(passesOnceOf("random [ Player Target ] -> [ Player ]\n") == std::vector<bool>{false});
    CHECK(passesOnceOf("rigid [ > Player ] -> [ Player ]\n") == std::vector<bool>{false});
    CHECK(passesOnceOf("[ Player Target ] -> [ Player random Crate ]\n") == std::vector<bool>{false});
}
