#include "ChildProcess.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <utility>

namespace psc {
namespace {

// The supervisor's handler for psc's death (and for SIGINT/SIGTERM/SIGHUP sent
// to its group): the whole group, itself included, dies at once.
void killOwnGroup(int) { kill(0, SIGKILL); }

// What the supervisor tells psc: the child's wait status (-1: it could not be
// started) and how long the child ran, which psc, collecting it later, cannot
// see.
struct ChildReport {
    int status = 0;
    long long nanoseconds = 0;
};

long long monotonicNanoseconds() {
    timespec t{};
    clock_gettime(CLOCK_MONOTONIC, &t);  // async-signal-safe
    return static_cast<long long>(t.tv_sec) * 1000000000LL + t.tv_nsec;
}

bool writeAll(int fd, const void* data, size_t size) {
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t n = write(fd, p, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        p += n;
        size -= static_cast<size_t>(n);
    }
    return true;
}

// Between fork and exec only async-signal-safe calls: psc has threads.
[[noreturn]] void superviseChild(pid_t parent, const char* path, char* const* argv, int logFd, int statusFd,
                                 const ChildLimits& limits) {
    setpgid(0, 0);
    struct sigaction action {};
    action.sa_handler = killOwnGroup;
    sigemptyset(&action.sa_mask);
    for (int s : {SIGTERM, SIGINT, SIGHUP}) sigaction(s, &action, nullptr);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) killOwnGroup(0);  // psc died before the request took effect
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    const long long started = monotonicNanoseconds();
    const pid_t child = fork();
    if (child == 0) {
        struct sigaction fallback {};
        fallback.sa_handler = SIG_DFL;
        sigemptyset(&fallback.sa_mask);
        for (int s : {SIGTERM, SIGINT, SIGHUP}) sigaction(s, &fallback, nullptr);
        if (limits.memoryBytes > 0) {
            const rlimit limit{limits.memoryBytes, limits.memoryBytes};
            setrlimit(RLIMIT_AS, &limit);
        }
        const int devNull = open("/dev/null", O_RDONLY);
        if (devNull >= 0) dup2(devNull, 0);
        dup2(logFd, 1);
        dup2(logFd, 2);
        execv(path, argv);
        _exit(127);
    }
    ChildReport report;
    if (child < 0) {
        report.status = -1;
    } else {
        while (waitpid(child, &report.status, 0) < 0 && errno == EINTR) {
        }
    }
    report.nanoseconds = monotonicNanoseconds() - started;
    writeAll(statusFd, &report, sizeof report);
    _exit(0);
}

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::string findProgram(const std::string& name) {
    if (name.empty()) return {};
    if (name.find('/') != std::string::npos) return access(name.c_str(), X_OK) == 0 ? name : std::string();
    const char* path = std::getenv("PATH");
    std::string dirs = path && *path ? path : "/usr/local/bin:/usr/bin:/bin";
    size_t begin = 0;
    while (begin <= dirs.size()) {
        size_t end = dirs.find(':', begin);
        if (end == std::string::npos) end = dirs.size();
        const std::string dir = end > begin ? dirs.substr(begin, end - begin) : ".";
        const std::string candidate = dir + "/" + name;
        struct stat st {};
        if (stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) && access(candidate.c_str(), X_OK) == 0) return candidate;
        begin = end + 1;
    }
    return {};
}

// Waits until `fd` is readable or the wall-clock limit (0: none) counted
// from `start` has passed; false at the limit.  `meanwhile`, where given,
// runs every kMeanwhileMs while it waits.
constexpr int kMeanwhileMs = 5;
bool waitReadable(int fd, double wallSeconds, std::chrono::steady_clock::time_point start,
                  const std::function<void()>& meanwhile = {}) {
    for (;;) {
        int waitMs = -1;
        if (wallSeconds > 0) {
            const double left = wallSeconds - secondsSince(start);
            if (left <= 0) return false;
            waitMs = static_cast<int>(left * 1000) + 1;
        }
        if (meanwhile && (waitMs < 0 || waitMs > kMeanwhileMs)) waitMs = kMeanwhileMs;
        pollfd pfd{fd, POLLIN, 0};
        const int ready = poll(&pfd, 1, waitMs);
        if (ready > 0 || (ready < 0 && errno != EINTR)) return true;  // the read that follows says which
        if (ready == 0 && meanwhile) meanwhile();
    }
}

