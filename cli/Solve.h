// psc solve: solutions of a game's levels by search (search/Solver.h), one
// record per level as text or JSON lines; a progress line on stderr for
// searches longer than a second.  Exit status: 0 when every level asked for
// is solved, 1 when one is not, 2 on an error.
#pragma once

#include <string>
#include <vector>

#include "GameBuild.h"
#include "Solver.h"

namespace psc::cli {

struct SolveCommandOptions {
    std::string gamePath;
    std::vector<int> levels;  // playable levels from 0; empty with allLevels: every one
    bool allLevels = false;
    std::string algorithm = "bfs";
    std::string backend = "cpu";
    int threads = 1;
    int device = 0;  // CUDA ordinal (--backend cuda)
    double timeLimit = 60;
    uint64_t maxStates = 0;
    double maxMemoryMb = 0;  // 0: half of the machine's memory
    double weight = 2;
    uint64_t beamWidth = 0;  // 0: by backend (search::SolveOptions)
    uint64_t seed = 0;
    std::string fromInputs;
    std::string format = "text";
    bool quiet = false;  // no progress line
    GameBuildOptions build;
};

int runSolve(const SolveCommandOptions& options);

}  // namespace psc::cli
