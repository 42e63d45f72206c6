// The terminal while psc play runs: raw input, the alternate screen, a hidden
// cursor, and the promise that all of it is undone however the program ends
// (normal exit, an exception, Ctrl-C, SIGTERM, SIGHUP or a crash).
#pragma once

#include <string_view>

namespace psc::play {

struct TerminalSize {
    int columns = 80;
    int rows = 24;
};

// Signals the player handles between frames; read with Terminal::takeEvents.
struct TerminalEvents {
    bool resized = false;
    int stopSignal = 0;  // SIGINT, SIGTERM or SIGHUP when one arrived
};

class Terminal {
public:
    // Takes over the terminal: raw mode on `inputFd` when it is a terminal,
    // and the full screen on `outputFd` when `fullScreen`.  One at a time.
    Terminal(int inputFd, int outputFd, bool fullScreen);
    ~Terminal();  // restores everything it changed
    Terminal(const Terminal&) = delete;
    Terminal& operator=(const Terminal&) = delete;

    TerminalSize size() const;
    void write(std::string_view bytes) const;
    // A file descriptor that becomes readable when a signal arrived (for poll).
    int eventFd() const;
    TerminalEvents takeEvents();

private:
    int outputFd_;
};

}  // namespace psc::play
