#include "Terminal.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <exception>
#include <stdexcept>

namespace psc::play {
namespace {

// What the signal handlers need, kept where they can reach it without locks.
struct SavedState {
    int inputFd = -1;
    int outputFd = -1;
    termios original{};
    volatile sig_atomic_t rawActive = 0;
    volatile sig_atomic_t screenActive = 0;
    int eventPipe[2] = {-1, -1};
    volatile sig_atomic_t resized = 0;
    volatile sig_atomic_t stopSignal = 0;
    std::terminate_handler previousTerminate = nullptr;
};
SavedState g;

// Leave the alternate screen, show the cursor, reset colours, wrap lines again.
constexpr char kLeaveScreen[] = "\x1b[0m\x1b[?7h\x1b[?25h\x1b[?1049l";
constexpr char kEnterScreen[] = "\x1b[?1049h\x1b[?25l\x1b[?7l\x1b[2J";

void writeAll(int fd, const char* data, size_t size) {
    while (size > 0) {
        const ssize_t n = ::write(fd, data, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return;
        data += n;
        size -= static_cast<size_t>(n);
    }
}

// Async-signal-safe: only write() and tcsetattr().
void restoreNow() {
    if (g.screenActive) {
        g.screenActive = 0;
        writeAll(g.outputFd, kLeaveScreen, sizeof kLeaveScreen - 1);
    }
    if (g.rawActive) {
        g.rawActive = 0;
        tcsetattr(g.inputFd, TCSAFLUSH, &g.original);
    }
}

void notify() {
    if (g.eventPipe[1] >= 0) {
        const int saved = errno;
        const char byte = 1;
        [[maybe_unused]] ssize_t n = ::write(g.eventPipe[1], &byte, 1);
        errno = saved;
    }
}

void onResize(int) {
    g.resized = 1;
    notify();
}

// The player stops at its next turn of the loop; a second signal before then
// (the player is stuck) restores the terminal and exits at once.
void onStop(int signal) {
    if (g.stopSignal) {
        restoreNow();
        _exit(128 + signal);
    }
    g.stopSignal = signal;
    notify();
}

void onCrash(int signal) {
    restoreNow();
    ::signal(signal, SIG_DFL);
    raise(signal);
}

constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};
constexpr int kCrashSignals[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};

void install(int signal, void (*handler)(int)) {
    struct sigaction sa {};
    sa.sa_handler = handler;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;  // no SA_RESTART: poll() returns at once with EINTR
    sigaction(signal, &sa, nullptr);
}

}  // namespace

Terminal::Terminal(int inputFd, int outputFd, bool fullScreen) : outputFd_(outputFd) {
    if (g.eventPipe[0] >= 0) throw std::logic_error("only one Terminal at a time");
    if (pipe2(g.eventPipe, O_NONBLOCK | O_CLOEXEC) != 0) throw std::runtime_error("cannot create a pipe");
    g.inputFd = inputFd;
    g.outputFd = outputFd;
    g.resized = 0;
    g.stopSignal = 0;
    install(SIGWINCH, onResize);
    for (int s : kStopSignals) install(s, onStop);
    for (int s : kCrashSignals) install(s, onCrash);
    g.previousTerminate = std::set_terminate([] {
        restoreNow();
        if (g.previousTerminate) g.previousTerminate();
        std::abort();
    });
    if (isatty(inputFd) && tcgetattr(inputFd, &g.original) == 0) {
        termios raw = g.original;
        // Keys arrive one at a time, unechoed; Ctrl-C and Ctrl-Z arrive as keys too.
        raw.c_iflag &= ~static_cast<tcflag_t>(BRKINT | ICRNL | INPCK | ISTRIP | IXON);
        raw.c_lflag &= ~static_cast<tcflag_t>(ECHO | ICANON | IEXTEN | ISIG);
        raw.c_cflag |= CS8;
        raw.c_cc[VMIN] = 1;
        raw.c_cc[VTIME] = 0;
        g.rawActive = 1;
        tcsetattr(inputFd, TCSAFLUSH, &raw);
    }
    if (fullScreen) {
        g.screenActive = 1;
        writeAll(outputFd, kEnterScreen, sizeof kEnterScreen - 1);
    }
}

Terminal::~Terminal() {
    restoreNow();
    for (int s : kStopSignals) ::signal(s, SIG_DFL);
    for (int s : kCrashSignals) ::signal(s, SIG_DFL);
    ::signal(SIGWINCH, SIG_DFL);
    std::set_terminate(g.previousTerminate);
    close(g.eventPipe[0]);
    close(g.eventPipe[1]);
    g.eventPipe[0] = g.eventPipe[1] = -1;
}

TerminalSize Terminal::size() const {
    winsize ws{};
    if (ioctl(outputFd_, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 && ws.ws_row > 0) return {ws.ws_col, ws.ws_row};
    return {};
}

void Terminal::write(std::string_view bytes) const { writeAll(outputFd_, bytes.data(), bytes.size()); }

int Terminal::eventFd() const { return g.eventPipe[0]; }

TerminalEvents Terminal::takeEvents() {
    char drain[64];
    while (read(g.eventPipe[0], drain, sizeof drain) > 0) {
    }
    TerminalEvents events;
    events.resized = g.resized != 0;
    g.resized = 0;
    events.stopSignal = g.stopSignal;
    return events;
}

}  // namespace psc::play
