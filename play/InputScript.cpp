#include "InputScript.h"

#include <cctype>

#include "psc_plugin.h"

namespace psc::play {

char inputLetter(int action) {
    static constexpr char kLetters[] = {'u', 'l', 'd', 'r', 'x', 'z', '!', '.'};
    return action >= 0 && action < PSC_ACTION_COUNT ? kLetters[action] : '?';
}

std::optional<std::vector<int>> parseInputScript(const std::string& text, std::string* problem) {
    std::vector<int> actions;
    bool comment = false;
    bool lineStart = true;
    int line = 1;
    for (char raw : text) {
        if (raw == '\n') {
            comment = false;
            lineStart = true;
            ++line;
            continue;
        }
        if (lineStart && raw == '#') comment = true;
        if (!std::isspace(static_cast<unsigned char>(raw))) lineStart = false;
        if (comment || std::isspace(static_cast<unsigned char>(raw))) continue;
        const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(raw)));
        int action = -1;
        for (int a = 0; a < PSC_ACTION_COUNT; ++a) {
            if (inputLetter(a) == c) action = a;
        }
        if (action < 0) {
            *problem = "line " + std::to_string(line) + ": '" + std::string(1, raw) +
                       "' is not an input (u l d r x, z undo, ! restart, . tick)";
            return std::nullopt;
        }
        actions.push_back(action);
    }
    return actions;
}

}  // namespace psc::play
