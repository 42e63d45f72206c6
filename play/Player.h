// psc play: a game played in the terminal, screen by screen, as the
// reference engine's browser player plays it (title screen, message screens,
// levels one after another), with psc's extras: level select, next and
// previous level, progress kept between runs, hints from the solver, scripted
// input, replays and records.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "LevelView.h"
#include "Plugin.h"

namespace psc::play {

struct PlayOptions {
    std::string gamePath;
    std::optional<int> level;          // start at this playable level (from 0), skipping the title screen
    bool forceGlyphs = false;
    bool scripted = false;             // keys from standard input, which may be a pipe
    std::vector<int> replay;           // inputs to animate first (psc_action)
    bool hasReplay = false;
    double replayInterval = 0.15;      // seconds between replayed inputs
    std::string recordPath;            // where the inputs played are written
    uint64_t seed = 0;                 // random games' level seed
    std::string pscBinary;             // psc itself, for hints (psc solve)
    double hintTimeLimit = 10;         // seconds
};

// Plays until the player quits.  Returns the exit status: 0 after Q (or the
// end of scripted input), 128 + the signal after Ctrl-C or a signal.  Throws
// on failures (the terminal is restored first).
int play(const Plugin& plugin, const GameDisplay& display, const PlayOptions& options);

}  // namespace psc::play
