// Keys of psc play, decoded from the bytes a terminal sends (arrow keys as
// ANSI escape sequences, everything else as characters).
#pragma once

#include <optional>
#include <string>

namespace psc::play {

enum class Key {
    Up, Left, Down, Right,  // arrows and WASD
    Action,                 // X, space, Enter, C
    Undo,                   // Z, U
    Restart,                // R
    Back,                   // Esc: back to the title screen
    Quit,                   // Q
    NextLevel,              // N
    PreviousLevel,          // P
    LevelSelect,            // L
    Hint,                   // H
    Interrupt,              // Ctrl-C
};

// Splits a byte stream into keys.  A lone Esc is told from the start of an
// escape sequence by what follows it: call next(true) when no more bytes
// came soon after (or the input ended), and it is taken as Esc.
class KeyDecoder {
public:
    void feed(const char* bytes, size_t size) { pending_.append(bytes, size); }
    // The next key; nothing when the bytes so far make none (yet).  Bytes that
    // are no key of psc play are skipped.
    std::optional<Key> next(bool inputIdle);
    // Whether bytes wait that might still become a key (an unfinished escape sequence).
    bool waiting() const { return !pending_.empty(); }

private:
    std::string pending_;
};

}  // namespace psc::play