RunningChild startChild(const std::vector<std::string>& argv, const std::string& logPath, const ChildLimits& limits) {
    RunningChild c;
    c.start_ = std::chrono::steady_clock::now();
    c.wallSeconds_ = limits.wallSeconds;
    ChildResult& r = c.result_;
    if (argv.empty()) {
        r.error = "no program to run";
        return c;
    }
    c.program_ = argv[0];
    c.path_ = findProgram(argv[0]);
    if (c.path_.empty()) {
        r.error = fmt::format("cannot find the program {}", argv[0]);
        return c;
    }
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const int logFd = open(logPath.empty() ? "/dev/null" : logPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (logFd < 0) {
        r.error = fmt::format("cannot write {}: {}", logPath, std::strerror(errno));
        return c;
    }
    int statusPipe[2];
    if (pipe2(statusPipe, O_CLOEXEC) != 0) {
        close(logFd);
        r.error = fmt::format("cannot create a pipe: {}", std::strerror(errno));
        return c;
    }
    const pid_t parent = getpid();
    const pid_t supervisor = fork();
    if (supervisor == 0) superviseChild(parent, c.path_.c_str(), args.data(), logFd, statusPipe[1], limits);
    close(statusPipe[1]);
    close(logFd);
    if (supervisor < 0) {
        close(statusPipe[0]);
        r.error = fmt::format("cannot start {}: {}", argv[0], std::strerror(errno));
        return c;
    }
    // Both sides set the group, so that a kill at the deadline reaches it
    // even when the supervisor has not run yet.
    setpgid(supervisor, supervisor);
    r.started = true;
    c.supervisor_ = supervisor;
    c.statusFd_ = statusPipe[0];
    return c;
}

RunningChild::RunningChild(RunningChild&& other) noexcept { *this = std::move(other); }

RunningChild& RunningChild::operator=(RunningChild&& other) noexcept {
    if (this != &other) {
        stop();
        result_ = std::move(other.result_);
        program_ = std::move(other.program_);
        path_ = std::move(other.path_);
        start_ = other.start_;
        wallSeconds_ = other.wallSeconds_;
        supervisor_ = std::exchange(other.supervisor_, -1);
        statusFd_ = std::exchange(other.statusFd_, -1);
    }
    return *this;
}

RunningChild::~RunningChild() { stop(); }

bool RunningChild::ended() const {
    if (supervisor_ <= 0) return true;
    pollfd pfd{statusFd_, POLLIN, 0};
    return poll(&pfd, 1, 0) != 0;  // its report, or the supervisor gone
}

void RunningChild::stop() {
    if (supervisor_ <= 0) return;
    kill(-supervisor_, SIGKILL);
    close(statusFd_);
    while (waitpid(supervisor_, nullptr, 0) < 0 && errno == EINTR) {
    }
    supervisor_ = -1;
    statusFd_ = -1;
}

ChildResult RunningChild::wait() {
    if (supervisor_ <= 0) return result_;
    ChildResult& r = result_;
    ChildReport report;
    size_t got = 0;
    for (;;) {
        if (!waitReadable(statusFd_, wallSeconds_, start_)) {
            r.timedOut = true;
            break;
        }
        const ssize_t n = read(statusFd_, reinterpret_cast<char*>(&report) + got, sizeof report - got);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;  // the supervisor died without a report
        got += static_cast<size_t>(n);
        if (got == sizeof report) break;
    }
    const int status = report.status;
    close(statusFd_);
    statusFd_ = -1;
    if (r.timedOut || got != sizeof report) kill(-supervisor_, SIGKILL);
    int supervisorStatus = 0;
    while (waitpid(supervisor_, &supervisorStatus, 0) < 0 && errno == EINTR) {
    }
    supervisor_ = -1;
    r.seconds = got == sizeof report ? static_cast<double>(report.nanoseconds) * 1e-9 : secondsSince(start_);
    if (r.timedOut) return r;
    if (got != sizeof report || status == -1) {
        r.error = fmt::format("{} ended without a status", program_);
        r.signal = WIFSIGNALED(supervisorStatus) ? WTERMSIG(supervisorStatus) : 0;
        return r;
    }
    if (WIFEXITED(status)) {
        r.exitCode = WEXITSTATUS(status);
        if (r.exitCode == 127) r.error = fmt::format("cannot run {}", path_);
    } else if (WIFSIGNALED(status)) {
        r.signal = WTERMSIG(status);
    }
    return r;
}

ChildResult runChild(const std::vector<std::string>& argv, const std::string& logPath, const ChildLimits& limits) {
    return startChild(argv, logPath, limits).wait();
}

ChildResult runForked(const std::function<std::string()>& work, std::string* output, double wallSeconds,
                      const std::function<void()>& meanwhile) {
    ChildResult r;
    const auto start = std::chrono::steady_clock::now();
    output->clear();
    int pipeFds[2];
    if (pipe2(pipeFds, O_CLOEXEC) != 0) {
        r.error = fmt::format("cannot create a pipe: {}", std::strerror(errno));
        return r;
    }
    std::fflush(stdout);
    std::fflush(stderr);
    const pid_t parent = getpid();
    const pid_t child = fork();
    if (child == 0) {
        close(pipeFds[0]);
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent) _exit(1);
        std::string out;
        try {
            out = work();
        } catch (...) {
            _exit(3);
        }
        // Its length first, so that a result cut short is never taken
        // for a whole one.
        const uint64_t size = out.size();
        _exit(writeAll(pipeFds[1], &size, sizeof size) && writeAll(pipeFds[1], out.data(), out.size()) ? 0 : 2);
    }
    close(pipeFds[1]);
    if (child < 0) {
        close(pipeFds[0]);
        r.error = fmt::format("cannot fork: {}", std::strerror(errno));
        return r;
    }
    r.started = true;
    char buffer[1 << 16];
    std::string received;
    uint64_t size = 0;
    for (;;) {
        if (received.size() >= sizeof size) {
            std::memcpy(&size, received.data(), sizeof size);
            if (received.size() - sizeof size >= size) break;
        }
        if (!waitReadable(pipeFds[0], wallSeconds, start, meanwhile)) {
            r.timedOut = true;
            break;
        }
        const ssize_t n = read(pipeFds[0], buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        received.append(buffer, static_cast<size_t>(n));
    }
    if (received.size() >= sizeof size && received.size() - sizeof size == size) *output = received.substr(sizeof size);
    close(pipeFds[0]);
    if (r.timedOut) kill(child, SIGKILL);
    int status = 0;
    while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
    }
    r.seconds = secondsSince(start);
    if (r.timedOut) return r;
    if (WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
    else if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
    return r;
}

ChildLimits defaultCompileLimits() {
    ChildLimits limits;
    limits.wallSeconds = kDefaultCompileSeconds;
    if (const char* s = std::getenv("PSC_COMPILE_TIMEOUT"); s && *s) limits.wallSeconds = std::max(0.0, std::atof(s));
    const long pages = sysconf(_SC_PHYS_PAGES);
    const long pageSize = sysconf(_SC_PAGE_SIZE);
    if (pages > 0 && pageSize > 0) limits.memoryBytes = static_cast<unsigned long long>(pages) * pageSize / 4 * 3;
    if (const char* m = std::getenv("PSC_COMPILE_MEMORY_MB"); m && *m) {
        limits.memoryBytes = static_cast<unsigned long long>(std::max(0.0, std::atof(m))) << 20;
    }
    return limits;
}

std::string limitMessage(const ChildResult& result, const ChildLimits& limits, const std::string& log) {
    if (result.timedOut) {
        return fmt::format("stopped at the compile time limit of {:g} s (PSC_COMPILE_TIMEOUT=seconds sets it, 0: none)",
                           limits.wallSeconds);
    }
    if (limits.memoryBytes == 0 || result.ok()) return {};
    const bool outOfMemory = log.find("memory exhausted") != std::string::npos ||
                             log.find("out of memory") != std::string::npos ||
                             log.find("Cannot allocate memory") != std::string::npos ||
                             log.find("std::bad_alloc") != std::string::npos;
    if (!outOfMemory) return {};
    return fmt::format("ran out of memory at the compile memory limit of {} MB of address space "
                       "(PSC_COMPILE_MEMORY_MB=megabytes sets it, 0: none)",
                       limits.memoryBytes >> 20);
}

}  // namespace psc
