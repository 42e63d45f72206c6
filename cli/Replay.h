// psc replay: drives a game through a recorded corpus case and compares the
// state after every input with the recording.
#pragma once

#include <string>

#include "GameBuild.h"

namespace psc::cli {

struct ReplayOptions {
    std::string casePath;
    std::string backend = "cpu";
    int device = 0;  // CUDA ordinal (--backend cuda)
    std::string dumpPath;  // JSON lines: the initial state and the state after every input
    // Also check every level state's key (templates/state_key.h): decoded over
    // a fresh start of the entry shown, it must give back the same state.
    bool checkKeys = false;
    GameBuildOptions build;
};

// 0: every state matches; 1: a mismatch (the first is printed); 2: an error.
int runReplay(const ReplayOptions& options);

}  // namespace psc::cli
