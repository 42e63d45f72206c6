#include "Keys.h"

#include <cctype>

namespace psc::play {

namespace {

std::optional<Key> characterKey(unsigned char c) {
    switch (std::tolower(c)) {
        case 'w': return Key::Up;
        case 'a': return Key::Left;
        case 's': return Key::Down;
        case 'd': return Key::Right;
        case 'x': case 'c': case ' ': case '\r': case '\n': return Key::Action;
        case 'z': case 'u': return Key::Undo;
        case 'r': return Key::Restart;
        case 'q': return Key::Quit;
        case 'n': return Key::NextLevel;
        case 'p': return Key::PreviousLevel;
        case 'l': return Key::LevelSelect;
        case 'h': return Key::Hint;
        case 0x03: return Key::Interrupt;
        default: return std::nullopt;
    }
}

std::optional<Key> arrowKey(char final) {
    switch (final) {
        case 'A': return Key::Up;
        case 'B': return Key::Down;
        case 'C': return Key::Right;
        case 'D': return Key::Left;
        default: return std::nullopt;
    }
}

}  // namespace

std::optional<Key> KeyDecoder::next(bool inputIdle) {
    while (!pending_.empty()) {
        const unsigned char c = static_cast<unsigned char>(pending_[0]);
        if (c != 0x1b) {
            pending_.erase(0, 1);
            if (auto key = characterKey(c)) return key;
            continue;
        }
        if (pending_.size() == 1) {
            if (!inputIdle) return std::nullopt;  // maybe the start of a sequence
            pending_.clear();
            return Key::Back;
        }
        const char introducer = pending_[1];
        if (introducer != '[' && introducer != 'O') {
            pending_.erase(0, 1);  // Esc, then an ordinary key
            return Key::Back;
        }
        // CSI or SS3: parameters and intermediates up to a final byte in @..~.
        size_t end = 2;
        while (end < pending_.size() && !(pending_[end] >= 0x40 && pending_[end] <= 0x7e)) ++end;
        if (end == pending_.size()) {
            if (!inputIdle) return std::nullopt;
            pending_.clear();  // a cut-off sequence
            return std::nullopt;
        }
        const char final = pending_[end];
        pending_.erase(0, end + 1);
        if (auto key = arrowKey(final)) return key;
    }
    return std::nullopt;
}

}  // namespace psc::play
