// psc bench: steps/s of a game's plugin on random actions, with automatic
// reset on a win.  Prints a table of the repeats and a line `steps/s: <median>`.
#pragma once

#include <string>

#include "GameBuild.h"

namespace psc::cli {

struct BenchOptions {
    std::string gamePath;
    int level = 0;
    int batch = 1;
    int steps = 1000;
    int threads = 1;
    int repeats = 5;
    int warmup = 1;
    std::string backend = "cpu";
    bool allLevels = false;  // build every level (default: only the one measured)
    GameBuildOptions build;
};

int runBench(const BenchOptions& options);

}  // namespace psc::cli
