#include "TestGames.h"

namespace psc::test {

std::string gameText(const GameParts& p) {
    return p.prelude + "\nOBJECTS\n\n" + p.objects + "\nLEGEND\n\n" + p.legend + "\nSOUNDS\n\n" + p.sounds +
           "\nCOLLISIONLAYERS\n\n" + p.layers + "\nRULES\n\n" + p.rules + "\nWINCONDITIONS\n\n" + p.winConditions +
           "\nLEVELS\n\n" + p.levels;
}

CompileResult compileParts(const GameParts& parts) { return compileSource(gameText(parts)); }

}  // namespace psc::test
