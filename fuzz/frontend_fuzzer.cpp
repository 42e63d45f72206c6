// Fuzz target (a): the whole front end (`psc check`: scanner, rule grammar,
// every pass) on arbitrary bytes and on structural mutations of real games.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "Compiler.h"
#include "GameMutator.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    psc::compileSource(std::string_view(reinterpret_cast<const char*>(data), size));
    return 0;
}

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t maxSize, unsigned int seed) {
    return psc::fuzz::mutateGameBytes(data, size, maxSize, seed);
}
