// psc bench --expand: how fast a game's plugin expands states for search
// (psc_expand), in children generated per second.  The keys are a frontier
// of distinct states that breadth-first search reaches from the level's
// start; they stay where the backend computes (device memory on the GPU), so
// the figure is expansion alone.  One row per batch size (states a call),
// median, min and max of the repeats after warm-up (CUDA events on the GPU).
#pragma once

#include <optional>

#include "Bench.h"
#include "CudaTimer.h"

namespace psc::cli {

// `timer` times the GPU (set for --backend cuda).
int runExpandBench(const BenchOptions& options, const Plugin& plugin, std::optional<CudaTimer>& timer);

}  // namespace psc::cli
