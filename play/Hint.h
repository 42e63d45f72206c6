// The hint key: asks the solver (`psc solve`, run as a child process so the
// player stays responsive and can drop a search) for the way to win from the
// state shown, given as the inputs played since the level's start.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <string>

namespace psc::play {

struct HintRequest {
    std::string pscBinary;   // the psc executable
    std::string gamePath;
    int level = 0;           // playable, from 0
    std::string fromInputs;  // u l d r x from the level's start
    uint64_t seed = 0;
    double timeLimit = 10;   // seconds of search
};

struct HintAnswer {
    bool solved = false;
    char nextInput = 0;   // u l d r x, when solved
    int remaining = 0;    // inputs still needed to win, the next one included
    std::string problem;  // why there is no hint, otherwise
};

class HintSearch {
public:
    HintSearch() = default;
    ~HintSearch();  // stops a search still running
    HintSearch(const HintSearch&) = delete;
    HintSearch& operator=(const HintSearch&) = delete;

    // Starts a search (stopping one under way); false and a problem when it cannot start.
    bool start(const HintRequest& request, std::string* problem);
    bool running() const { return pid_ > 0; }
    // The solver's output pipe (for poll), -1 when none runs.
    int fd() const { return fd_; }
    // Reads what the solver wrote; the answer once it has finished.  With
    // `wait`, blocks until then.
    std::optional<HintAnswer> collect(bool wait);
    void cancel();

private:
    HintAnswer finish();

    pid_t pid_ = -1;
    int fd_ = -1;
    std::string output_;
};

// The answer in psc solve's JSON line (or its error text).
HintAnswer parseSolverOutput(const std::string& output, int exitStatus);

}  // namespace psc::play
