// Structure-aware mutations of PuzzleScript games, for libFuzzer's custom
// mutator: whole lines and sections moved, duplicated or dropped, names
// renamed throughout, keywords inserted.  Byte-level mutations alone rarely
// get past the section structure; these keep games close to real ones.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <string>

namespace psc::fuzz {

// One structural mutation of `game` chosen by `rng`; the result may be the
// input unchanged when the mutation does not apply (a one-line game).
std::string mutateGame(const std::string& game, std::mt19937& rng);

// libFuzzer glue: mutates data[0, size) in place (capacity max_size) with a
// structural mutation or, half of the time, with LLVMFuzzerMutate.
size_t mutateGameBytes(uint8_t* data, size_t size, size_t maxSize, unsigned seed);

}  // namespace psc::fuzz
