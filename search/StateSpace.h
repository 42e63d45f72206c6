// The state space of one level, as search sees it: state keys
// (templates/state_key.h) and their children, computed in batches by a game's
// plugin on CPU threads or on the GPU (psc_expand).  ANTLR and the compiler
// stay out of search: it needs only a loaded plugin.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "Plugin.h"

namespace psc::search {

enum class Backend { Cpu, Cuda };

struct SpaceOptions {
    Backend backend = Backend::Cpu;
    int threads = 1;        // CPU threads expanding a batch
    int device = 0;         // CUDA device ordinal
    uint64_t seed = 0;      // the level's random seed (psc_reset), for games that use random
    size_t maxBatch = 0;    // states expanded per call; 0: by backend
};

// The letters of solutions, as `psc solve` prints them.
char inputLetter(int action);     // psc_action 0 up 'u', 1 left 'l', 2 down 'd', 3 right 'r', 4 action 'x'
int actionOfLetter(char letter);  // the inverse (case-insensitive); -1 for any other character

class StateSpace {
public:
    // Level `level` (playable, from 0) started with `seed`, then `fromInputs`
    // (letters u d l r x) played.  Throws std::runtime_error on a bad level,
    // letter or plugin error.
    StateSpace(const Plugin& plugin, const SpaceOptions& options, int level, std::string_view fromInputs);
    ~StateSpace();
    StateSpace(const StateSpace&) = delete;
    StateSpace& operator=(const StateSpace&) = delete;

    size_t keyWords() const { return keyWords_; }
    // The psc_action of each search input: the four directions, and action unless the game has noaction.
    const std::vector<int32_t>& inputs() const { return inputs_; }
    const std::vector<uint64_t>& root() const { return root_; }
    uint64_t rootHash() const { return rootHash_; }
    bool rootWon() const { return rootWon_; }  // the start or fromInputs already won the level
    // The level's start won it before any input (its `again` chain did):
    // the reference engine shows the next entry before the first input.
    bool startWon() const { return startWon_; }
    // The level's start (or an input of fromInputs) ran an `again` chain that
    // was cut off: the reference engine never finishes it, so nothing follows.
    bool rootCutOff() const { return rootCutOff_; }
    int entry() const { return entry_; }
    size_t maxBatch() const { return maxBatch_; }
    Backend backend() const { return options_.backend; }
    int deviceOrdinal() const { return options_.device; }

    // Children of keys[0..count) (count <= maxBatch()): child i * inputs + a
    // of key i under inputs()[a], with its flags (PSC_EXPAND_*), hash and,
    // where `estimates` is not null, its distance estimate.
    void expand(const uint64_t* keys, size_t count, uint64_t* children, uint8_t* flags, uint64_t* hashes,
                int32_t* estimates = nullptr);
    // The next expansions stop `seconds` from now (psc_set_deadline; CPU
    // spaces), flagging what they did not finish PSC_EXPAND_TIMED_OUT.
    void setDeadline(double seconds);
    // Expansion of keys left where the backend computes (device memory on the
    // GPU), with the children kept there: expansion alone, for measuring it.
    void stage(const uint64_t* keys, size_t count);
    void expandStaged(size_t count);  // queued on the GPU; synchronize() waits
    void synchronize();
    // CUDA spaces: children of keys already in device memory (and their
    // estimates where asked), left in the space's device buffers below,
    // queued on the batch's stream.
    void expandResident(const void* deviceKeys, size_t count, bool withEstimates = false);
    const void* deviceChildren() const { return deviceChildren_; }
    const void* deviceEstimates() const { return deviceEstimates_; }
    const void* deviceFlags() const { return deviceFlags_; }
    const void* deviceHashes() const { return deviceHashes_; }
    // The CUDA stream the batch queues its work on (null: the default stream).
    void setStream(void* stream);
    // psc_estimate_distance of keys[0..count).
    void estimate(const uint64_t* keys, size_t count, int32_t* estimates);
    // Whether playing `inputs` from the start (fromInputs included) wins the level at the last one and not before.
    bool winsExactlyAtEnd(std::string_view inputs);

private:
    void check(int status, const char* what) const;

    const Plugin& plugin_;
    SpaceOptions options_;
    int level_;
    psc_batch* batch_ = nullptr;
    size_t keyWords_ = 0;
    std::vector<int32_t> inputs_;
    std::vector<uint64_t> root_;
    uint64_t rootHash_ = 0;
    bool rootWon_ = false;
    bool startWon_ = false;
    bool rootCutOff_ = false;
    int entry_ = 0;
    size_t maxBatch_ = 0;
    // Buffers of staged expansion on the CPU.
    std::vector<uint64_t> stagedKeys_, stagedChildren_, stagedHashes_;
    std::vector<uint8_t> stagedFlags_;
    // Device buffers of a CUDA space (null on the CPU).
    void* deviceKeys_ = nullptr;
    void* deviceChildren_ = nullptr;
    void* deviceFlags_ = nullptr;
    void* deviceHashes_ = nullptr;
    void* deviceEstimates_ = nullptr;
    void* deviceInputs_ = nullptr;
};

}  // namespace psc::search
