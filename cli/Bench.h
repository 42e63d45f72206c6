// psc bench: steps/s of a game's plugin on random actions with automatic
// reset on a win (the plugin's fused rollout).  Prints one row per batch size
// (median and min of the repeats, warm-up excluded; CUDA events on the GPU;
// and the seconds the batch's reset took, not counted in steps/s) and a last
// line `steps/s: <median of the best batch size>`.  A sweep that has run past
// its time limit measures no further batch and says so (exit 2).  With --devices,
// one batch of each size on every device listed, stepped at once: the rows are
// the devices' steps/s together, timed by the host's clock.
#pragma once

#include <string>
#include <vector>

#include "GameBuild.h"

namespace psc::cli {

struct BenchOptions {
    std::string gamePath;
    int level = 0;
    std::vector<int> batches;  // empty: 1 (cpu), or a sweep 1 ... 4M (cuda)
    int steps = 0;             // steps per timed run; 0: chosen so that a run takes about 0.25 s
    int threads = 1;
    int repeats = 5;
    int warmup = 1;
    double timeLimit = 600;  // seconds; no batch is begun after it
    std::string backend = "cpu";
    int device = 0;            // CUDA ordinal
    std::vector<int> devices;  // several CUDA ordinals: one batch on each, stepped at once (aggregate steps/s)
    bool allLevels = false;  // build every level (default: only the one measured)
    bool expand = false;     // measure psc_expand (BenchExpand.h) instead of stepping
    GameBuildOptions build;
};

int runBench(const BenchOptions& options);

}  // namespace psc::cli
