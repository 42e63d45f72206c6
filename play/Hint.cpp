#include "Hint.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

extern char** environ;

namespace psc::play {

HintSearch::~HintSearch() { cancel(); }

bool HintSearch::start(const HintRequest& request, std::string* problem) {
    cancel();
    int pipeFds[2];
    if (pipe2(pipeFds, O_CLOEXEC) != 0) {
        *problem = std::string("cannot start the solver: ") + std::strerror(errno);
        return false;
    }
    std::vector<std::string> args = {request.pscBinary, "solve", request.gamePath,
                                     "--level", std::to_string(request.level),
                                     "--seed", std::to_string(request.seed),
                                     "--time-limit", fmt::format("{}", request.timeLimit),
                                     "--format", "json", "--quiet",
                                     "--keep-going"};  // psc play plays games the reference plays despite errors
    if (!request.fromInputs.empty()) {
        args.push_back("--from-inputs");
        args.push_back(request.fromInputs);
    }
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, pipeFds[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, pipeFds[1], STDERR_FILENO);
    // Its own process group, so that the terminal's Ctrl-C reaches only the player.
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attributes, 0);
    pid_t pid = -1;
    const int status = posix_spawn(&pid, request.pscBinary.c_str(), &actions, &attributes, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attributes);
    close(pipeFds[1]);
    if (status != 0) {
        close(pipeFds[0]);
        *problem = fmt::format("cannot run {}: {}", request.pscBinary, std::strerror(status));
        return false;
    }
    pid_ = pid;
    fd_ = pipeFds[0];
    fcntl(fd_, F_SETFL, fcntl(fd_, F_GETFL) | O_NONBLOCK);
    output_.clear();
    return true;
}

std::optional<HintAnswer> HintSearch::collect(bool wait) {
    if (!running()) return std::nullopt;
    for (;;) {
        char buffer[4096];
        const ssize_t n = read(fd_, buffer, sizeof buffer);
        if (n > 0) {
            output_.append(buffer, static_cast<size_t>(n));
            continue;
        }
        if (n == 0) return finish();
        if (errno == EINTR) continue;
        if (errno != EAGAIN && errno != EWOULDBLOCK) return finish();
        if (!wait) return std::nullopt;
        pollfd p{fd_, POLLIN, 0};
        poll(&p, 1, -1);
    }
}

HintAnswer HintSearch::finish() {
    close(fd_);
    fd_ = -1;
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
    return parseSolverOutput(output_, WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
}

void HintSearch::cancel() {
    if (!running()) return;
    kill(pid_, SIGTERM);
    close(fd_);
    fd_ = -1;
    while (waitpid(pid_, nullptr, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
}

HintAnswer parseSolverOutput(const std::string& output, int exitStatus) {
    HintAnswer answer;
    std::istringstream lines(output);
    std::string firstOther;
    for (std::string line; std::getline(lines, line);) {
        if (line.empty() || line[0] != '{') {
            if (firstOther.empty()) firstOther = line;
            continue;
        }
        try {
            const nlohmann::json record = nlohmann::json::parse(line);
            const std::string status = record.at("status").get<std::string>();
            if (status == "solved") {
                const std::string solution = record.at("solution").get<std::string>();
                if (solution.empty()) {
                    answer.problem = "the level is already won";
                    return answer;
                }
                answer.solved = true;
                answer.nextInput = solution[0];
                answer.remaining = static_cast<int>(solution.size());
            } else if (status == "exhausted") {
                answer.problem = "no way to win from here: undo or restart";
            } else {
                answer.problem = "the solver found nothing within its " + record.value("limit", std::string("time")) + " limit";
            }
            return answer;
        } catch (const std::exception&) {
            if (firstOther.empty()) firstOther = line;
        }
    }
    answer.problem = firstOther.empty() ? fmt::format("the solver failed (exit status {})", exitStatus)
                                        : "the solver failed: " + firstOther;
    return answer;
}

}  // namespace psc::play
