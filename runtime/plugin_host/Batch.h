// A batch of environments as the plugin host keeps it: on the CPU, the
// environments and their undo rings as bytes (the game module knows their
// layout); on a CUDA device, a CudaBatch (CudaBackend.h).
#pragma once

#include <stdint.h>

#include <vector>

#include "psc_plugin.h"
#include "GameModule.h"
#include "WorkerPool.h"

namespace psc_host {

class CudaBatch;

inline const GameModule& game() { return psc_game_module; }

// One environment (or undo snapshots) outside a batch, 8-byte aligned.
class EnvBuffer {
public:
    explicit EnvBuffer(size_t bytes) : words_((bytes + 7) / 8) {}
    void* data() { return words_.data(); }
    const void* data() const { return words_.data(); }

private:
    std::vector<uint64_t> words_;
};

}  // namespace psc_host

struct psc_batch {
    psc_host::CudaBatch* cuda = nullptr;  // the CUDA backend's batch, when this batch runs there
    int numEnvs = 0;
    int undoDepth = 0;
    int autoReset = PSC_AUTO_RESET_OFF;
    int maxEpisodeSteps = 0;
    // CPU batches: numEnvs environments of game().envBytes each (8-byte aligned,
    // as the engine's Env is), and numEnvs × undoDepth snapshots.
    std::vector<uint64_t> envWords;
    std::vector<uint64_t> undoWords;
    std::vector<psc_host::UndoRing> undo;
    // psc_buffers
    std::vector<int32_t> actions;
    std::vector<uint8_t> observations;
    std::vector<float> rewards;
    std::vector<uint8_t> terminated;
    std::vector<uint8_t> truncated;
    std::vector<uint8_t> won;
    std::vector<int32_t> episodeSteps;
    unsigned long long rolloutSteps = 0;  // steps run by rollouts so far (the random actions' counter)
    int64_t expandDeadline = 0;            // psc_set_deadline: steady-clock nanoseconds, or 0
    psc_host::WorkerPool* pool = nullptr;

    void* env(int i) { return reinterpret_cast<char*>(envWords.data()) + psc_host::game().envBytes * static_cast<size_t>(i); }
    const void* env(int i) const {
        return reinterpret_cast<const char*>(envWords.data()) + psc_host::game().envBytes * static_cast<size_t>(i);
    }
};
