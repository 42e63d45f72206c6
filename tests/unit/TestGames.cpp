#include "TestGames.h"

#include <catch2/catch.hpp>

namespace psc::test {

std::string gameText(const GameParts& p) {
    return p.prelude + "\nOBJECTS\n\n" + p.objects + "\nLEGEND\n\n" + p.legend + "\nSOUNDS\n\n" + p.sounds +
           "\nCOLLISIONLAYERS\n\n" + p.layers + "\nRULES\n\n" + p.rules + "\nWINCONDITIONS\n\n" + p.winConditions +
           "\nLEVELS\n\n" + p.levels;
}

CompileResult compileParts(const GameParts& parts) { return compileSource(gameText(parts)); }

int objectId(const ir::Game& game, const std::string& name) {
    for (const auto& o : game.objects) {
        if (o.name == name && !o.ghost) return o.id;
    }
    FAIL("no object " << name);
    return -1;
}

}  // namespace psc::test
