// Small games for the front-end tests, built from a template so each test
// states only the part it is about.
#pragma once

#include <string>

#include "Compiler.h"

namespace psc::test {

struct GameParts {
    std::string prelude;
    std::string objects = "Background\nblack\n\nPlayer\nblue\n\nWall\ngray\n\nCrate\norange\n\nTarget\nyellow\n";
    std::string legend = ". = Background\nP = Player\n# = Wall\n* = Crate\nO = Target\n";
    std::string sounds;
    std::string layers = "Background\nTarget\nPlayer, Wall, Crate\n";
    std::string rules;
    std::string winConditions;
    std::string levels = "#####\n#P*O#\n#####\n";
};

std::string gameText(const GameParts& parts);
CompileResult compileParts(const GameParts& parts);
// The id of the (live) object named `name`; fails the test where there is none.
int objectId(const ir::Game& game, const std::string& name);

}  // namespace psc::test
