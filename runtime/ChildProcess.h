// Running an external compiler (c++, nvcc) so that it never outlives psc and
// never runs unbounded: no shell, its own process group, a wall-clock limit
// and an address-space limit.
//
// Each child runs under a small supervisor process (forked, not exec'd) that
// leads the child's process group and asks the kernel to signal it when psc
// dies (PR_SET_PDEATHSIG).  However psc ends - a normal exit, SIGINT, SIGTERM,
// a caller's timeout sending SIGKILL - the supervisor then kills the whole
// group: the compiler driver and what it started (cc1plus, as, ptxas).
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <vector>

namespace psc {

struct ChildLimits {
    double wallSeconds = 0;       // 0: none
    unsigned long long memoryBytes = 0;  // RLIMIT_AS of the child (each of its processes); 0: none
};

struct ChildResult {
    bool started = false;   // false: it could not be run (error says why)
    int exitCode = -1;      // the child's exit status, when it exited
    int signal = 0;         // the signal that ended it, when one did
    bool timedOut = false;  // killed at limits.wallSeconds
    double seconds = 0;     // how long it ran (until it was stopped, when it was)
    std::string error;

    bool ok() const { return started && !timedOut && signal == 0 && exitCode == 0; }
};

// A child started by startChild.  wait() waits for it (at most until its
// wall-clock limit, counted from its start) and says how it ended; a child
// destroyed without wait() is killed with its group.
class RunningChild {
public:
    RunningChild() = default;
    RunningChild(RunningChild&& other) noexcept;
    RunningChild& operator=(RunningChild&& other) noexcept;
    ~RunningChild();

    ChildResult wait();
    // Whether wait() would return at once: the child has ended (or was never started).
    bool ended() const;

private:
    friend RunningChild startChild(const std::vector<std::string>&, const std::string&, const ChildLimits&);
    void stop();

    ChildResult result_;
    std::string program_;
    std::string path_;
    std::chrono::steady_clock::time_point start_;
    double wallSeconds_ = 0;
    int supervisor_ = -1;
    int statusFd_ = -1;
};

// Starts argv[0] (searched in PATH when it has no '/') with argv, its stdout
// and stderr written to `logPath` (empty: /dev/null), and returns at once.
// Safe while psc runs other threads: the forked copy only calls exec's
// async-signal-safe preparations.
RunningChild startChild(const std::vector<std::string>& argv, const std::string& logPath, const ChildLimits& limits);

// startChild, then wait.
ChildResult runChild(const std::vector<std::string>& argv, const std::string& logPath, const ChildLimits& limits);

// Runs `work` in a forked copy of psc, for a compiler that runs inside psc
// (NVRTC), so that it too has a wall-clock limit (`wallSeconds`, 0: none)
// and dies with psc; `*output` receives what `work` returned.  No memory
// limit: a sanitizer's shadow memory already spans more address space than
// any limit would allow.  Call it while psc runs no other thread (the copy
// has only the calling one, and a lock another held would stay locked).
// `meanwhile`, where given, runs in psc every few milliseconds while the copy
// works (to start the next step of a build whose other parts are done).
ChildResult runForked(const std::function<std::string()>& work, std::string* output, double wallSeconds,
                      const std::function<void()>& meanwhile = {});

// The program's path: `name` when it has a '/', else its first match in PATH;
// empty when there is none.
std::string findProgram(const std::string& name);

// The default limits of compiler processes: $PSC_COMPILE_TIMEOUT seconds
// (default kDefaultCompileSeconds) and $PSC_COMPILE_MEMORY_MB megabytes of
// address space (default: three quarters of the machine's memory).
constexpr double kDefaultCompileSeconds = 300;
ChildLimits defaultCompileLimits();

// What a failed child was stopped by, in words that name the limit (and the
// variable that sets it), or the empty string when no limit stopped it.
// `log` is the child's output (a compiler out of memory says so there).
std::string limitMessage(const ChildResult& result, const ChildLimits& limits, const std::string& log);

}  // namespace psc
